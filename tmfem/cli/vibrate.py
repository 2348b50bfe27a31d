"""``tmfem vibrate``: free vibration of the control-oriented model (6.5, Park's method)."""
from __future__ import annotations

import sys

import numpy as np

from tmfem.cli.common import add_system_args, system_from_args
from tmfem.errors import InputError

NAME = "vibrate"
HELP = "free vibration after an initial perturbation (control-oriented model, Park's method)"


def configure(parser) -> None:
    add_system_args(parser)
    parser.add_argument("--model", choices=("com",), default="com",
                        help="com: control-oriented model (ch. 5)")
    parser.add_argument("--membrane-modes", type=int, default=None,
                        help="membrane modes K (default: the dissertation's, 5 for 1-4, 4 for 2-3)")
    parser.add_argument("--t-end", type=float, default=10.0, help="duration [s] (default 10)")
    parser.add_argument("--dt", type=float, default=0.01, help="time step [s] (6.5: 0.01)")
    parser.add_argument("--perturb", action="append", default=[], metavar="STATE=VALUE",
                        help="initial perturbation, e.g. theta_11_dot=0.01 (repeatable)")
    parser.add_argument("--damping", type=float, default=0.0, help="modal damping c_m [1/s] (eq. 5.13)")
    parser.add_argument("--prestress-scale", type=float, default=1.0,
                        help="factor on the designed membrane prestress (1 = designed)")
    parser.add_argument("--mesh", type=int, default=10, help="membrane mesh n per patch (default 10)")
    parser.add_argument("--scheme", choices=("park", "trapezoidal"), default="park")
    parser.add_argument("--csv", help="write the histories to this CSV file (row by row)")
    parser.add_argument("--plot", help="write a plot of the monitored histories (PNG)")
    parser.add_argument("--vtk", metavar="DIR",
                        help="write a ParaView series (.pvd + .vtu frames) to this directory")
    parser.add_argument("--vtk-every", type=int, default=10,
                        help="steps between ParaView frames (default 10)")


def run(args) -> dict:
    from tmfem.reduced.modal import default_membrane_modes
    from tmfem.reduced.model import ControlOrientedModel
    from tmfem.reduced.simulate import free_vibration, parse_perturbation, plot_free_vibration

    system = system_from_args(args)
    K = default_membrane_modes(system) if args.membrane_modes is None else args.membrane_modes
    if not (args.t_end > 0 and args.dt > 0):
        raise InputError(f"expected --t-end > 0 and --dt > 0, found {args.t_end}, {args.dt}")
    print(f"tmfem vibrate: {system.name} COM, K = {K}, building the model", file=sys.stderr)
    model = ControlOrientedModel(system, membrane_modes=K, mesh_n=args.mesh, damping=args.damping,
                                 prestress_scale=args.prestress_scale)
    pert = parse_perturbation(args.perturb, model.state_names)
    res = free_vibration(model, t_end=args.t_end, dt=args.dt, perturb=pert, csv_path=args.csv,
                         scheme=args.scheme, jacobian="reuse", progress=True,
                         vtk_dir=args.vtk, vtk_every=args.vtk_every)
    out = {"system": system.name, "model": "com", "membrane_modes": K, "t_end": args.t_end,
           "dt": args.dt, "perturbation": pert, "scheme": args.scheme,
           "wall_time_s": res.wall_time, "steps": res.stats["steps"],
           "newton_iterations": res.stats["newton_iterations"],
           "jacobian_evaluations": res.stats["jacobian_evaluations"],
           "min_tendon_force_N": res.stats["min_tendon_force"],
           "min_tendon_force_tendon": res.stats["min_tendon_force_tendon"],
           "w_max_abs_m": np.max(np.abs(res.w), axis=0).tolist() if res.w.size else [],
           "node_range_m": {k: np.ptp(v, axis=0).tolist() for k, v in res.nodes.items()},
           "final": dict(zip(model.state_names, np.concatenate([res.z[-1], res.zd[-1]]).tolist()))}
    if args.csv:
        out["csv"] = args.csv
    if "pvd" in res.stats:
        out["pvd"] = res.stats["pvd"]
    if args.plot:
        out["plot"] = plot_free_vibration(res, args.plot,
                                          title=f"{system.name} COM free vibration, K = {K}")
    return out


def format_text(r: dict) -> str:
    lines = [f"{r['system']} COM free vibration: {r['steps']} steps of {r['dt']} s "
             f"({r['scheme']}), {r['wall_time_s']:.2f} s wall, {r['newton_iterations']} Newton "
             f"iterations, {r['jacobian_evaluations']} Jacobians",
             "perturbation: " + ", ".join(f"{k}={v:g}" for k, v in r["perturbation"].items()),
             f"smallest tendon force {r['min_tendon_force_N']:.4g} N ({r['min_tendon_force_tendon']})"]
    for i, w in enumerate(r["w_max_abs_m"]):
        lines.append(f"max |w_{i + 1}| = {1e3 * w:.4f} mm")
    for k, v in r["node_range_m"].items():
        lines.append(f"{k} peak-to-peak (x, y, z) = " + ", ".join(f"{1e3 * a:.3f}" for a in v) + " mm")
    for k in ("csv", "plot", "pvd"):
        if k in r:
            lines.append(f"{k}: {r[k]}")
    return "\n".join(lines)
