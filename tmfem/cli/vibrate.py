"""``tmfem vibrate``: free vibration of the control-oriented model or of a finite-element model
(membrane-truss-cable, shell-beam-cable; 6.5, Park's method)."""
from __future__ import annotations

import sys

import numpy as np

from tmfem.cli.common import (add_model_args, add_system_args, check_frames, check_time_steps,
                              finite_float, model_from_args, parse_perturbation, positive_int,
                              progress_bar)
from tmfem.errors import InputError
from tmfem.cli.static import check_fe_static
from tmfem.models.mtc.spec import sequence_of

NAME = "vibrate"
HELP = "free vibration after an initial perturbation (COM, MTC or SBC model, Park's method)"


def configure(parser) -> None:
    add_system_args(parser)
    add_model_args(parser, NAME, default="com")
    parser.add_argument("--t-end", type=finite_float, default=10.0, help="duration [s] (default 10)")
    parser.add_argument("--dt", type=finite_float, default=0.01,
                        help="time step [s] (default 0.01, as in 6.5)")
    parser.add_argument("--perturb", action="append", default=[], metavar="STATE=VALUE",
                        help="initial perturbation, e.g. theta_11_dot=0.01 (repeatable)")
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
    model, options = model_from_args(args, NAME)
    if args.model in ("mtc", "sbc"):
        return run_fe(args, model, options)
    from tmfem.simulation.vibration import free_vibration

    system = model.system
    print(f"tmfem vibrate: {system.name} COM, K = {model.K}", file=sys.stderr)
    pert = parse_perturbation(args.perturb, model.state_names)
    with progress_bar(args.t_end, args.dt, f"vibrate {system.name}") as bar:
        res = free_vibration(model, t_end=args.t_end, dt=args.dt, perturb=pert, csv_path=args.csv,
                             scheme=args.scheme, jacobian="reuse", progress=bar,
                             vtk_dir=args.vtk, vtk_every=args.vtk_every)
    out = {"system": system.name, "model": "com", "membrane_modes": model.K, "t_end": args.t_end,
           "dt": args.dt, "perturbation": pert, "scheme": args.scheme,
           **_run_summary(res, args, title=f"{system.name} COM free vibration, K = {model.K}"),
           "final": dict(zip(model.state_names, np.concatenate([res.z[-1], res.zd[-1]]).tolist()))}
    return out


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


def run_fe(args, model, options) -> dict:
    """Free vibration of a finite-element model (MTC or SBC) about its static equilibrium."""
    from tmfem.models.fe_plant import perturbation_names
    from tmfem.simulation.vibration import mtc_free_vibration, sbc_free_vibration

    system, name = model.system, args.model.upper()
    pert = parse_perturbation(args.perturb, perturbation_names(system))
    rayleigh = options["rayleigh"] or (0.0, 0.0)
    print(f"tmfem vibrate: {system.name} {name}, mesh {system.N}x{options['mesh']}x{options['mesh']}, "
          f"{model.ndof} DOFs, static equilibrium", file=sys.stderr)
    if args.model == "mtc":
        st = model.solve_static(start="undeformed",
                                sequence=sequence_of(options["mesh"], options["sequence"]))
        run, eq = mtc_free_vibration, st.x
    else:
        st = model.solve_static()
        run, eq = sbc_free_vibration, st.state
    check_fe_static(model, st)
    with progress_bar(args.t_end, args.dt, f"vibrate {system.name} {name}") as bar:
        res = run(model, eq, t_end=args.t_end, dt=args.dt, perturb=pert, csv_path=args.csv,
                  scheme=args.scheme, alpha=rayleigh[0], beta=rayleigh[1], progress=bar,
                  vtk_dir=args.vtk, vtk_every=args.vtk_every)
    out = {"system": system.name, "model": args.model, "mesh": options["mesh"], "ndof": model.ndof,
           "tendon_elements": options["tendon_elements"], "t_end": args.t_end, "dt": args.dt,
           "perturbation": pert, "scheme": args.scheme, "rayleigh": list(rayleigh),
           "static_time_s": st.time,
           **_run_summary(res, args, title=f"{system.name} {name} free vibration, mesh {options['mesh']}"),
           "max_tendon_deflection_m": res.stats["max_tendon_deflection"],
           "max_tendon_deflection_tendon": res.stats["max_tendon_deflection_tendon"],
           "energy_drift_J": float(np.max(np.abs(res.energy - res.energy[0]))),
           "initial_kinetic_energy_J": float(res.kinetic[0]),
           "q_range": dict(zip(system.q_names, np.ptp(res.q, axis=0).tolist()))}
    return out


def format_text(r: dict) -> str:
    if r.get("model") in ("mtc", "sbc"):
        return _format_fe(r)
    lines = [f"{r['system']} COM free vibration: {r['steps']} steps of {r['dt']} s "
             f"({r['scheme']}), {r['wall_time_s']:.2f} s wall, {r['newton_iterations']} Newton "
             f"iterations, {r['jacobian_evaluations']} Jacobians",
             "perturbation: " + ", ".join(f"{k}={v:g}" for k, v in r["perturbation"].items()),
             f"smallest tendon force {r['min_tendon_force_N']:.4g} N ({r['min_tendon_force_tendon']})"]
    return "\n".join(lines + _format_outputs(r))


def _format_fe(r: dict) -> str:
    lines = [f"{r['system']} {r['model'].upper()} free vibration ({r['ndof']} DOFs): {r['steps']} steps of "
             f"{r['dt']} s ({r['scheme']}), {r['wall_time_s']:.2f} s wall (static "
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
