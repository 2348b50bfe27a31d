"""``tmfem deploy``: closed-loop deployment of a 1-N(D) or 2-3 system (dissertation 7.4).

The 7.4 parameters of each deployment are :data:`tmfem.reference.deployments.DEPLOYMENTS`.
Every option and output path is checked before the controller design (docs/cli.md).
"""
from __future__ import annotations

import time

from tmfem.cli.common import (check_time_steps, output_dir, output_file, positive_float,
                              progress_bar)
from tmfem.errors import ConvergenceError, InputError
from tmfem.reference.deployments import (CONTROLLERS, DEPLOYMENTS, UNCERTAINTIES, check_choices,
                                         setup, write_outputs)

NAME = "deploy"
HELP = "deploy a system from its packaged to its deployed configuration (adaptive PFL, switch to a linear controller)"

def configure(parser) -> None:
    parser.add_argument("--preset", required=True, choices=sorted(DEPLOYMENTS))
    parser.add_argument("--controller", default="adaptive-hinf", choices=sorted(CONTROLLERS),
                        help="adaptive PFL then a linear controller about the final equilibrium: "
                             "adaptive-hinf (the LMI H-infinity controller of 7.3, tmfem control), "
                             "adaptive-hinf-riccati (python-control hinfsyn), adaptive-lqr (LQR "
                             "state feedback) or adaptive (no switch)")
    parser.add_argument("--uncertainty", choices=list(UNCERTAINTIES),
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
                             "rate frozen at the final rest lengths, as eq. 5.19 and the COM); the "
                             "adaptive PFL's tendon model follows it")
    parser.add_argument("--pfl-at", choices=["state", "reference"],
                        help="where the adaptive PFL evaluates its model terms: state (the "
                             "measured state, eq. 5.58; default on --plant com) or reference (the "
                             "reference q_d, q_d' with the measured membrane coordinates: the "
                             "plant's own stiffness stays in the loop; default on --plant mtc, "
                             "where the law at the state diverges, docs/fe-plant.md)")
    parser.add_argument("--t-end", type=positive_float, default=20.0, help="duration [s]")
    parser.add_argument("--dt", type=positive_float, default=0.01, help="sample time [s]")
    parser.add_argument("--csv", help="write every named signal (one column each, units in the header)")
    parser.add_argument("--plot", help="PNG as Figures 7.2-7.4")
    parser.add_argument("--gif", help="animation of the deployment (GIF)")
    parser.add_argument("--vtk", metavar="DIR", help="ParaView series of the configuration")


def run(args) -> dict:
    # refused before the controller design: time grid, output paths
    check_time_steps(t_end=args.t_end, dt=args.dt)
    output_file(args.csv, option="--csv", suffixes=(".csv",))
    output_file(args.plot, option="--plot", suffixes=(".png",))
    output_file(args.gif, option="--gif", suffixes=(".gif",))
    output_dir(args.vtk, option="--vtk")
    check_choices(args.preset, controller=args.controller, uncertainty=args.uncertainty,
                  path=args.path)
    mesh_n = check_plant(args)
    t0 = time.perf_counter()
    pfl_at = args.pfl_at or ("state" if args.plant == "com" else "reference")
    # the PFL's tendon model is the plant's tendon law (docs/fe-plant.md)
    tendons = "fixed-rate" if args.plant == "com" else args.plant_tendons or "cable"
    s = setup(args.preset, controller=args.controller, uncertainty=args.uncertainty,
              allocation=args.allocation, path=args.path, evaluation=pfl_at,
              tendon_law=tendons)
    from tmfem.control.deploy import run_deployment
    plant = None
    if args.plant == "mtc":
        from tmfem.control.state_estimate import mtc_deployment_plant
        from tmfem.system.presets import load_preset
        plant = mtc_deployment_plant(s.model, load_preset(args.preset + "-initial"),
                                     mesh_n=mesh_n, tendon_law=tendons)
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
           **({"plant_tendons": tendons, "plant_mesh": mesh_n}
              if args.plant == "mtc" else {}),
           "uncertainty": s.adaptive.uncertainty, "allocation": s.adaptive.allocation,
           "pfl_at": pfl_at,
           "path": args.path or DEPLOYMENTS[args.preset]["path"],
           **r.summary(), **s.info,
           "total_wall_time_s": time.perf_counter() - t0}
    out.update(write_outputs(s, r, preset=args.preset, csv_path=args.csv, plot=args.plot,
                             gif=args.gif, vtk=args.vtk,
                             title=f"{args.preset} deployment on the {args.plant} plant: {args.controller}, "
                                   f"uncertainty {s.adaptive.uncertainty}"))
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
