"""``tmfem modal``: natural frequencies and mode shapes about the prestressed state (6.4, eq. 5.32)."""
from __future__ import annotations


from tmfem.cli.common import (add_model_args, add_system_args, default_monitor, model_from_args,
                              requested_files, say, with_backend)
from tmfem.errors import InputError
from tmfem.models.registry import get_spec
from tmfem.reference.printed_modes import with_printed
from tmfem.system.collapse import check_equilibrium, check_stable

NAME = "modal"
HELP = "natural frequencies and mode shapes (finite-element or control-oriented model)"
STAGES = ("equilibrium",)


def configure(parser) -> None:
    add_system_args(parser)
    add_model_args(parser, NAME, default="mtc", stages=STAGES)
    parser.add_argument("--modes", type=int, default=12, help="number of modes (default 12)")
    parser.add_argument("--vtk", help="write the mode shapes (point data mode_k) to this .vtu "
                                      "[finite-element models]")
    parser.add_argument("--png", help="render the first six mode shapes to this PNG "
                                      "[finite-element models]")


def run(args) -> dict:
    if not (isinstance(args.modes, int) and args.modes >= 1):
        raise InputError(f"--modes: expected an integer >= 1, found {args.modes!r}")
    model, options, spec = model_from_args(args, NAME)
    report = spec.report()
    files = requested_files(args, NAME, report.MODE_FILES, ("vtk", "png"))
    if args.modes > model.max_modes:              # before the static solve
        raise InputError(f"--modes {args.modes}: expected at most {model.max_modes} modes (the "
                         f"{spec.name} model of {model.system.name} has {model.ndof} free DOFs, the "
                         "coordinates of its equation of motion)")
    say(NAME, f"{model.system.name} {spec.name.upper()}, {model.ndof} degrees of freedom")
    res = model.equilibrium(monitor=default_monitor(model.system),
                            **spec.equilibrium_kwargs(options))
    check_equilibrium(model, res)
    modes = model.modes(k=args.modes, at=res)
    check_stable(model, modes)
    out = with_printed(report.modal_summary(model, res, modes), system=model.system, modes=args.modes)
    if files:
        out.update(report.write_mode_files(model, res, modes, **files))
    return with_backend(out, model) if spec.uses_backend else out


def format_text(r: dict) -> str:
    return get_spec(r["model"]).report().format_modal(r)
