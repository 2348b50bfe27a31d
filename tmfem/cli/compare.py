"""``tmfem compare``: the SBC, MTC and COM models side by side -- natural frequencies (beside
the printed ones when the file has them: Tables 6.6/6.7 for 1-4 and 2-3, 6.4), or with
``--vibrate`` free vibration from the same perturbation (6.5). The frequencies of a 1-N(D)
system compare the SBC and COM models (the MTC model cannot represent it, and the output says
so); ``--vibrate`` needs all three and refuses such a system."""
from __future__ import annotations


from tmfem.cli.common import (Progress, add_system_args, check_model_budget, check_time_steps,
                              finite_float, output_file, parse_perturbation, positive_int,
                              say, system_from_args)
from tmfem.errors import InputError
from tmfem.solvers.backends import backend_names

NAME = "compare"
HELP = ("the three models (SBC, MTC, COM) side by side: frequencies (beside the printed ones, "
        "Tables 6.6/6.7 for 1-4 and 2-3; SBC and COM only for a 1-N(D) system), or free vibration "
        "from one perturbation (--vibrate)")

#: options of each mode, refused in the other
FREQUENCY_ONLY = ("modes",)
VIBRATE_ONLY = ("t_end", "dt", "perturb")


def configure(parser) -> None:
    add_system_args(parser)
    parser.add_argument("--mesh", type=positive_int, default=10,
                        help="FE membrane elements per side of each quadrilateral (6.4: 10; "
                             "6.5: 10, the '20 x 20' square of 6.5.1 is 4 x 10 x 10)")
    parser.add_argument("--tendon-elements", type=positive_int, default=3,
                        help="truss elements per tendon of the FE models (6.4: 3)")
    parser.add_argument("--backend", choices=backend_names(), default="auto",
                        help="linear-algebra backend of the FE models")
    parser.add_argument("--modes", type=positive_int, default=None,
                        help="frequencies per model (default 12, as Tables 6.6/6.7)")
    parser.add_argument("--vibrate", action="store_true",
                        help="free vibration of the three models instead of frequencies (6.5)")
    parser.add_argument("--t-end", type=finite_float, default=None,
                        help="--vibrate: duration [s] (default 10)")
    parser.add_argument("--dt", type=finite_float, default=None,
                        help="--vibrate: time step [s] (default 0.01, as 6.5)")
    parser.add_argument("--perturb", action="append", default=None, metavar="STATE=VALUE",
                        help="--vibrate: initial perturbation (default the file's [report] "
                             "perturbation: 6.5's theta_12_dot=0.01 for 1-4, theta_11_dot=0.01 "
                             "otherwise; repeatable)")
    parser.add_argument("--csv", help="write the table (frequencies) or the histories to this CSV")
    parser.add_argument("--plot", help="PNG: frequencies and differences, or the overlaid histories")


def run(args) -> dict:
    from tmfem.reference.model_compare import compared_system, loaded_system
    if args.as_printed:
        raise InputError("--as-printed: option does not apply: each model is taken at the "
                         "prestress the file names (docs/guides/system-file.md, [report])")
    args.system = (compared_system if args.vibrate else loaded_system)(system_from_args(args))
    args.preset = args.system.name
    mine, other = (VIBRATE_ONLY, FREQUENCY_ONLY) if args.vibrate else (FREQUENCY_ONLY, VIBRATE_ONLY)
    wrong = [d for d in other if getattr(args, d) is not None]
    if wrong:
        flags = ", ".join("--" + d.replace("_", "-") for d in wrong)
        raise InputError(f"compare{' --vibrate' if args.vibrate else ''}: option does not apply: "
                         f"{flags} ({'without' if args.vibrate is False else 'with'} --vibrate)")
    # the SBC model is the larger of the two FE models (shells: 6 DOFs a node)
    check_model_budget(args.system, mesh=args.mesh, tendon_elements=args.tendon_elements,
                       modes=args.modes, dofs_per_node=6, backend=args.backend)
    output_file(args.csv, option="--csv", suffixes=(".csv",))
    output_file(args.plot, option="--plot", suffixes=(".png",))
    return run_vibration(args) if args.vibrate else run_frequencies(args)


def run_frequencies(args) -> dict:
    from tmfem.reference.model_compare import applicable_models, compare_frequencies, write_compare_csv
    with Progress(total=len(applicable_models(args.system)), desc=f"compare {args.preset}") as bar:
        r = compare_frequencies(args.system, modes=args.modes or 12, mesh_n=args.mesh,
                                tendon_elements=args.tendon_elements, backend=args.backend,
                                progress=bar.step)
    if args.csv:
        r["csv"] = str(write_compare_csv(args.csv, r))
    if args.plot:
        from tmfem.post.compare import plot_model_frequencies
        r["plot"] = str(plot_model_frequencies(args.plot, r))
    return r


def run_vibration(args) -> dict:
    from tmfem.models.fe.plant import perturbation_names
    from tmfem.reference.model_compare import fe_system
    from tmfem.reference.vibration_compare import (format_vibration_compare, key_signals,
                                                   three_model_vibration, write_vibration_csv)
    t_end = 10.0 if args.t_end is None else args.t_end
    dt = 0.01 if args.dt is None else args.dt
    check_time_steps(t_end=t_end, dt=dt)
    system = fe_system(args.system)
    pert = parse_perturbation(args.perturb, perturbation_names(system)) if args.perturb else None
    say("compare --vibrate", f"{args.preset}, {t_end:g} s at dt = {dt:g} s, FE mesh {args.mesh}")
    with Progress(total=3, desc=f"vibrate {args.preset}") as bar:
        def progress(model):
            bar.step(model)
            return bar.callback(f"{model} steps")
        r = three_model_vibration(args.system, t_end=t_end, dt=dt, perturb=pert, mesh_n=args.mesh,
                                  tendon_elements=args.tendon_elements, backend=args.backend,
                                  progress=progress)
    out = dict(r["comparison"])
    out["vibrate"] = True
    out["text"] = format_vibration_compare(out, system)
    if args.csv:
        out["csv"] = str(write_vibration_csv(args.csv, r["t"], r["signals"]))
    if args.plot:
        from tmfem.post.compare import plot_vibration_overlay
        names = key_signals(system) + ["tendon_deflection"]
        out["plot"] = str(plot_vibration_overlay(
            args.plot, r["t"], r["signals"], names,
            title=f"{args.preset}: SBC, MTC and COM free vibration, "
                  + ", ".join(f"{k} = {v:g}" for k, v in out["perturbation"].items())
                  + f" (FE mesh {args.mesh})"))
    return out


def format_text(r: dict) -> str:
    if r.get("vibrate"):
        lines = [r["text"]]
    else:
        from tmfem.reference.model_compare import format_compare
        lines = [format_compare(r)]
    return "\n".join(lines + [f"wrote {r[k]}" for k in ("csv", "plot") if k in r])
