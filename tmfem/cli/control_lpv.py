"""``tmfem control lpv``: gridded LPV state feedback of ch. 8 (eqs. 5.95-5.99), its pointwise
lower bound and its verification on a finer grid (8.3). Called by :mod:`tmfem.cli.control`."""
from __future__ import annotations

import numpy as np

from tmfem.cli import lpv_options
from tmfem.cli.common import output_file, system_from_args
from tmfem.control import lpv
from tmfem.control.lpv.defaults import CERTIFICATE_ROUNDS
from tmfem.errors import InputError

# the options of `tmfem control` that only `lpv` takes (refused by the other actions)
LPV_ONLY = ("grid", "rate_bound_deg", "refine", "verify_rounds", "max_iter", "bound_only", "gamma", "gamma_rtol",
            "time_budget", "fixed_gamma", "sample_time", "start", "output_feedback", "noise", "rate_certificate",
            "certificate_rounds", "estimator_interpolation", "estimator_refine")


def configure(parser) -> None:
    lpv_options.configure_synthesis(parser)
    parser.add_argument("--rate-bound-deg", type=float, default=None,
                        help="lpv: |d rho/dt| bound [deg/s] (default the [lpv] table's rate_bound_deg; "
                             "8.3: 10)")
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


def run(args) -> dict:
    rate = args.rate_bound_deg
    if rate is not None and not (np.isfinite(rate) and rate >= 0):
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
    if args.spec is None and args.preset is None:
        args.preset = "2-3-lpv"
    cfg = lpv_options.check_synthesis(args, solver=args.solver or "EIGOPT", system=system_from_args(args))
    R = check_estimator_refine(args.estimator_refine, refine=cfg["refine"], output_feedback=bool(args.output_feedback))
    plant, gp, bound, out = lpv_options.design_plant(cfg, rate_deg=rate)
    out = {"action": "lpv", **out}
    if args.bound_only:
        return out
    ctrl, syn = lpv_options.synthesize(cfg, gp, bound, max_iter=args.max_iter, sample_time=args.sample_time)
    fine = lpv_options.refined_plant(cfg["system"], plant, cfg["refine"], what="verification plant")
    est = None if R == 1 else lpv_options.refined_plant(cfg["system"], plant, R, what="estimator plant")
    ctrl, v, checked = lpv_options.verify_finer(cfg, plant, ctrl, sample_time=args.sample_time, fine=fine)
    out = {**out, **syn, **checked}
    saved = ctrl
    if args.output_feedback:
        saved, extra = lpv.output_feedback_design(
            ctrl, plant, fine, tracked=cfg["system"].q_names, noise=noise, sample_time=args.sample_time,
            certificate=(cfg["rtol"], cfg["budget"], rounds) if args.rate_certificate else None,
            interpolation=args.estimator_interpolation or "multilinear", estimator_plant=est,
            progress=lpv_options.progress)
        out = {**out, **extra}
    if args.save:
        saved.save(args.save)
        out["saved"] = args.save
    return out


def format_text(r: dict) -> str:
    deg = [f"{np.degrees(a):.2f} deg" for a in r["lpv_gamma_lower_bound_at"]]
    printed = f" (printed ||G_pw|| < {r['printed_gamma_bound']})" if "printed_gamma_bound" in r else ""
    lines = [f"LPV state feedback, {r['system']}, grid {r['grid'][0]}x{r['grid'][1]}, "
             f"rates +-{r['rate_bound_deg']:g} deg/s",
             f"pointwise state-feedback lower bound of gamma: {r['lpv_gamma_lower_bound']:.4g} at "
             f"({', '.join(r['scheduling_parameters'])}) = ({', '.join(deg)}){printed}"]
    if "gamma" in r:
        lines += [f"{'K(rho): ' if r.get('output_feedback') else ''}gamma = "
                  f"{r.get('state_feedback_gamma', r['gamma']):.5g} ({r['solver']}, {r['status']}, "
                  f"{r['solve_time_s']:.1f} s, sizes {r['sizes']})",
                  f"verification on {r['verification_grid']}: max LMI eigenvalue {r['verification_max_eig']:.3e}, "
                  f"max closed-loop Re {r['closed_loop_max_real']:.3e}"]
        if "design_refinement" in r:
            ref = r["design_refinement"]
            level = ("gamma kept" if ref["gamma"] == ref["design_gamma"] else
                     f"gamma raised from {ref['design_gamma']:.5g} above the new points' pointwise optima")
            lines.append(f"  the bisection's design failed between its grid points (largest LMI eigenvalue "
                         f"{ref['rounds'][0]['fine_max_eig']:.3e}); cutting-plane refinement: {ref['stopped']} after "
                         f"{len(ref['rounds']) - 1} re-solves, {ref['points_added']} points of the verification "
                         f"grid imposed, {level} ({ref['time_s']:.0f} s)")
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
