"""``tmfem static``: equilibrium of a finite-element model reached from the undeformed membrane (6.2)."""
from __future__ import annotations


from tmfem.cli.common import (add_model_args, add_system_args, default_monitor, model_from_args,
                              requested_files, say, with_backend)
from tmfem.models.registry import get_spec
from tmfem.system.collapse import check_equilibrium

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
                                               "slack) and tension directions (docs/guides/wrinkling.md) "
                                               "[--model mtc]")
    parser.add_argument("--progress", action="store_true", help="iteration progress on stderr")


def static_progress(enabled: bool):
    """A ``progress(iteration, rnorm, [mu, rho])`` callback of the static solve that prints
    one line per iteration on stderr (``--progress``), or None."""
    if not enabled:
        return None

    def show(it, rn, mu=0.0, rho=float("nan")):
        say(NAME, f"static it {it:3d}  |r| = {rn:.3e} N  mu = {mu:.3g}  rho = {rho:.3g}")
    return show


def run(args) -> dict:
    model, options, spec = model_from_args(args, NAME)
    report = spec.report()
    files = requested_files(args, NAME, report.STATIC_FILES, FILES)
    monitor = args.monitor.split(",") if args.monitor else default_monitor(model.system)
    say(NAME, f"{model.system.name} {spec.name.upper()}, {model.ndof} free dofs")
    res = model.equilibrium(monitor=monitor, progress=static_progress(args.progress),
                            **spec.equilibrium_kwargs(options))
    out = report.static_summary(model, res)
    check_equilibrium(model, res, values=out)          # before anything is written
    if files:
        out.update(report.write_static_files(model, res, **files))
    return with_backend(out, model) if spec.uses_backend else out


def format_text(r: dict) -> str:
    return get_spec(r["model"]).report().format_static(r)
