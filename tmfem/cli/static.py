"""``tmfem static``: equilibrium of a finite-element model reached from the undeformed membrane (6.2)."""
from __future__ import annotations

import sys

from tmfem.cli.common import add_model_args, add_system_args, model_from_args
from tmfem.errors import InputError
from tmfem.models.registry import get_spec

NAME = "static"
HELP = "static equilibrium of a finite-element model (dissertation 6.2)"
STAGES = ("equilibrium",)
#: the file options of the command (each model's report says which it writes)
FILES = ("vtk", "png", "stress_plot", "wrinkle_plot")


def configure(parser) -> None:
    add_system_args(parser)
    add_model_args(parser, NAME, default="mtc", capability="finite-element", stages=STAGES)
    parser.add_argument("--monitor", default=None,
                        help="comma-separated node labels whose iteration history is reported "
                             "(default B_M1 and, for 1-4, B_14 as in Fig. 6.1)")
    parser.add_argument("--vtk", help="write the equilibrium (bars, tendons with forces, membrane "
                                      "with displacement and stresses) to this .vtu file")
    parser.add_argument("--png", help="render the equilibrium to this PNG")
    parser.add_argument("--stress-plot", help="PNG maps of the membrane stresses in the floating "
                                              "frame (Figs. 6.3-6.4) [--model mtc]")
    parser.add_argument("--wrinkle-plot", help="PNG map of the membrane states (taut / wrinkled / "
                                               "slack) and tension directions (docs/wrinkling.md) "
                                               "[--model mtc]")
    parser.add_argument("--progress", action="store_true", help="iteration progress on stderr")


def default_monitor(system) -> list[str]:
    """Monitored nodes of Figures 6.1 (B_14 of 1-4) and 6.5-6.7 (B_11, A_21, B_21 of 2-3)."""
    if system.M == 1:
        return [f"B_1{system.N}"] if system.N < 10 else [f"B_1,{system.N}"]
    return ["B_11", "A_21", "B_21"]


def static_progress(enabled: bool):
    """A ``progress(iteration, rnorm, [mu, rho])`` callback of the static solve that prints
    one line per iteration on stderr (``--progress``), or None."""
    if not enabled:
        return None

    def show(it, rn, mu=0.0, rho=float("nan")):
        print(f"  static it {it:3d}  |r| = {rn:.3e} N  mu = {mu:.3g}  rho = {rho:.3g}",
              file=sys.stderr)
    return show


def requested_files(args, command: str, report, names=FILES) -> dict:
    """The file options of ``names`` given in ``args``, refused (before any work) where the
    model's ``report`` does not write them."""
    given = {k: getattr(args, k) for k in names if getattr(args, k, None)}
    accepted = report.STATIC_FILES if command == NAME else report.MODE_FILES
    wrong = [k for k in given if k not in accepted]
    if wrong:
        flags = "/".join("--" + k.replace("_", "-") for k in wrong)
        raise InputError(f"{command} --model {args.model}: option does not apply: {flags} (the "
                         f"{args.model} model writes "
                         + (", ".join("--" + k.replace("_", "-") for k in accepted) or "no files")
                         + ")")
    return given


def run(args) -> dict:
    model, options, spec = model_from_args(args, NAME)
    report = spec.report()
    files = requested_files(args, NAME, report)
    monitor = args.monitor.split(",") if args.monitor else default_monitor(model.system)
    print(f"tmfem static: {model.system.name} {spec.name.upper()}, {model.ndof} free dofs",
          file=sys.stderr)
    res = model.equilibrium(monitor=monitor, progress=static_progress(args.progress),
                            **spec.equilibrium_kwargs(options))
    out = report.static_summary(model, res)
    if files:
        out.update(report.write_static_files(model, res, **files))
    return out


def format_text(r: dict) -> str:
    return get_spec(r["model"]).report().format_static(r)
