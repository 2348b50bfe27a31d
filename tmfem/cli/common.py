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
