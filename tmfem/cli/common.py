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
    :class:`tmfem.models.com.model.ControlOrientedModel`); read it with :func:`prestress_scale_of`."""
    parser.add_argument("--prestress-scale", type=float, default=None,
                        help="--model com: factor on the designed membrane prestress (default 1 = "
                             "designed; 1.2903 gives the printed 1-4 tendon stress and Table 6.6, "
                             "docs/errata.md)")


def prestress_scale_of(args: argparse.Namespace) -> float:
    """The ``--prestress-scale`` factor (1 when not given)."""
    return 1.0 if args.prestress_scale is None else args.prestress_scale


def add_attachment_args(parser) -> None:
    """``--attachment`` / ``--patch``: membrane corner attachment of the plane-stress FE
    (``equilibrium``, ``study``) and of the MTC model (``converge``)."""
    parser.add_argument("--attachment", choices=("point", "distributed"), default="point",
                        help="membrane corner attachment: 'point' (default, the dissertation's "
                             "model; singular, F_Delta and the rest lengths drift like 1/log(n) "
                             "with the mesh) or 'distributed' (corner spread over a patch by an "
                             "RBE3-type affine coupling; converges under mesh refinement)")
    parser.add_argument("--patch", type=float, default=None, metavar="R",
                        help="patch radius [m] of --attachment distributed (default 10%% of "
                             "r_mb). It must reach beyond the corner's two edge neighbours: "
                             "with fewer than 3 nodes it is an error, with only those it "
                             "reduces to the point attachment (1-4 at the default patch: "
                             "--mesh 5 fails, --mesh 10 equals point; use --mesh >= 20)")
