"""``tmfem deploy``: closed-loop deployment of a 1-N(D) or 2-3 system (dissertation 7.4).

The dissertation's parameters per deployment (7.4): omega_r of eq. 5.68, the gains of
Table 7.1 (eq. 5.69), the uncertainty model of the controller (eq. 5.72 for 1-4(D), M G
ignored for 1-6(D) and 2-3) and the monitored membrane points of eqs. 5.73-5.75. The
printed points lie on the membrane edges (mid-edge points of the polygon); they are moved
1 mm toward the centroid so that they fall inside the mesh (docs/errata.md).
"""
from __future__ import annotations

import csv
import time

import numpy as np

from tmfem.cli.common import progress_bar
from tmfem.errors import ConvergenceError, InputError

NAME = "deploy"
HELP = "deploy a system from its packaged to its deployed configuration (adaptive PFL, switch to a linear controller)"

#: 7.4: omega_r (eq. 5.68), Table 7.1 (omega_0, omega_e, tau, d_c), uncertainty, points (5.73-5.75)
DEPLOYMENTS = {
    "1-4D": {"omega_r": 0.7, "table_7_1": (15.0, 150.0, 20.0, 1.5), "uncertainty": "initial",
             "points": [(1.0, 1.0), (2.0, 1.0), (1.0, 2.0)], "u_m": 0.01, "path": "delta"},
    "1-6D": {"omega_r": 0.35, "table_7_1": (4.0, 10.0, 20.0, 0.7), "uncertainty": "no-MG",
             "points": [(1.0, 1.732), (2.5, 0.866), (2.5, 2.598)], "u_m": 0.02, "path": "delta"},
    "2-3-deploy": {"omega_r": 0.5, "table_7_1": (1.0, 24.0, 5.0, 0.9), "uncertainty": "no-MG",
                   "points": [(0.866, 0.5), (1.30, 0.75), (0.433, 0.75)], "u_m": 0.01,
                   "path": "table-7-7-bases"},
}
CONTROLLERS = {"adaptive-hinf": "lmi", "adaptive-hinf-riccati": "hinf", "adaptive-lqr": "lqr",
               "adaptive": "none"}


def inside_points(system, points, *, inset: float = 1e-3):
    """The points moved ``inset`` metres toward the membrane centroid (see module docstring)."""
    c = system.membrane_corners.mean(axis=1)
    out = []
    for p in points:
        p = np.asarray(p, dtype=float)
        d = c - p
        out.append(tuple(p + inset * d / np.linalg.norm(d)))
    return out


def setup(preset: str, *, controller: str = "adaptive-hinf", uncertainty: str | None = None,
          allocation: str = "bounded", path: str | None = None):
    """The deployment of ``preset`` with the 7.4 parameters (:func:`build_deployment`).
    ``path`` (default the preset's): ``"delta"`` (1-N(D): psi_r from eq. 3.22 with the
    membrane stretch Delta linear in s), ``"table-7-7-bases"`` (2-3: the stage-2 base on the
    reconstructed Table 7.7 rule, :func:`tmfem.reference.tables.deployment_bases`) or
    ``"linear"`` (every symmetric parameter linear in s)."""
    from tmfem.control.adaptive import Gains
    from tmfem.control.deploy import build_deployment
    from tmfem.reference.tables import deployment_bases
    from tmfem.system.presets import load_preset
    if preset not in DEPLOYMENTS:
        raise InputError(f"deploy: expected a preset among {sorted(DEPLOYMENTS)}, found {preset!r}")
    if controller not in CONTROLLERS:
        raise InputError(f"--controller: expected one of {sorted(CONTROLLERS)}, found {controller!r}")
    p = DEPLOYMENTS[preset]
    path = path or p["path"]
    if path not in ("linear", p["path"]):
        raise InputError(f"--path for {preset}: expected 'linear' or {p['path']!r}, found {path!r}")
    final, initial = load_preset(preset), load_preset(preset + "-initial")
    w0, we, tau, dc = p["table_7_1"]
    return build_deployment(final=final, initial=initial, omega_r=p["omega_r"],
                            gains=Gains(omega_0=w0, omega_e=we, tau=tau, d_c=dc),
                            uncertainty=uncertainty or p["uncertainty"],
                            output_points=inside_points(final, p["points"]),
                            linear=CONTROLLERS[controller], u_m=p["u_m"],
                            bases=deployment_bases(final) if path == "table-7-7-bases" else None,
                            delta_path=path == "delta",
                            allocation=allocation)


def configure(parser) -> None:
    parser.add_argument("--preset", required=True, choices=sorted(DEPLOYMENTS))
    parser.add_argument("--controller", default="adaptive-hinf", choices=sorted(CONTROLLERS),
                        help="adaptive PFL then a linear controller about the final equilibrium: "
                             "adaptive-hinf (the LMI H-infinity controller of 7.3, tmfem control), "
                             "adaptive-hinf-riccati (python-control hinfsyn), adaptive-lqr (LQR "
                             "state feedback) or adaptive (no switch)")
    parser.add_argument("--uncertainty", choices=["initial", "no-MG", "exact"],
                        help="controller model error (default: the 7.4 choice of the preset)")
    parser.add_argument("--path", choices=["delta", "table-7-7-bases", "linear"],
                        help="deployment path (default: delta for 1-N(D), table-7-7-bases for 2-3; "
                             "linear: every symmetric parameter linear in the progress)")
    parser.add_argument("--allocation", choices=["bounded", "clip"], default="bounded",
                        help="rest-length limits in the PFL: bounded (the admissible rest lengths "
                             "closest in acceleration, default) or clip (eq. 5.58 as is, saturated "
                             "by the plant)")
    parser.add_argument("--plant", choices=["com", "mtc"], default="com",
                        help="the model the controller drives: com (the control-oriented model it "
                             "is designed on, default) or mtc (the membrane-truss-cable FE model, "
                             "read through the COM-state estimate; systems without H_1j nodes)")
    parser.add_argument("--plant-mesh", type=int, metavar="N",
                        help="membrane elements per side of each of the FE plant's N "
                             "quadrilaterals (--plant mtc; default 10, the paper's mesh)")
    parser.add_argument("--plant-tendons", choices=["cable", "fixed-rate"],
                        help="tendon law of the FE plant (--plant mtc): cable (EA fixed, the rate "
                             "EA/r of eq. 3.9 follows the rest length; default) or fixed-rate (the "
                             "rate frozen at the final rest lengths, as eq. 5.19 and the COM)")
    parser.add_argument("--t-end", type=float, default=20.0)
    parser.add_argument("--dt", type=float, default=0.01)
    parser.add_argument("--csv", help="write every named signal (one column each)")
    parser.add_argument("--plot", help="PNG as Figures 7.2-7.4")
    parser.add_argument("--gif", help="animation of the deployment (GIF)")
    parser.add_argument("--vtk", metavar="DIR", help="ParaView series of the configuration")


def run(args) -> dict:
    from tmfem.simulation.driver import check_time_grid
    check_time_grid(args.t_end, args.dt)            # refused before the controller design
    mesh_n = check_plant(args)
    t0 = time.perf_counter()
    s = setup(args.preset, controller=args.controller, uncertainty=args.uncertainty,
              allocation=args.allocation, path=args.path)
    from tmfem.control.deploy import run_deployment
    plant = None
    if args.plant == "mtc":
        from tmfem.control.state_estimate import mtc_deployment_plant
        from tmfem.system.presets import load_preset
        plant = mtc_deployment_plant(s.model, load_preset(args.preset + "-initial"),
                                     mesh_n=mesh_n, tendon_law=args.plant_tendons or "cable")
    with progress_bar(args.t_end, args.dt, f"deploy {args.preset} on {args.plant}") as bar:
        try:
            r = run_deployment(model=s.model, reference=s.reference, controller=s.controller,
                               z0=s.z0, t_end=args.t_end, dt=args.dt, progress=bar, plant=plant,
                               jacobian="reuse" if plant is None else "step")
        except ConvergenceError as exc:
            if plant is None:
                raise
            raise ConvergenceError(f"the closed loop on the {args.plant} plant diverged: {exc} "
                                   "(docs/fe-plant.md)") from None
    out = {"preset": args.preset, "controller": args.controller, "plant": args.plant,
           **({"plant_tendons": args.plant_tendons or "cable", "plant_mesh": mesh_n}
              if args.plant == "mtc" else {}),
           "uncertainty": s.adaptive.uncertainty, "allocation": s.adaptive.allocation,
           "path": args.path or DEPLOYMENTS[args.preset]["path"],
           **r.summary(), **s.info,
           "total_wall_time_s": time.perf_counter() - t0}
    if args.csv:
        out["csv"] = write_csv(args.csv, r)
    if args.plot:
        from tmfem.post.deploy_plots import plot_deployment
        out["plot"] = str(plot_deployment(args.plot, r, title=f"{args.preset} ({args.controller})"))
    if args.gif:
        from tmfem.post.deploy_plots import animate_deployment
        out["gif"] = str(animate_deployment(args.gif, s.model.system, r))
    if args.vtk:
        from tmfem.io.codes import configuration_cells
        from tmfem.io.series import write_series
        sysm = s.model.system
        cells = configuration_cells(sysm)
        idx = range(0, r.t.size, 10)
        out["pvd"] = str(write_series(args.vtk, ((float(r.t[k]), sysm.nodes(r.z[k, :s.model.nq]),
                                                  cells) for k in idx), name=args.preset))
    return out


def check_plant(args) -> int | None:
    """The FE plant's options, checked before any work: ``--plant-mesh`` belongs to
    ``--plant mtc``; the MTC model has no nodes along the bars, so no 1-N(D) system; the
    mesh within the machine's budget. Returns the plant mesh (None for the COM plant)."""
    from tmfem.cli.common import check_mesh_budget
    from tmfem.system.presets import load_preset
    if args.plant == "com":
        for opt, val in (("--plant-mesh", args.plant_mesh), ("--plant-tendons", args.plant_tendons)):
            if val is not None:
                raise InputError(f"{opt} belongs to --plant mtc (the COM plant has neither a "
                                 f"membrane mesh nor FE tendons), found {opt} {val} with --plant com")
        return None
    system = load_preset(args.preset)
    if system.deployable:
        raise InputError(f"--plant mtc: {args.preset} is a 1-N(D) system (tendons attached at "
                         "H_1j along the bars), which the MTC model cannot represent; expected a "
                         "system without H_1j nodes (2-3-deploy), or --plant com")
    n = 10 if args.plant_mesh is None else args.plant_mesh
    if n < 2:
        raise InputError(f"--plant-mesh: expected an integer >= 2, found {n}")
    check_mesh_budget(N=system.N, n=n, option="--plant-mesh")
    return n


def write_csv(path, r) -> str:
    """One column per named signal: time, q, q_d, w, rest lengths, tendon lengths, controller."""
    n = r.names
    head = (["t"] + n["q"] + [f"{q}_d" for q in n["q"]] + n["w"] + n["u"]
            + [f"L_{t}" for t in n["tendons"]] + ["eta_energy", "controller"])
    nq = len(n["q"])
    with open(path, "w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(head)
        for k in range(r.t.size):
            wr.writerow([f"{r.t[k]:.6g}"] + [f"{v:.10g}" for v in r.z[k, :nq]]
                        + [f"{v:.10g}" for v in r.q_d[k]] + [f"{v:.10g}" for v in r.w[k]]
                        + [f"{v:.10g}" for v in r.u[k]] + [f"{v:.10g}" for v in r.lengths[k]]
                        + [f"{r.eta_energy[k]:.6g}", r.controller[min(k, len(r.controller) - 1)]])
    return str(path)


def format_text(r: dict) -> str:
    keys = ["switch_time_s", "t_end_s", "max_membrane_deflection_m", "peak_bar_compression_N",
            "bar_critical_load_N", "max_von_mises_Pa", "max_tendon_stress_Pa",
            "min_rest_length_margin_m", "final_tracking_error", "limits_active_s",
            "max_eta_energy_J", "B_q_condition_max", "wall_time_s"]
    keys += [k for k in r if k.startswith("plant_")]
    lines = [f"deployment {r['preset']} on the {r['plant']} plant ({r['controller']}, "
             f"uncertainty {r['uncertainty']})"]
    lines += [f"  {k}: {r[k]:.6g}" if isinstance(r[k], float) else f"  {k}: {r[k]}" for k in keys]
    return "\n".join(lines + [f"{k}: {r[k]}" for k in ("csv", "plot", "gif", "pvd") if k in r])
