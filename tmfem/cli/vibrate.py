"""``tmfem vibrate``: free vibration of the control-oriented model or of a finite-element model
(membrane-truss-cable, shell-beam-cable; 6.5, Park's method)."""
from __future__ import annotations


import numpy as np

from tmfem.cli.common import (add_model_args, add_system_args, check_frames, check_time_steps,
                              finite_float, model_from_args, parse_perturbation, positive_int,
                              progress_bar, say, with_backend)
from tmfem.errors import InputError
from tmfem.simulation.vibration import model_free_vibration
from tmfem.system.collapse import check_equilibrium

NAME = "vibrate"
HELP = "free vibration after an initial perturbation (COM, MTC or SBC model, Park's method)"
STAGES = ("equilibrium", "dynamics")


def configure(parser) -> None:
    add_system_args(parser)
    add_model_args(parser, NAME, default="com", stages=STAGES)
    parser.add_argument("--t-end", type=finite_float, default=10.0, help="duration [s] (default 10)")
    parser.add_argument("--dt", type=finite_float, default=0.01,
                        help="time step [s] (default 0.01, as in 6.5)")
    parser.add_argument("--perturb", action="append", default=[], metavar="STATE=VALUE",
                        help="initial perturbation, e.g. theta_11_dot=0.01 (repeatable; default the "
                             "system file's [report] perturbation: theta_11_dot=0.01 unless it "
                             "says otherwise, theta_12_dot=0.01 for the preset 1-4)")
    parser.add_argument("--scheme", choices=("park", "trapezoidal"), default="park",
                        help="time integrator: Park's stiffly stable method (eqs. 5.34-5.35) or "
                             "the trapezoidal rule")
    parser.add_argument("--csv", help="write the histories to this CSV file (row by row)")
    parser.add_argument("--plot", help="write a plot of the monitored histories (PNG)")
    parser.add_argument("--vtk", metavar="DIR",
                        help="write a ParaView series (.pvd + .vtu frames) to this directory")
    parser.add_argument("--vtk-every", type=positive_int, default=None,
                        help="steps between ParaView frames of --vtk (default 10)")


def run(args) -> dict:
    steps = check_time_steps(t_end=args.t_end, dt=args.dt)
    if args.vtk_every is not None and args.vtk is None:
        raise InputError("--vtk-every: option does not apply without --vtk DIR (it spaces the "
                         "ParaView frames)")
    args.vtk_every = args.vtk_every or 10
    if args.vtk is not None:
        check_frames(steps=steps, every=args.vtk_every)
    model, options, spec = model_from_args(args, NAME)
    system, name = model.system, spec.name.upper()
    pert = parse_perturbation(default_perturbation(args, system), model.perturbation_names)
    size = model.describe_text()
    say(NAME, f"{system.name} {name}, {size}, static equilibrium")
    eq = model.equilibrium(**spec.equilibrium_kwargs(options))
    check_equilibrium(model, eq)
    dynamics = spec.plant_kwargs(options)
    with progress_bar(args.t_end, args.dt, f"vibrate {system.name} {name}") as bar:
        res = model_free_vibration(model, at=eq, perturb=pert, dynamics=dynamics,
                                   t_end=args.t_end, dt=args.dt, csv_path=args.csv,
                                   scheme=args.scheme, progress=bar, vtk_dir=args.vtk,
                                   vtk_every=args.vtk_every)
    title = f"{system.name} {name} free vibration, {size}"
    out = {"system": system.name, "model": spec.name, **model.describe(), "t_end": args.t_end,
           "dt": args.dt, "perturbation": pert, "scheme": args.scheme,
           **{o.name: options[o.name] for o in spec.options if o.stage == "dynamics"},
           "static_time_s": eq.time, **_run_summary(res, args, title=title), **res.summary()}
    return with_backend(out, model) if spec.uses_backend else out


def _run_summary(res, args, *, title: str) -> dict:
    """What both models report of a free-vibration run: solver counts, the smallest tendon
    force, monitored amplitudes, and the files written (CSV, ParaView series, plot)."""
    from tmfem.post.plots import plot_free_vibration

    out = {"wall_time_s": res.wall_time, "steps": res.stats["steps"],
           "newton_iterations": res.stats["newton_iterations"],
           "jacobian_evaluations": res.stats["jacobian_evaluations"],
           "min_tendon_force_N": res.stats["min_tendon_force"],
           "min_tendon_force_tendon": res.stats["min_tendon_force_tendon"],
           "w_max_abs_m": np.max(np.abs(res.w), axis=0).tolist() if res.w.size else [],
           "node_range_m": {k: np.ptp(v, axis=0).tolist() for k, v in res.nodes.items()}}
    if args.csv:
        out["csv"] = args.csv
    if "pvd" in res.stats:
        out["pvd"] = res.stats["pvd"]
    if args.plot:
        out["plot"] = plot_free_vibration(res, args.plot, title=title)
    return out


def default_perturbation(args, system) -> list:
    """``--perturb``, else the file's ``[report] perturbation`` (a free vibration from the
    equilibrium without one would stay there)."""
    return args.perturb or [f"{k}={v!r}" for k, v in system.problem.report.perturbation.items()]


def format_text(r: dict) -> str:
    if "energy_drift_J" in r:
        return _format_fe(r)
    lines = [f"{r['system']} COM free vibration: {r['steps']} steps of {r['dt']} s "
             f"({r['scheme']}), {r['wall_time_s']:.2f} s wall, {r['newton_iterations']} Newton "
             f"iterations, {r['jacobian_evaluations']} Jacobians",
             "perturbation: " + ", ".join(f"{k}={v:g}" for k, v in r["perturbation"].items()),
             f"smallest tendon force {r['min_tendon_force_N']:.4g} N ({r['min_tendon_force_tendon']})"]
    return "\n".join(lines + _format_outputs(r))


def _format_fe(r: dict) -> str:
    lines = [f"{r['system']} {r['model'].upper()} free vibration ({r['ndof']} DOFs): {r['steps']} steps of "
             f"{r['dt']} s ({r['scheme']}, backend {r['backend']}), {r['wall_time_s']:.2f} s wall (static "
             f"{r['static_time_s']:.2f} s), {r['newton_iterations']} Newton iterations, "
             f"{r['jacobian_evaluations']} Jacobians",
             "perturbation: " + ", ".join(f"{k}={v:g}" for k, v in r["perturbation"].items()),
             f"smallest tendon force {r['min_tendon_force_N']:.4g} N ({r['min_tendon_force_tendon']})",
             f"largest tendon transverse deflection {1e3 * r['max_tendon_deflection_m']:.3g} mm "
             f"({r['max_tendon_deflection_tendon']})",
             f"energy drift {r['energy_drift_J']:.3g} J (initial kinetic {r['initial_kinetic_energy_J']:.3g} J)"]
    return "\n".join(lines + _format_outputs(r))


def _format_outputs(r: dict) -> list:
    lines = [f"max |w_{i + 1}| = {1e3 * w:.4f} mm" for i, w in enumerate(r["w_max_abs_m"])]
    for k, v in r["node_range_m"].items():
        lines.append(f"{k} peak-to-peak (x, y, z) = " + ", ".join(f"{1e3 * a:.3f}" for a in v) + " mm")
    return lines + [f"{k}: {r[k]}" for k in ("csv", "plot", "pvd") if k in r]
