"""Options shared by subcommands: which system to use."""
from __future__ import annotations

import argparse

from tmfem.errors import InputError
from tmfem.system import System, load_preset, load_system


def add_system_args(parser: argparse.ArgumentParser) -> None:
    """Add ``[spec] --preset NAME --as-printed`` to a subcommand."""
    parser.add_argument("spec", nargs="?", help="system file (TOML); or use --preset")
    parser.add_argument("--preset", help="built-in system (see `tmfem presets`)")
    parser.add_argument("--as-printed", action="store_true",
                        help="use the dissertation's printed values instead of the consistent ones")


def system_from_args(args: argparse.Namespace) -> System:
    """The system named by ``spec`` or ``--preset`` (exactly one)."""
    if (args.spec is None) == (args.preset is None):
        raise InputError("expected exactly one of a system file or --preset NAME")
    if args.preset is not None:
        return load_preset(args.preset, as_printed=args.as_printed)
    if args.as_printed:
        raise InputError("--as-printed applies to presets only")
    return load_system(args.spec)


def add_prestress_scale_arg(parser) -> None:
    """Add ``--prestress-scale S`` (control-oriented model only, see
    :class:`tmfem.reduced.model.ControlOrientedModel`); read it with :func:`prestress_scale_of`."""
    parser.add_argument("--prestress-scale", type=float, default=None,
                        help="--model com: factor on the designed membrane prestress (default 1 = "
                             "designed; 1.2903 gives the printed 1-4 tendon stress and Table 6.6, "
                             "docs/errata.md)")


def prestress_scale_of(args: argparse.Namespace) -> float:
    """The ``--prestress-scale`` factor (1 when not given)."""
    return 1.0 if args.prestress_scale is None else args.prestress_scale
