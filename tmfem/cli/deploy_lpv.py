"""``tmfem deploy --preset 2-3-lpv --controller lpv``: the LPV deployment of 8.4 (called by
:mod:`tmfem.cli.deploy`).

The controller is loaded (``--lpv-controller saved.npz`` from ``tmfem control lpv --save``,
its design plant rebuilt on its grid) or synthesised on the fly with the options of
``tmfem control lpv`` (EIGOPT by default, with the sampled-loop constraint at --dt), then
verified on the finer grid. A controller built elsewhere (any object with the reset/output/
update/name protocol of :mod:`tmfem.simulation.controllers` reading the measured LPV
signals, :class:`tmfem.control.lpv.deployment.LPVDeployment`) deploys through :data:`DESIGNS`
and :data:`BUILDERS` (a new ``--controller`` name adds an entry to each and to
:data:`tmfem.reference.deployments.LPV_CONTROLLERS`).
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from tmfem import reference, simulation
from tmfem.cli import lpv_options
from tmfem.cli.common import progress_bar, say
from tmfem.control import lpv
from tmfem.control.lpv.plant import lpv_membrane_mode_choice
from tmfem.errors import InfeasibleController, InputError
from tmfem.system.problem import lpv_path

#: the synthesis options of an on-the-fly design (refused with --lpv-controller)
SYNTHESIS = ("grid", "gamma", "solver", "gamma_rtol", "time_budget", "fixed_gamma", "refine", "start", "verify_rounds")
#: options of the 7.4 deployments that do not apply to the LPV one (None or False: not given)
NOT_LPV = ("uncertainty", "allocation", "pfl_at", "gains")


def configure(parser) -> None:
    parser.add_argument("--lpv-controller", metavar="FILE.npz",
                        help="--controller lpv: a design saved by `tmfem control lpv --save` (else one "
                             "is synthesised with the options below)")
    parser.add_argument("--solver", choices=("EIGOPT", "CLARABEL", "SCS"), default=None,
                        help="--controller lpv: synthesis solver (default EIGOPT, docs/guides/lpv.md)")
    lpv_options.configure_synthesis(parser, prefix="--controller lpv: ")
    parser.add_argument("--estimator-interpolation", choices=("multilinear", "spline"), default=None,
                        help="--controller lpv-output: how the Kalman estimator's model and gains are "
                             "evaluated between grid points (default multilinear; spline: tensor-product "
                             "splines, docs/guides/lpv.md)")
    parser.add_argument("--estimator-refine", type=int, default=None, metavar="R",
                        help="--controller lpv-output: the Kalman estimator on the design grid refined R "
                             "times (new COM linearisations; default 1; docs/guides/lpv.md)")
    parser.add_argument("--noise", type=float, default=None, metavar="SIGMA",
                        help="LPV deployment: measurement noise, seeded Gaussian samples of this standard "
                             "deviation [rad, m; rad/s, m/s] per step on every signal the controller reads "
                             "(lpv: all states and rho; lpv-output: q, the membrane points and rho)")


def given(args, names) -> list:
    """The options among ``names`` given on the command line (not None / not False)."""
    return ["--" + k.replace("_", "-") for k in names if getattr(args, k, None) not in (None, False)]


def check(args) -> None:
    """Refusals before any work: options of the 7.4 deployments, the paths (the FE plant's
    options are those of the 7.4 deployments, checked by :mod:`tmfem.cli.deploy`)."""
    bad = given(args, NOT_LPV)
    args.system.problem.lpv.check_schedule(args.system.name)
    own = lpv_path(args.system)
    if args.path not in (None, own):
        bad.append(f"--path {args.path}")
    if bad:
        raise InputError(f"--controller {args.controller}: options {bad} do not apply to the LPV deployment "
                         f"of {args.preset} (reference of eq. 5.100 on the {own} path, no PFL)")
    for opt in ("estimator_interpolation", "estimator_refine"):
        if getattr(args, opt) is not None and args.controller != "lpv-output":
            raise InputError(f"--{opt.replace('_', '-')} belongs to --controller lpv-output (the estimator "
                             f"of the output feedback), found --controller {args.controller}")
    if args.estimator_refine is not None and args.estimator_refine < 1:
        raise InputError(f"--estimator-refine: expected an integer R >= 1, found {args.estimator_refine}")
    if args.lpv_controller is not None:
        syn = given(args, SYNTHESIS)
        if syn:
            raise InputError(f"--lpv-controller: options {syn} belong to a synthesis on the fly, found them "
                             "with a saved design")
        if not (args.lpv_controller.endswith(".npz") and Path(args.lpv_controller).is_file()):
            raise InputError(f"--lpv-controller: expected an existing .npz file (tmfem control lpv --save), "
                             f"found {args.lpv_controller!r}")


def design(args, preset: str):
    """(design plant, state-feedback design, JSON entries): loaded and checked on its grid
    (sampled at --dt), or synthesized and verified on the finer grid."""
    if args.lpv_controller is not None:
        d = lpv.LPVStateFeedback.load(args.lpv_controller)
        s = args.system
        n = int(np.prod([a.size for a in d.axes]))
        say("deploy", f"{preset}: rebuilding the design plant at its {n} grid points")
        try:
            plant = lpv.saved_design_plant(d, s, bases=reference.lpv_bases(s), progress=lpv_options.progress)
        except InputError as exc:
            raise InputError(f"--lpv-controller {args.lpv_controller}: {exc}") from None
        v = lpv.verify_design(d, plant, tracked=s.q_names, sample_time=args.dt)
        return plant, d, {"lpv_controller": args.lpv_controller, "gamma": d.gamma,
                          **{f"design_grid_{k}": x for k, x in v.to_dict().items()}}
    cfg = lpv_options.check_synthesis(args, solver=args.solver or "EIGOPT", system=args.system)
    plant, gp, bound, out = lpv_options.design_plant(cfg, command="deploy")
    sample = args.dt if cfg["solver"] == "EIGOPT" else None
    ctrl, syn = lpv_options.synthesize(cfg, gp, bound, sample_time=sample)
    ctrl, _, checked = lpv_options.verify_finer(cfg, plant, ctrl, sample_time=args.dt)
    out.pop("preset")
    return plant, ctrl, {**out, **syn, **checked}


#: --controller name -> design(args, preset) -> (design plant, design with ``gamma``, JSON entries)
DESIGNS = {"lpv": design, "lpv-output": design}
#: --controller name -> builder(deployment, design) of a controller on the LPV signals y_lpv
#: (a function of :mod:`tmfem.control.lpv`)
BUILDERS = {"lpv": "state_feedback_controller", "lpv-output": "output_feedback_controller"}


def _run_on(args, dep, d, kind: str, mesh_n, estimator_options):
    """(set-up, result) of the LPV deployment with a fresh controller of ``d`` (the
    ``--controller`` builder, with ``--noise`` its seeded measurement noise) on the plant
    ``kind``: an FE plant starts in its own equilibrium of the packaged configuration under
    the rest lengths the controller starts with (docs/guides/fe-plant.md)."""
    c = getattr(lpv, BUILDERS[args.controller])(dep, d, **estimator_options)
    if args.noise:
        c = simulation.MeasurementNoise(c, sigma=args.noise, index=c.read_index, seed=0)
    s = dep.setup(c)
    with progress_bar(args.t_end, args.dt, f"deploy {args.preset} ({args.controller}) on {kind}") as bar:
        r = reference.run_on_plant(s, kind=kind, options=reference.FEPlantOptions.of(args),
                                   initial=dep.packaged(), mesh_n=mesh_n, t_end=args.t_end, dt=args.dt,
                                   progress=bar)
    if not np.all(np.isfinite(r.z)):
        raise InfeasibleController(f"the LPV deployment of {args.preset} on the {kind} plant diverged "
                                   "(non-finite states)")
    return s, r


def _figures(r) -> dict:
    """The LPV run's own JSON figures: the largest tracking error of q (eq. 5.100) and of the
    commanded rest lengths above the tendon lengths."""
    q_err = np.abs(r.z[:, :len(r.names["q"])] - r.q_d)
    return {"max_tracking_error": float(q_err.max()),
            "rest_length_above_tendon_length_max_m": float(np.max(r.u - r.lengths))}


def run(args, *, mesh_n) -> dict:
    """The LPV deployment (module docstring) on the FE plant mesh ``mesh_n`` (None on the COM
    plant); the JSON keys of the 7.4 deployments plus the design's; with ``--compare-plant``
    the same design (a fresh controller) on the second plant
    (:func:`tmfem.reference.deployment_plants.compare_plants`)."""
    if args.noise is not None and not (np.isfinite(args.noise) and args.noise >= 0):
        raise InputError(f"--noise: expected a standard deviation >= 0, found {args.noise}")
    t0 = time.perf_counter()
    plant, d, info = DESIGNS[args.controller](args, args.preset)
    dep = reference.lpv_setup(args.system, plant)
    est = {}          # the output feedback's estimator options (check: lpv-output only)
    if args.estimator_interpolation:
        est["interpolation"] = args.estimator_interpolation
    if (args.estimator_refine or 1) > 1:
        est["estimator_plant"] = dep.on_turn(lpv_options.refined_plant(dep.model.system, plant, args.estimator_refine,
                                                                       what="estimator plant"))
    s, r = _run_on(args, dep, d, args.plant, mesh_n, est)
    # the keys of the 7.4 deployments (tmfem.cli.deploy.run; no PFL: uncertainty, allocation and
    # pfl_at None), then the design's
    ctrl = {"controller": args.controller, "uncertainty": None, "allocation": None, "pfl_at": None,
            "gamma": d.gamma, "lpv_controller": args.lpv_controller,
            "measurement_noise_sigma": args.noise or 0.0,
            "estimator_interpolation": (args.estimator_interpolation or "multilinear")
            if args.controller == "lpv-output" else None,
            "estimator_refine": (args.estimator_refine or 1) if args.controller == "lpv-output" else None}
    plants = reference.FEPlantOptions.of(args)
    out = {"system": args.system.name, "plant": args.plant, **plants.summary(args.plant, mesh_n),
           **ctrl, "path": lpv_path(args.system), **r.summary(), **s.info,
           **_figures(r), **info,
           "membrane_mode_choice": lpv_membrane_mode_choice(args.system).to_dict()}
    title = f"{args.preset} deployment on the {args.plant} plant: {args.controller} (gamma = {d.gamma:.4g}), eq. 5.100"
    out.update(reference.write_outputs(s, r, preset=args.preset, csv_path=args.csv, plot=args.plot, gif=args.gif,
                                       vtk=args.vtk, title=title, lpv=True))
    if args.compare_plant:
        def rerun(kind):
            _, r2 = _run_on(args, dep, d, kind, mesh_n, est)
            return r2, _figures(r2)
        src = args.lpv_controller or "synthesised here"
        out["compare"] = reference.compare_plants(
            r, rerun, options=plants, preset=args.preset, csv=args.compare_csv, plot=args.compare_plot,
            mesh_n=mesh_n, controller=ctrl,
            about=f"gamma = {d.gamma:.4g}, {src}" + (f", noise {args.noise:g}" if args.noise else ""),
            reference="eq. 5.100")
    out["total_wall_time_s"] = time.perf_counter() - t0
    out["failed_checks"] = (reference.diverged([(args.plant, out), (args.compare_plant, out.get("compare", {}))])
                            + out.get("strength_checks_failed", []))
    return out
