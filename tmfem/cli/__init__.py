"""The ``tmfem`` command line.

Every module of this package that defines ``NAME``, ``HELP``, ``configure(parser)`` and
``run(args) -> dict`` is a subcommand. ``run`` returns a JSON-serialisable result; with
``--json`` it is printed as one JSON document on stdout, otherwise the module's
``format_text(result) -> str`` (or a default rendering) is printed. A
:class:`tmfem.errors.TmfemError` becomes a one-line message on stderr and a non-zero
exit code, never a traceback.
"""
from __future__ import annotations

import argparse
import importlib
import json
import logging
import math
import pkgutil
import sys

import numpy as np

from tmfem.errors import TmfemError


def _subcommands() -> dict:
    mods = {}
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_") or info.name == "common":
            continue
        mod = importlib.import_module(f"{__name__}.{info.name}")
        if all(hasattr(mod, a) for a in ("NAME", "HELP", "configure", "run")):
            mods[mod.NAME] = mod
    return dict(sorted(mods.items()))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tmfem", description="Tensegrity-membrane systems: "
                                     "equilibrium, finite-element and control-oriented models, control.")
    sub = parser.add_subparsers(dest="command", metavar="<command>")
    sub.required = True
    for name, mod in _subcommands().items():
        p = sub.add_parser(name, help=mod.HELP, description=mod.HELP)
        p.add_argument("--json", action="store_true", help="print one JSON document on stdout")
        mod.configure(p)
        p.set_defaults(_module=mod)
    return parser


def _default_text(result) -> str:
    return json.dumps(result, indent=2, default=str)


def _log_to_stderr() -> None:
    """Library progress (``logging`` INFO of the ``tmfem`` loggers) as lines on stderr."""
    log = logging.getLogger("tmfem")
    if not log.handlers:
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("tmfem: %(message)s"))
        log.addHandler(handler)
        log.setLevel(logging.INFO)


def main(argv=None) -> int:
    """Entry point of the ``tmfem`` console script; returns the exit code."""
    _log_to_stderr()
    parser = build_parser()
    args = parser.parse_args(argv)
    mod = args._module
    try:
        result = mod.run(args)
    except TmfemError as exc:
        print(f"tmfem {args.command}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    if args.json:
        print(json.dumps(_finite(result), default=_json_default, allow_nan=False))
    else:
        print(getattr(mod, "format_text", _default_text)(result))
    return 0


def _finite(obj):
    """``obj`` with non-finite floats replaced by None: JSON has no NaN or infinity
    (a tendon that would push has no rest length, a missing printed value is absent)."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _finite(obj.tolist())
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    return obj


def _json_default(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
