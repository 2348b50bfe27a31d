"""``tmfem deploy``: closed-loop deployment of a system from its packaged to its deployed
configuration (dissertation 7.4, 8.4).

The parameters of a deployment are the system file's (``[packaged]``, ``[deployment]``,
``[control]``, ``[lpv]``: :mod:`tmfem.reference.deployments`, docs/guides/system-file.md).
Every option and output path is checked before the controller design (docs/guides/cli.md).
"""
from __future__ import annotations

import time
from dataclasses import astuple

from tmfem import reference
from tmfem.cli import deploy_lpv
from tmfem.cli.common import (check_frames, check_mesh_budget, check_time_steps, output_dir,
                              output_file, positive_float, progress_bar, warn)
from tmfem.cli.uncontrollable import add_uncontrollable_arg, excluded_text, with_uncontrollable
from tmfem.errors import InputError
from tmfem.models.com.mode_count import MembraneModeChoice
from tmfem.models.com.model import membrane_modes_of
from tmfem.reference.deployments import (CONTROLLERS, LPV_CONTROLLERS, UNCERTAINTIES, check_choices,
                                         VTK_EVERY, own_path, setup, write_outputs)

NAME = "deploy"
HELP = "deploy a system from its packaged to its deployed configuration (adaptive PFL, switch to a linear controller)"

def configure(parser) -> None:
    parser.add_argument("spec", nargs="?", help="system file (TOML) with [packaged] and "
                                                "[deployment] tables; or use --preset")
    from tmfem.system.presets import list_presets
    parser.add_argument("--preset", choices=list_presets(),
                        help="built-in system with a deployment (1-4D, 1-6D, 2-3-deploy; "
                             "2-3-lpv: the LPV deployment of 8.4)")
    parser.add_argument("--controller", default=None, choices=sorted(CONTROLLERS) + list(LPV_CONTROLLERS),
                        help="7.4 presets: adaptive PFL then a linear controller about the final equilibrium: "
                             "adaptive-hinf (default; the H-infinity controller of 7.3: the central one at "
                             "1.01 gamma_opt, tmfem control hinf --method central), "
                             "adaptive-hinf-riccati (python-control hinfsyn), adaptive-lqr (LQR "
                             "state feedback) or adaptive (no switch); LPV presets (8.4): lpv (default; "
                             "the scheduled state feedback of 8.3) or lpv-output (its observer-based output "
                             "feedback on the "
                             "measured q and membrane points, docs/guides/lpv.md)")
    parser.add_argument("--uncertainty", choices=list(UNCERTAINTIES),
                        help="controller model error (default: the file's [deployment] uncertainty, else no-MG)")
    parser.add_argument("--path", choices=["delta", "auto", "table-7-7-bases", "linear"],
                        help="deployment path (default: the file's [deployment] path, else delta for "
                             "1-N(D) and auto for M >= 2 (stage bases continued through the symmetric "
                             "equilibria, docs/guides/deployment.md); table-7-7-bases for 2-3; "
                             "linear: every symmetric parameter linear in the progress)")
    parser.add_argument("--allocation", choices=["bounded", "clip"], default=None,
                        help="rest-length limits in the PFL: bounded (the admissible rest lengths "
                             "closest in acceleration, default) or clip (eq. 5.58 as is, saturated "
                             "by the plant)")
    parser.add_argument("--plant", choices=["com", "mtc", "sbc"], default="com",
                        help="the model the controller drives: com (the control-oriented model it "
                             "is designed on, default), mtc (the membrane-truss-cable FE model; "
                             "systems without H_1j nodes) or sbc (the shell-beam-cable FE model, "
                             "any system), the FE plants read through the COM-state estimate")
    parser.add_argument("--plant-mesh", type=int, metavar="N",
                        help="membrane elements per side of each of the FE plant's N "
                             "quadrilaterals (--plant or --compare-plant mtc|sbc; default 10, the "
                             "paper's mesh)")
    parser.add_argument("--plant-tendons", choices=["cable", "fixed-rate"],
                        help="tendon law of the MTC plant (--plant or --compare-plant mtc): cable "
                             "(EA fixed, the rate EA/r of eq. 3.9 follows the rest length; "
                             "default) or fixed-rate (the rate frozen at the final rest lengths, as "
                             "eq. 5.19 and the COM); the SBC model has the cable law only; the "
                             "adaptive PFL's tendon model follows the plant's law (fixed rates under "
                             "uncertainty 'initial', eq. 5.72)")
    parser.add_argument("--plant-bars", choices=["chord", "rigid"],
                        help="how the SBC plant's state estimate measures the bar coordinates q "
                             "(--plant or --compare-plant sbc): rigid (the rigid bars closest to "
                             "the beam nodes in the kinetic-energy norm: the bending modes do not "
                             "move them; default) or chord (the bar end nodes, which see the "
                             "beams' bending modes: the LPV loop diverges with them, "
                             "docs/guides/fe-plant.md)")
    parser.add_argument("--plant-damping", type=positive_float, metavar="BETA",
                        help="stiffness-proportional Rayleigh damping C = BETA K_0 [s] of the FE "
                             "plant (--plant or --compare-plant mtc|sbc; default none: the "
                             "undamped plant)")
    parser.add_argument("--plant-damping-tangent", choices=["current", "initial"],
                        help="the tangent of the FE plant's damping (--plant-damping): current "
                             "(C_n = BETA K_T(x_n), the tangent at every sampled state, held over "
                             "the step: a bar's rigid rotation meets no axial damping; default) or "
                             "initial (C = BETA K_0, the tangent at the packaged equilibrium, which "
                             "drags the deploying bars, docs/guides/fe-plant.md)")
    parser.add_argument("--plant-actuation", choices=["rest-length", "force"],
                        help="the FE plant's tendon actuators (--plant or --compare-plant "
                             "mtc|sbc): rest-length (the commanded rest lengths are set on the FE "
                             "tendons, the dissertation's actuators; default) or force "
                             "(tension-servoed winches: the command becomes the COM's tendon force "
                             "k (|d(q)| - u) at the measured q, realised on the FE tendon at its "
                             "measured length and held over the sample; the PFL's tendon model is "
                             "then the COM's fixed rates, docs/guides/fe-plant.md)")
    parser.add_argument("--compare-plant", choices=["com", "mtc", "sbc"],
                        help="run the same deployment on this plant too and compare (JSON "
                             "'compare': its figures and the deviation between the plants)")
    parser.add_argument("--compare-plot", help="PNG: both runs overlaid and their deviation over "
                                               "time (--compare-plant)")
    parser.add_argument("--compare-csv", help="the CSV of the --compare-plant run (the same "
                                              "columns as --csv)")
    parser.add_argument("--pfl-at", choices=["state", "reference"],
                        help="where the adaptive PFL evaluates its model terms: state (the "
                             "measured state, eq. 5.58; default without an FE plant) or reference (the "
                             "reference q_d, q_d' with the measured membrane coordinates: the "
                             "plant's own stiffness stays in the loop; default with an FE "
                             "plant, where the law at the state diverges, docs/guides/fe-plant.md); "
                             "a --compare-plant run uses the same controller")
    parser.add_argument("--gains", type=pfl_gains, metavar="OMEGA_0,OMEGA_E,TAU,D_C",
                        help="the adaptive PFL's gains of eq. 5.69, omega(t) = omega_0 + omega_e "
                             "(1 - exp(-t / tau)), d_q = 2 d_c omega, k_q = omega^2, in rad/s, "
                             "rad/s, s and - (default: the file's [deployment] gains, else 4,10,20,0.9; the "
                             "presets carry their Table 7.1 rows, e.g. 1-4D 15,150,20,1.5). A crossover below the "
                             "FE plant's unmodelled "
                             "dynamics, e.g. 10,0,20,1 with --uncertainty no-MG, deploys 1-4D on "
                             "the SBC plant (docs/guides/fe-plant.md)")
    add_uncontrollable_arg(parser, what="the deployment's switch")
    parser.add_argument("--t-end", type=positive_float, default=20.0, help="duration [s]")
    parser.add_argument("--dt", type=positive_float, default=0.01, help="sample time [s]")
    parser.add_argument("--allow-infeasible", action="store_true",
                        help="exit 0 when a strength check of the run fails (tendon or membrane yield, bar "
                             "buckling); the failed checks are still printed and listed in the JSON")
    parser.add_argument("--csv", help="write every named signal (one column each, units in the header)")
    parser.add_argument("--plot", help="PNG as Figures 7.2-7.4")
    parser.add_argument("--gif", help="animation of the deployment (GIF)")
    parser.add_argument("--vtk", metavar="DIR", help="ParaView series of the configuration")
    deploy_lpv.configure(parser)


def deployed_system(args):
    """``args.system``: the System of ``spec`` or ``--preset`` (exactly one); ``args.preset``
    becomes its label in titles and the JSON (the preset name, or the file's system name)."""
    from tmfem.cli.common import system_from_args
    args.as_printed = False
    args.system = system_from_args(args)
    if args.preset is None:
        args.preset = args.system.name
    pr = args.system.problem
    if pr.lpv is None and (pr.packaged is None or pr.deployment is None):
        check_choices(args.system)                   # names the missing tables
    return args.system


def pfl_gains(text: str) -> tuple:
    """argparse ``type`` of ``--gains``: four comma-separated numbers omega_0, omega_e, tau,
    d_c (checked by :class:`tmfem.control.deployment.adaptive.Gains`)."""
    import argparse
    from tmfem.control.deployment.adaptive import Gains
    parts = text.split(",")
    try:
        values = tuple(float(v) for v in parts)
    except ValueError:
        values = ()
    if len(values) != 4:
        raise argparse.ArgumentTypeError(f"expected four comma-separated numbers OMEGA_0,OMEGA_E,"
                                         f"TAU,D_C, found {text!r}")
    try:
        Gains(*values)
    except InputError as e:
        raise argparse.ArgumentTypeError(str(e)) from None
    return values


def run(args) -> dict:
    # refused before the controller design: time grid, output paths
    steps = check_time_steps(t_end=args.t_end, dt=args.dt)
    if args.vtk is not None:
        check_frames(steps=steps, every=VTK_EVERY, option=None)
    output_file(args.csv, option="--csv", suffixes=(".csv",))
    output_file(args.plot, option="--plot", suffixes=(".png",))
    output_file(args.gif, option="--gif", suffixes=(".gif",))
    output_dir(args.vtk, option="--vtk")
    output_file(args.compare_plot, option="--compare-plot", suffixes=(".png",))
    output_file(args.compare_csv, option="--compare-csv", suffixes=(".csv",))
    deployed_system(args)
    # a file with [lpv] and without [deployment] deploys by LPV; one with both, by the 7.4 PFL
    # unless an LPV controller is asked for
    pr = args.system.problem
    args.controller = args.controller or ("lpv" if pr.lpv is not None and pr.deployment is None else "adaptive-hinf")
    lpv = args.controller in LPV_CONTROLLERS
    if not (pr.lpv is not None if lpv else pr.deployment is not None or pr.lpv is None):
        own = not lpv                                  # the deployment the file carries
        raise InputError(f"--controller {args.controller}: expected one of "
                         f"{list(LPV_CONTROLLERS) if own else sorted(CONTROLLERS)} for the "
                         f"{'LPV deployment (8.4)' if own else '7.4 deployment'} of {args.preset}")
    if lpv:
        with_uncontrollable(args.system, exclude=args.exclude_uncontrollable, controller=args.controller)
        deploy_lpv.check(args)
        return deploy_lpv.run(args, mesh_n=check_plant(args))
    lpv_opts = deploy_lpv.given(args, ("lpv_controller", "noise", "estimator_interpolation",
                                       "estimator_refine") + deploy_lpv.SYNTHESIS)
    if lpv_opts:
        raise InputError(f"options {lpv_opts} apply to --controller lpv only, found --controller {args.controller}")
    args.allocation = args.allocation or "bounded"
    args.system = with_uncontrollable(args.system, exclude=args.exclude_uncontrollable,
                                      controller=args.controller)
    check_choices(args.system, controller=args.controller, uncertainty=args.uncertainty,
                  path=args.path)
    mesh_n = check_plant(args)
    t0 = time.perf_counter()
    plants = reference.FEPlantOptions.of(args)
    pfl_at = plants.pfl_evaluation(args.pfl_at)
    tendons = plants.pfl_tendon_model(args.uncertainty or args.system.problem.deployment.uncertainty)
    s = setup(args.system, controller=args.controller, uncertainty=args.uncertainty,
              allocation=args.allocation, path=args.path, evaluation=pfl_at,
              tendon_law=tendons, gains=args.gains)
    warnings = plants.tendon_model_warnings(tendons)
    for w in warnings:
        warn(NAME, w)
    r = _run_on(args, s, args.plant, mesh_n)
    # the controller's options, the same on both plants of a comparison (docs/guides/fe-plant.md)
    ctrl = {"controller": args.controller, "uncertainty": s.adaptive.uncertainty,
            "allocation": s.adaptive.allocation, "pfl_at": pfl_at, "pfl_tendon_model": tendons,
            "pfl_gains": list(astuple(s.adaptive.gains))}
    out = {"system": args.system.name, "plant": args.plant, **plants.summary(args.plant, mesh_n),
           **ctrl, "path": args.path or own_path(args.system),
           **r.summary(), **s.info}
    title = (f"{args.preset} deployment on the {args.plant} plant: {args.controller}, "
             f"uncertainty {s.adaptive.uncertainty}")
    out.update(write_outputs(s, r, preset=args.preset, csv_path=args.csv, plot=args.plot,
                             gif=args.gif, vtk=args.vtk, title=title, lpv=False))
    saturated = saturation_warning(out, omega_r=args.system.problem.deployment.omega_r)
    if saturated:
        warn(NAME, saturated)
    out["warnings"] = warnings + ([saturated] if saturated else [])
    out["membrane_mode_choice"] = membrane_modes_of(s.model.system).to_dict()
    if args.compare_plant:
        def rerun(kind):
            s2 = setup(args.system, controller=args.controller, uncertainty=args.uncertainty,
                       allocation=args.allocation, path=args.path, evaluation=pfl_at,
                       tendon_law=tendons, gains=args.gains)
            return _run_on(args, s2, kind, mesh_n), {}
        out["compare"] = reference.compare_plants(
            r, rerun, options=plants, preset=args.preset, csv=args.compare_csv, plot=args.compare_plot,
            mesh_n=mesh_n, controller=ctrl,
            about=f"PFL at the {pfl_at}, its tendon model {tendons}, uncertainty "
                  f"{s.adaptive.uncertainty}, allocation {s.adaptive.allocation}, gains "
                  f"{','.join(f'{g:g}' for g in astuple(s.adaptive.gains))}")
    out["total_wall_time_s"] = time.perf_counter() - t0
    # a diverged closed loop is a failed check: the result and the files of the record up
    # to the failure are written, the exit code is 1 (docs/guides/cli.md, docs/guides/fe-plant.md)
    out["failed_checks"] = (reference.diverged([(args.plant, out), (args.compare_plant, out.get("compare", {}))])
                            + out.get("strength_checks_failed", []))
    return out


def saturation_warning(r: dict, *, omega_r: float) -> str | None:
    """A hint when a deployment with a switch never met its switch condition while its rest
    lengths sat at their limits for at least half the run (``limits_active_s`` of the result
    ``r``): the reference of eq. 5.68 moves faster than the tendons can follow. None otherwise."""
    t, active = r["t_end_s"], r.get("limits_active_s") or 0.0
    if r.get("switch_time_s") is not None or r["controller"] == "adaptive" or active < 0.5 * t:
        return None
    return (f"no switch before t_end: the rest lengths sat at their limits for {active:.3g} of {t:.3g} s, so the "
            f"reference (eq. 5.68, omega_r = {omega_r:g} rad/s) outruns what the tendons can do; a slower "
            "reference ([deployment] omega_r) or a longer --t-end lets the deployment settle and switch")


def _run_on(args, s, plant_kind: str, mesh_n):
    """The deployment of set-up ``s`` on ``plant_kind``
    (:func:`tmfem.reference.deployment_plants.run_on_plant`)."""
    with progress_bar(args.t_end, args.dt, f"deploy {args.preset} on {plant_kind}") as bar:
        return reference.run_on_plant(s, kind=plant_kind, options=reference.FEPlantOptions.of(args),
                                      initial=s.model.system.problem.packaged, mesh_n=mesh_n,
                                      t_end=args.t_end, dt=args.dt, progress=bar)


def check_plant(args) -> int | None:
    """The FE plants' options, checked before any work: ``--plant-mesh``,
    ``--plant-damping`` (and ``--plant-damping-tangent``, which needs it) and
    ``--plant-actuation`` belong to an FE plant (force actuation on
    the COM plant is refused: the COM is the design model), ``--plant-tendons`` to an MTC
    plant (the SBC model has the cable law only), ``--plant-bars`` to an SBC plant; the
    MTC model has no nodes along the bars, so no 1-N(D) system; ``--compare-plant`` differs
    from ``--plant`` and ``--compare-plot``/``--compare-csv`` need it; the mesh within the
    machine's budget. Returns the plant mesh (None without an FE plant)."""
    plants = [args.plant] + ([args.compare_plant] if args.compare_plant else [])
    for opt in ("--compare-plot", "--compare-csv"):
        if getattr(args, opt[2:].replace("-", "_")) and not args.compare_plant:
            raise InputError(f"{opt} belongs to --compare-plant (the second plant of the same "
                             f"deployment), found {opt} without it")
    if args.compare_plant == args.plant:
        raise InputError(f"--compare-plant: expected a plant other than --plant {args.plant}, "
                         f"found {args.compare_plant}")
    fe = [p for p in plants if p != "com"]
    if args.plant_bars is not None and "sbc" not in fe:
        raise InputError(f"--plant-bars belongs to an SBC plant (beam bars with nodes along them; "
                         f"the MTC bars are straight trusses), expected --plant sbc or "
                         f"--compare-plant sbc, found --plant-bars {args.plant_bars} with "
                         f"{' and '.join(plants)}")
    if not fe:
        if reference.FEPlantOptions.of(args).actuation() == "force":
            raise InputError("--plant-actuation force belongs to an FE plant (--plant or "
                             "--compare-plant mtc|sbc): the COM is the design model, whose tendon "
                             "forces k (|d(q)| - u) are what the force actuator reproduces on an FE "
                             "plant; found --plant-actuation force with --plant com")
        for opt, val, fe_kinds in (("--plant-mesh", args.plant_mesh, "mtc|sbc"),
                                   ("--plant-tendons", args.plant_tendons, "mtc"),
                                   ("--plant-damping", args.plant_damping, "mtc|sbc"),
                                   ("--plant-damping-tangent", args.plant_damping_tangent,
                                    "mtc|sbc"),
                                   ("--plant-actuation", args.plant_actuation, "mtc|sbc")):
            if val is not None:
                raise InputError(f"{opt} belongs to --plant {fe_kinds} or --compare-plant "
                                 f"{fe_kinds} (the COM plant has no membrane mesh, FE tendons, FE "
                                 f"damping or FE actuators), found {opt} {val} with --plant com")
        return None
    if args.plant_damping_tangent is not None and not args.plant_damping:
        raise InputError(f"--plant-damping-tangent belongs to --plant-damping (the tangent of "
                         f"the FE plant's damping C = BETA K), found --plant-damping-tangent "
                         f"{args.plant_damping_tangent} without --plant-damping")
    if args.plant_tendons is not None and "mtc" not in fe:
        raise InputError(f"--plant-tendons belongs to an MTC plant: the SBC model has the cable "
                         f"law only (EA fixed, k = EA / r); expected no --plant-tendons with "
                         f"--plant sbc, found --plant-tendons {args.plant_tendons}")
    system = args.system if getattr(args, "system", None) is not None else deployed_system(args)
    if system.deployable and "mtc" in fe:
        raise InputError(f"--plant mtc: {args.preset} is a 1-N(D) system (tendons attached at "
                         "H_1j along the bars), which the MTC model cannot represent; expected a "
                         "system without H_1j nodes (2-3-deploy), --plant sbc or --plant com")
    n = 10 if args.plant_mesh is None else args.plant_mesh
    if n < 2:
        raise InputError(f"--plant-mesh: expected an integer >= 2, found {n}")
    check_mesh_budget(N=system.N, n=n, option="--plant-mesh")
    return n


#: the text of a result entry that is None (JSON null)
_NONE_TEXT = {"switch_time_s": "none (the switch condition was not met before t_end)",
              "failure": "none"}


def _value_text(key: str, value) -> str:
    """One value of the text summary: a float to 6 digits, None in words."""
    if value is None:
        return _NONE_TEXT.get(key, "none")
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def format_text(r: dict) -> str:
    keys = ["switch_time_s", "t_end_s", "max_membrane_deflection_m", "peak_bar_compression_N",
            "bar_critical_load_N", "max_von_mises_Pa", "max_tendon_stress_Pa",
            "min_rest_length_margin_m", "final_tracking_error", "limits_active_s",
            "max_eta_energy_J", "B_q_condition_max", "wall_time_s"]
    keys += [k for k in r if k.startswith("plant_")] + ["failure"]
    keys += [k for k in ("gamma", "max_tracking_error") if k in r]
    lines = [f"deployment {r['system']} on the {r['plant']} plant ({r['controller']}, "
             f"uncertainty {r['uncertainty']})"]
    if "membrane_mode_choice" in r:
        lines.append("  COM: " + MembraneModeChoice(**r["membrane_mode_choice"]).text)
    if "excluded_modes_hz" in r:
        lines.append("  " + excluded_text(r["excluded_modes_hz"]))
    lines += [f"  {k}: {_value_text(k, r[k])}" for k in keys]
    if "compare" in r:
        c = r["compare"]
        lines.append(f"  on the {c['plant']} plant: switch_time_s {c['switch_time_s']}, "
                     f"final_tracking_error {c['final_tracking_error']:.6g}, failure {c['failure']}")
        lines += [f"  deviation {k}: {v}" for k, v in c["deviation"].items()]
        lines += [f"compare {k}: {c[k]}" for k in ("csv", "plot") if k in c]
    return "\n".join(lines + [f"{k}: {r[k]}" for k in ("csv", "plot", "gif", "pvd") if k in r])
