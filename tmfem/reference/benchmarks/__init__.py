"""Registry of the element benchmarks run by ``tmfem benchmark NAME``.

Every module of this package that defines

``NAME``                      the benchmark's CLI name (``truss-arch``, ``shell-levy-plate``, ...);
``HELP``                      one line: the problem and its source;
``COLUMNS``                   ``{row key: unit}`` of the result rows (JSON ``rows``, CSV columns);
``run(*, reduced=False) -> dict``   ``{"rows": [...], "reference": ..., "source": ..., ...}``;
                                    ``reduced=True`` runs a smaller size (CI);
``plot(result, png) -> Path`` optional: the benchmark's figure,

is a benchmark (discovered like the CLI's subcommands). Add a benchmark by adding a module.
"""
from __future__ import annotations

import importlib
import pkgutil

from tmfem.errors import InputError


def registry() -> dict:
    """``{NAME: module}`` of every benchmark module of this package."""
    mods = {}
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{__name__}.{info.name}")
        if all(hasattr(mod, a) for a in ("NAME", "HELP", "COLUMNS", "run")):
            mods[mod.NAME] = mod
    return dict(sorted(mods.items()))


def get(name: str):
    """The benchmark module called ``name``."""
    reg = registry()
    if name not in reg:
        raise InputError(f"benchmark: expected one of {sorted(reg)}, found {name!r}")
    return reg[name]
