"""``tmfem control lpv``: gridded LPV state feedback of ch. 8 (eqs. 5.95-5.99), its pointwise
lower bound and its verification on a finer grid (8.3). Called by :mod:`tmfem.cli.control`."""
from __future__ import annotations

import sys
import time

import numpy as np

from tmfem.cli.common import output_file
from tmfem.errors import InfeasibleController, InputError, ResourceLimit

#: Largest verification grid: every point is one COM linearisation (~2 s for 2-3 on this
#: machine under load), so 500 points is about a quarter of an hour.
MAX_VERIFY_POINTS = 500

# the options of `tmfem control` that only `lpv` takes (refused by the other actions)
LPV_ONLY = ("grid", "rate_bound_deg", "refine", "max_iter", "bound_only", "gamma", "gamma_rtol",
            "time_budget", "fixed_gamma", "sample_time", "start", "output_feedback", "noise", "rate_certificate",
            "certificate_rounds", "estimator_interpolation", "estimator_refine")

#: EIGOPT defaults: relative bracket width of the gamma bisection, its time budget [s]
GAMMA_RTOL, TIME_BUDGET = 0.05, 300.0

#: cutting-plane rounds of the rate-bounded certificate on the finer grid, points added per round
CERTIFICATE_ROUNDS, CERTIFICATE_PER_ROUND = 8, 4


def configure_synthesis(parser, *, prefix: str = "lpv: ") -> None:
    """The synthesis options shared by `tmfem control lpv` and `tmfem deploy --controller lpv`."""
    parser.add_argument("--grid", default=None, help=prefix + "theta x psi points of the printed grid (8.3; default 6x3)")
    parser.add_argument("--refine", type=int, default=None,
                        help=prefix + "verification grid refinement factor (>= 4, default 4)")
    parser.add_argument("--gamma", type=float, default=None,
                        help=prefix + "EIGOPT: the first (upper) level of the gamma bisection (default 2 x the "
                             "pointwise lower bound), or the only level with --fixed-gamma")
    parser.add_argument("--gamma-rtol", type=float, default=None,
                        help=prefix + f"EIGOPT: stop the bisection when (hi - lo) <= rtol hi (default {GAMMA_RTOL})")
    parser.add_argument("--time-budget", type=float, default=None,
                        help=prefix + f"EIGOPT: seconds for the gamma bisection (default {TIME_BUDGET:g})")
    parser.add_argument("--fixed-gamma", action="store_true", default=None,
                        help=prefix + "EIGOPT: a feasible point at --gamma only (no bisection)")
    parser.add_argument("--start", metavar="FILE.npz", default=None,
                        help=prefix + "EIGOPT bisection: start the first level from this saved design (e.g. "
                             "one on a sub-grid: continuation in the grid) instead of the Riccati fit (with "
                             "--sample-time and no --start, the bisection first runs on the grid with psi "
                             "at its middle value and starts from that design)")


def configure(parser) -> None:
    configure_synthesis(parser)
    parser.add_argument("--rate-bound-deg", type=float, default=None,
                        help="lpv: |d rho/dt| bound [deg/s] (8.3: 10, the default)")
    parser.add_argument("--max-iter", type=int, default=None, help="lpv: SDP solver iteration limit")
    parser.add_argument("--sample-time", type=float, default=None,
                        help="lpv: EIGOPT: also require the frozen loops sampled at this zero-order-hold "
                             "step [s] to be stable (8.4 runs at 0.01 s; docs/guides/lpv.md)")
    parser.add_argument("--bound-only", action="store_true", default=None,
                        help="lpv: only the pointwise state-feedback lower bound of gamma (no SDP)")
    parser.add_argument("--output-feedback", action="store_true", default=None,
                        help="lpv: observer-based output feedback on the measured q and membrane points "
                             "(K(rho) with a gridded Kalman estimator; frozen-parameter verification on the "
                             "finer grid, sampled at --sample-time when given; docs/guides/lpv.md)")
    parser.add_argument("--rate-certificate", action="store_true", default=None,
                        help="lpv --output-feedback: also the rate-bounded certificate of the output-feedback "
                             "loop (analysis LMI with X(rho) affine, EIGOPT bisection on gamma with the "
                             "--gamma-rtol and --time-budget of the synthesis), re-checked on the finer grid; "
                             "where it fails there, refined by cutting planes (--certificate-rounds)")
    parser.add_argument("--certificate-rounds", type=int, default=None,
                        help="lpv --rate-certificate: at most this many cutting-plane rounds when the design-grid "
                             "certificate fails on the finer grid (each imposes the 4 worst failing points of "
                             "that grid and re-solves at the same gamma, within another --time-budget; default "
                             f"{CERTIFICATE_ROUNDS}, 0: none; docs/guides/lpv.md)")
    parser.add_argument("--estimator-interpolation", choices=("multilinear", "spline"), default=None,
                        help="lpv --output-feedback: how the Kalman estimator's model and gains are "
                             "evaluated between grid points: multilinear (default) or tensor-product "
                             "splines of degree min(3, points - 1) per parameter, 13-16 x closer to the "
                             "2-3 plant between the 6 x 3 points (docs/guides/lpv.md)")
    parser.add_argument("--estimator-refine", type=int, default=None, metavar="R",
                        help="lpv --output-feedback: the Kalman estimator's model and gains on the design grid "
                             "refined R times (new COM linearisations; K(rho) and the certificate stay on the "
                             "design grid; default 1); with R > 1, --refine must be a multiple of R and >= 2 R. "
                             "With --estimator-interpolation spline and R = 2 the rate-bounded certificate of the "
                             "2-3 loop holds on the 21 x 9 grid (docs/guides/lpv.md)")
    parser.add_argument("--noise", type=float, default=None,
                        help="lpv --output-feedback: measurement-noise weight W_n of the estimator design "
                             "and of the verified norm [rad, m] (default 0.001)")


def printed_grid(spec: str, printed: dict):
    """The --grid AxB points of the printed LPV grid (evenly spread, both ends; one point: the middle)."""
    try:
        nt, nps = (int(v) for v in spec.lower().split("x"))
    except ValueError:
        raise InputError(f"--grid: expected AxB (e.g. 6x3), found {spec!r}") from None
    th, ps = np.radians(printed["theta_grid_deg"]), np.radians(printed["psi_grid_deg"])
    if not (1 <= nt <= th.size and 1 <= nps <= ps.size):
        raise InputError(f"--grid: expected at most {th.size}x{ps.size} points of the printed grid, found {spec}")
    # k evenly spread points including both ends; one point: the middle one (psi_0 = 8.36 deg of
    # eq. 5.100 on the printed psi axis, so a reduced grid still holds the 8.4 reference)
    pick = lambda a, k: a[np.round(np.linspace(0, a.size - 1, k)).astype(int)] if k > 1 \
        else a[[a.size // 2]]                                                    # noqa: E731
    return pick(th, nt), pick(ps, nps)


def check_synthesis(args, *, solver: str, preset: str) -> dict:
    """The synthesis options, checked before any work; returns the resolved settings
    (system, grid axes, refine, EIGOPT bisection or fixed level)."""
    from tmfem.system import load_preset
    refine = 4 if args.refine is None else args.refine
    if refine < 4:
        raise InputError(f"--refine: expected >= 4 (the issue's verification standard), found {refine}")
    if solver not in ("CLARABEL", "SCS", "EIGOPT"):
        raise InputError(f"--solver {solver}: applies to `tmfem control hinf` only; lpv takes CLARABEL, SCS or EIGOPT")
    eig = {k: getattr(args, k, None) for k in ("gamma_rtol", "time_budget", "fixed_gamma", "start")}
    if solver != "EIGOPT":
        given = [k for k, v in {**eig, "gamma": args.gamma, "sample_time": getattr(args, "sample_time", None)}.items()
                 if v is not None]
        if given:
            raise InputError(f"options {['--' + k.replace('_', '-') for k in given]} apply to --solver EIGOPT "
                             f"only, found --solver {solver}")
    elif args.fixed_gamma:
        if args.gamma is None or any(eig[k] is not None for k in ("gamma_rtol", "time_budget", "start")):
            raise InputError("--fixed-gamma: expected --gamma G and none of --gamma-rtol, --time-budget, --start "
                             "(one level, no bisection)")
    start = None
    if eig["start"] is not None:
        from pathlib import Path
        from tmfem.control.lpv.synthesis import LPVStateFeedback
        if not Path(eig["start"]).is_file():
            raise InputError(f"--start: expected a design saved by `tmfem control lpv --save`, found no file "
                             f"{eig['start']!r}")
        start = LPVStateFeedback.load(eig["start"])
    rtol = GAMMA_RTOL if eig["gamma_rtol"] is None else eig["gamma_rtol"]
    budget = TIME_BUDGET if eig["time_budget"] is None else eig["time_budget"]
    if not (0 < rtol < 1):
        raise InputError(f"--gamma-rtol: expected 0 < rtol < 1, found {rtol}")
    if not (np.isfinite(budget) and budget > 0):
        raise InputError(f"--time-budget: expected seconds > 0, found {budget}")
    if args.gamma is not None and not (np.isfinite(args.gamma) and args.gamma > 0):
        raise InputError(f"--gamma: expected > 0, found {args.gamma}")
    s = load_preset(preset)
    printed = dict(s.printed or {})
    if "theta_grid_deg" not in printed or "psi_grid_deg" not in printed:
        raise InputError(f"preset {preset!r}: expected a printed LPV grid (theta_grid_deg, psi_grid_deg), found none")
    th, ps = printed_grid(args.grid or "6x3", printed)
    fine_n = [(a.size - 1) * refine + 1 for a in (th, ps)]
    if fine_n[0] * fine_n[1] > MAX_VERIFY_POINTS:
        raise ResourceLimit(f"--grid {args.grid or '6x3'} --refine {refine}: the verification grid "
                            f"has {fine_n[0]} x {fine_n[1]} = {fine_n[0] * fine_n[1]:,} points, one COM "
                            f"linearisation each (~2 s); the limit is {MAX_VERIFY_POINTS}")
    return {"system": s, "preset": preset, "theta": th, "psi": ps, "refine": refine, "solver": solver,
            "gamma": args.gamma, "fixed": bool(args.fixed_gamma), "rtol": rtol, "budget": budget, "start": start}


def design_plant(cfg: dict, *, rate_deg: float):
    """The gridded plant of ``cfg`` (:func:`check_synthesis`), its interconnection (Fig. 8.1)
    and the pointwise lower bound of gamma; returns (plant, gp, bound, JSON dict)."""
    from tmfem.cli.common import progress_bar
    from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
    from tmfem.control.lpv.plant import com_lpv_plant
    from tmfem.control.lpv.synthesis import interconnection_8_1
    from tmfem.reference.tables import deployment_bases
    s, th, ps = cfg["system"], cfg["theta"], cfg["psi"]
    rb = np.radians(rate_deg)
    print(f"tmfem: {cfg['preset']}: linearising at {th.size * ps.size} grid points", file=sys.stderr)
    with progress_bar(th.size * ps.size, 1, "LPV plant (grid points)") as bar:
        plant = com_lpv_plant(s, theta=th, psi=ps, bases=deployment_bases(s),
                              rate_bounds=[[-rb, rb], [-rb, rb]], progress=bar)
    gp = interconnection_8_1(plant, tracked=s.q_names)
    bound = pointwise_state_feedback_bound(gp)
    out = {"preset": cfg["preset"], "grid": list(plant.grid_shape), "rate_bound_deg": rate_deg,
           **bound.to_dict(), "printed_gamma_bound": 4.18}
    return plant, gp, bound, out


def synthesise(cfg: dict, gp, bound, *, max_iter=None, sample_time=None):
    """The controller (EIGOPT: gamma bisection from --gamma or 2 x the bound, or the fixed
    level; CLARABEL/SCS: their gamma minimisation) and its JSON entries."""
    from tmfem.control.lpv.synthesis import synthesize_state_feedback
    try:
        if cfg["solver"] == "EIGOPT" and not cfg["fixed"]:
            from tmfem.cli.common import progress_bar
            from tmfem.control.lpv.bisect import bisect_gamma
            upper = cfg["gamma"] if cfg["gamma"] is not None else 2.0 * bound.lower_bound
            if upper <= bound.lower_bound:
                raise InputError(f"--gamma {upper:g}: expected an upper level above the pointwise lower "
                                 f"bound {bound.lower_bound:.5g} (no controller below it)")
            with progress_bar(cfg["budget"], 1, "gamma bisection (s of budget)") as bar:
                t0 = time.perf_counter()
                ctrl, br = bisect_gamma(gp, lower=bound.lower_bound, upper=upper, rtol=cfg["rtol"],
                                        time_budget=cfg["budget"], max_iter=max_iter or 150,
                                        sample_time=sample_time, start=cfg["start"],
                                        progress=lambda w: bar(int(min(time.perf_counter() - t0, cfg["budget"])),
                                                               cfg["budget"]))
            extra = br.to_dict()
        else:
            ctrl = synthesize_state_feedback(gp, solver=cfg["solver"], max_iter=max_iter,
                                             gamma=cfg["gamma"], sample_time=sample_time)
            extra = {}
    except InfeasibleController as exc:
        raise InfeasibleController(f"{exc} (pointwise state-feedback lower bound of gamma: "
                                   f"{bound.lower_bound:.4g} at rho = {bound.at})") from None
    return ctrl, {"gamma": ctrl.gamma, "solver": ctrl.solver, "status": ctrl.status, "sizes": ctrl.sizes,
                  "solve_time_s": ctrl.solve_time, "sample_time_s": sample_time, **extra}


def fine_plant(cfg: dict, plant):
    """The plant on the grid ``refine`` times finer (:func:`refined_plant`)."""
    return refined_plant(cfg["system"], plant, cfg["refine"], what="verification plant")


def refined_plant(s, plant, factor: int, *, what: str):
    """The plant of system ``s`` on the grid ``factor`` times finer than ``plant``'s (new COM
    linearisations, the design's membrane points)."""
    from tmfem.cli.common import progress_bar
    from tmfem.control.lpv.plant import com_lpv_plant
    from tmfem.reference.tables import deployment_bases
    axes = plant.refined(factor)
    with progress_bar(axes[0].size * axes[1].size, 1, f"{what} (grid points)") as bar:
        return com_lpv_plant(s, theta=axes[0], psi=axes[1], bases=deployment_bases(s),
                             rate_bounds=plant.rate_bounds, membrane_points=plant.membrane_points, progress=bar)


def check_estimator_refine(R, *, refine: int, output_feedback: bool) -> int:
    """``--estimator-refine R`` (default 1): the estimator's grid R times finer than the
    design's; with R > 1 the verification grid (``--refine``) must be a multiple of R and at
    least 2 R times finer, so that it checks between the estimator's points too."""
    if R is None:
        return 1
    if not output_feedback:
        raise InputError("lpv: option --estimator-refine applies with --output-feedback only")
    if R < 1 or (R > 1 and (refine % R or refine < 2 * R)):
        raise InputError(f"--estimator-refine: expected an integer R >= 1 with the verification refinement "
                         f"--refine {refine} a multiple of R and >= 2 R when R > 1 (points between the "
                         f"estimator's), found {R}")
    return R


def verify_finer(cfg: dict, plant, ctrl, *, sample_time=None, fine=None):
    """:func:`tmfem.control.lpv.verify.verify` on the grid ``refine`` times finer
    (:func:`fine_plant`, or ``fine`` when given); refuses a controller that fails there."""
    from tmfem.control.lpv.synthesis import interconnection_8_1
    from tmfem.control.lpv.verify import verify
    fine = fine_plant(cfg, plant) if fine is None else fine
    return verify(ctrl, interconnection_8_1(fine, tracked=cfg["system"].q_names), sample_time=sample_time)


def output_feedback(ctrl, plant, fine, s, noise, dt, certificate=None, interpolation="multilinear",
                    estimator_plant=None):
    """The observer-based output feedback on q and the membrane point coordinates, verified
    frozen on the fine grid (sampled at ``dt`` when given). JSON: ``gamma`` becomes the
    largest frozen closed-loop norm from [q_d, n_d, n] to p over the fine grid
    (``state_feedback_gamma`` the certified level of K(rho)); ``verification_max_eig`` stays
    the LMI of K(rho) re-checked there. ``certificate``: (rtol, time budget, rounds) of the
    rate-bounded certificate of the loop (:mod:`tmfem.control.lpv.certificate`) on the design grid,
    refined by cutting planes on the fine grid (at most ``rounds`` re-solves within another time
    budget) and re-checked there (keys ``rate_bounded_*``), or None. ``estimator_plant``: the
    Kalman estimator's plant on a grid finer than the design's (default ``plant``);
    ``interpolation``: the estimator's between its grid points."""
    from tmfem.cli.common import progress_bar
    from tmfem.control.lpv.output_feedback import design_output_feedback, verify_output_feedback
    nz = plant.nx // 2
    measured = list(plant.state_names[:nz])          # q and the K point coordinates (eq. 5.17)
    t0 = time.perf_counter()
    est = plant if estimator_plant is None else estimator_plant
    d = design_output_feedback(ctrl, est, tracked=s.q_names, measured=measured, W_n=noise,
                               interpolation=interpolation)
    cert = None
    if certificate is not None:
        from tmfem.control.lpv.certificate import rate_bounded_certificate, refine_certificate
        rtol, budget, rounds = certificate
        with progress_bar(budget, 1, "rate-bounded certificate (s of budget)") as bar:
            t1 = time.perf_counter()
            cert = rate_bounded_certificate(d, plant, W_e=0.5, W_u=0.05, rtol=rtol, time_budget=budget,
                                            progress=lambda w: bar(int(min(time.perf_counter() - t1, budget)),
                                                                   budget))
        if cert.found and rounds > 0:
            with progress_bar(rounds, 1, "certificate refinement (rounds)") as bar:
                cert = refine_certificate(cert, d, fine, W_e=0.5, W_u=0.05, per_round=CERTIFICATE_PER_ROUND,
                                          max_rounds=rounds, time_budget=budget,
                                          progress=lambda k: bar(min(k, rounds), rounds))
    with progress_bar(int(np.prod(fine.grid_shape)), 1, "output-feedback verification (points)") as bar:
        vo = verify_output_feedback(d, fine, W_e=0.5, W_u=0.05, dt=dt, certificate=cert, progress=bar)
    return d, {"output_feedback": True, "measured": measured, "noise_weight": noise, "W_d": d.W_d,
               "estimator_interpolation": interpolation, "estimator_grid": list(est.grid_shape),
               "state_feedback_gamma": ctrl.gamma, "gamma": vo.max_hinf,
               "guarantee": ("rate-bounded (X(rho) of the loop on the design grid, re-checked on the fine grid)"
                             if cert is not None and cert.found else
                             "frozen-parameter (fine grid) only; K(rho) alone is rate-bounded on the design grid"),
               "output_feedback_time_s": time.perf_counter() - t0, **vo.to_dict()}


def run(args) -> dict:
    rate = 10.0 if args.rate_bound_deg is None else args.rate_bound_deg
    if not (np.isfinite(rate) and rate >= 0):
        raise InputError(f"--rate-bound-deg: expected >= 0, found {rate}")
    if args.max_iter is not None and args.max_iter < 1:
        raise InputError(f"--max-iter: expected an integer >= 1, found {args.max_iter}")
    if args.sample_time is not None and not (np.isfinite(args.sample_time) and args.sample_time > 0):
        raise InputError(f"--sample-time: expected seconds > 0, found {args.sample_time}")
    output_file(args.save, option="--save", suffixes=(".npz",))
    if args.noise is not None and not args.output_feedback:
        raise InputError("lpv: option --noise applies with --output-feedback only")
    if args.estimator_interpolation is not None and not args.output_feedback:
        raise InputError("lpv: option --estimator-interpolation applies with --output-feedback only")
    if args.rate_certificate and not args.output_feedback:
        raise InputError("lpv: option --rate-certificate applies with --output-feedback only")
    if args.certificate_rounds is not None and not args.rate_certificate:
        raise InputError("lpv: option --certificate-rounds applies with --rate-certificate only")
    rounds = CERTIFICATE_ROUNDS if args.certificate_rounds is None else args.certificate_rounds
    if rounds < 0:
        raise InputError(f"--certificate-rounds: expected an integer >= 0, found {rounds}")
    if args.output_feedback and args.bound_only:
        raise InputError("lpv: --bound-only computes no controller; it does not apply with --output-feedback")
    noise = 1e-3 if args.noise is None else args.noise
    if not (np.isfinite(noise) and noise > 0):
        raise InputError(f"--noise: expected a weight > 0, found {noise}")
    if args.spec is not None:
        raise InputError(f"lpv: expected --preset (a preset with a printed LPV grid), found the file {args.spec!r}")
    cfg = check_synthesis(args, solver=args.solver or "SCS", preset=args.preset or "2-3-lpv")
    R = check_estimator_refine(args.estimator_refine, refine=cfg["refine"], output_feedback=bool(args.output_feedback))
    plant, gp, bound, out = design_plant(cfg, rate_deg=rate)
    out = {"action": "lpv", **out}
    if args.bound_only:
        return out
    ctrl, syn = synthesise(cfg, gp, bound, max_iter=args.max_iter, sample_time=args.sample_time)
    fine = fine_plant(cfg, plant)
    est = None if R == 1 else refined_plant(cfg["system"], plant, R, what="estimator plant")
    v = verify_finer(cfg, plant, ctrl, sample_time=args.sample_time, fine=fine)
    out = {**out, **syn, **v.to_dict()}
    saved = ctrl
    if args.output_feedback:
        saved, extra = output_feedback(ctrl, plant, fine, cfg["system"], noise, args.sample_time,
                                       certificate=(cfg["rtol"], cfg["budget"], rounds) if args.rate_certificate else None,
                                       interpolation=args.estimator_interpolation or "multilinear",
                                       estimator_plant=est)
        out = {**out, **extra}
    if args.save:
        saved.save(args.save)
        out["saved"] = args.save
    return out


def format_text(r: dict) -> str:
    deg = [f"{np.degrees(a):.2f} deg" for a in r["lpv_gamma_lower_bound_at"]]
    lines = [f"LPV state feedback, {r['preset']}, grid {r['grid'][0]}x{r['grid'][1]}, rates +-{r['rate_bound_deg']:g} deg/s",
             f"pointwise state-feedback lower bound of gamma: {r['lpv_gamma_lower_bound']:.4g} at "
             f"(theta_13, psi_13) = ({', '.join(deg)}) (printed ||G_pw|| < {r['printed_gamma_bound']})"]
    if "gamma" in r:
        lines += [f"{'K(rho): ' if r.get('output_feedback') else ''}gamma = "
                  f"{r.get('state_feedback_gamma', r['gamma']):.5g} ({r['solver']}, {r['status']}, {r['solve_time_s']:.1f} s, sizes {r['sizes']})",
                  f"verification on {r['verification_grid']}: max LMI eigenvalue {r['verification_max_eig']:.3e}, "
                  f"max closed-loop Re {r['closed_loop_max_real']:.3e}"]
    if r.get("output_feedback"):
        lines += [f"output feedback on {len(r['measured'])} measured signals (W_n = {r['noise_weight']:g}): "
                  f"frozen max closed-loop Re {r['output_feedback_closed_loop_max_real']:.3e}, "
                  f"max ||T_pw|| {r['output_feedback_hinf_max']:.4g} ({r['guarantee']})"]
        if r["output_feedback_sampled_max_radius"] is not None:
            lines.append(f"sampled-data loops at dt = {r['sample_time_s']:g} s: max spectral radius "
                         f"{r['output_feedback_sampled_max_radius']:.9f} (state feedback alone "
                         f"{r['state_feedback_sampled_max_radius']:.9f})")
        if "rate_bounded_certificate" in r:
            lines.append("rate-bounded certificate of the loop (X(rho) affine): "
                         + (f"gamma = {r['rate_bounded_gamma']:.5g} (frozen norms up to "
                            f"{r['rate_bounded_frozen_norm_max']:.5g}), re-checked on the fine grid: max LMI "
                            f"eigenvalue {r['rate_bounded_verification_max_eig']:.3e}"
                            if r["rate_bounded_certificate"] else f"not found ({r['rate_bounded_message']})"))
        if "rate_bounded_refinement_passed" in r:
            lines.append(f"  cutting-plane refinement on {r['rate_bounded_refinement_fine_grid']}: "
                         f"{r['rate_bounded_refinement_stopped']} after {len(r['rate_bounded_refinement_rounds'])} "
                         f"checks, {r['rate_bounded_refinement_points_added']} points added "
                         f"({r['rate_bounded_refinement_time_s']:.0f} s)")
    if r.get("gamma_levels"):
        nf = r["gamma_not_found"]
        lines.append(f"EIGOPT bisection ({len(r['gamma_levels'])} levels, {r['gamma_search_time_s']:.0f} s, stopped on "
                     f"{r['gamma_stopped']}): feasible at {r['gamma_feasible']:.5g}, not found at "
                     f"{'-' if nf is None else f'{nf:.5g}'}; the optimum is in [{r['gamma_lower_bound_proven']:.5g}, "
                     f"{r['gamma_feasible']:.5g}] (a level not found is not proven infeasible)")
        if r.get("gamma_start_grid"):
            ok = [lv["gamma"] for lv in r["gamma_start_levels"] if lv["result"] == "feasible"]
            lines.append(f"continuation in the grid: started from the {'x'.join(map(str, r['gamma_start_grid']))} "
                         f"grid's design ({len(r['gamma_start_levels'])} levels there, lowest feasible "
                         f"{min(ok):.5g})")
    if "saved" in r:
        lines.append(f"saved {r['saved']}")
    return "\n".join(lines)
