"""Rate-bounded certificate of the 2-3 output-feedback LPV loop (tmfem.control.lpv.certificate;
docs/guides/lpv.md, output feedback) for a saved state-feedback design.

Run: .venv/bin/python benchmarks/lpv_certificate.py --design F.npz [--budget 900] [--rtol 0.05]
         [--upper G] [--fine] [--cache DIR] [--save-certificate X.npz | --certificate X.npz]
         [--estimator-refine R] [--fine-refine F] [--estimator-interpolation multilinear|spline]
         [--refine [--per-round 4] [--rounds 8] [--refine-budget 1200] [--refine-gamma G] [--refine-max-iter 150]
         [--save-refined Y.npz]]

Builds the design plant on the design's grid (COM linearisations at the symmetric equilibria
of eq. 5.97), the gridded Kalman estimator (W_d = W_n = 0.001) on q and the membrane points,
the 121-state loops and the EIGOPT bisection of the analysis LMI (X(rho) affine, +-10 deg/s)
between the largest frozen norm and --upper (default 2 x it). With --fine, a found certificate
is re-checked on the --fine-refine (default 4) x finer grid (new linearisations) with the frozen checks of
verify_output_feedback. --cache keeps the plants as pickles. --save-certificate writes the
certificate's X(rho) (LPVStateFeedback.save, no gain rows), --certificate reads one instead of
solving. --refine (implies --fine): the cutting-plane refinement of refine_certificate on that
finer grid (the worst --per-round failing points per round, at most --rounds re-solves within
--refine-budget s, at the certificate's gamma or --refine-gamma, --refine-max-iter L-BFGS iterations per smoothing
stage), then the re-check; --save-refined
writes the refined X(rho). --estimator-refine R: the Kalman estimator (its model and gains)
on the design grid refined R times (new linearisations; K(rho) stays the design's), so that
its interpolated model is nearer the true plant between design points; --fine-refine F: the
re-check grid F times finer than the design grid (default 4; a multiple of R, and at least 2 R
when R > 1, so that it checks between the estimator's points too); --estimator-interpolation:
how the estimator's model and gains are evaluated between its points (GriddedLPV.interpolate;
default multilinear). Prints one JSON object (times wall and CPU).
"""
import argparse
import json
import logging
import pickle
import time
from pathlib import Path

import numpy as np

from tmfem.control.lpv.certificate import (RateBoundedCertificate, _frozen_norms, closed_loop_lpv,
                                           rate_bounded_certificate, refine_certificate)
from tmfem.control.lpv.output_feedback import design_output_feedback, verify_output_feedback
from tmfem.control.lpv.plant import com_lpv_plant
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.reference.tables import deployment_bases
from tmfem.system import load_preset


def plant_on(s, theta, psi, rate_bounds, cache, name, membrane_points=None):
    f = None if cache is None else Path(cache) / f"{name}.pkl"
    if f is not None and f.is_file():
        return pickle.loads(f.read_bytes())
    pl = com_lpv_plant(s, theta=theta, psi=psi, bases=deployment_bases(s), rate_bounds=rate_bounds,
                       membrane_points=membrane_points)
    if f is not None:
        f.write_bytes(pickle.dumps(pl))
    return pl


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--design", required=True)
    ap.add_argument("--budget", type=float, default=900.0)
    ap.add_argument("--rtol", type=float, default=0.05)
    ap.add_argument("--upper", type=float, default=None)
    ap.add_argument("--fine", action="store_true")
    ap.add_argument("--cache", default=None)
    ap.add_argument("--save-certificate", default=None)
    ap.add_argument("--certificate", default=None)
    ap.add_argument("--refine", action="store_true")
    ap.add_argument("--per-round", type=int, default=4)
    ap.add_argument("--rounds", type=int, default=8)
    ap.add_argument("--refine-budget", type=float, default=1200.0)
    ap.add_argument("--save-refined", default=None)
    ap.add_argument("--refine-gamma", type=float, default=None)
    ap.add_argument("--refine-max-iter", type=int, default=150)
    ap.add_argument("--estimator-refine", type=int, default=1)
    ap.add_argument("--fine-refine", type=int, default=4)
    ap.add_argument("--estimator-interpolation", choices=["multilinear", "spline"], default="multilinear")
    a = ap.parse_args()
    R, F = a.estimator_refine, a.fine_refine
    if R < 1 or F < 4 or F % R or (R > 1 and F < 2 * R):
        ap.error(f"expected --estimator-refine R >= 1 and --fine-refine F >= 4, a multiple of R and >= 2 R "
                 f"when R > 1 (points between the estimator's), found R = {R}, F = {F}")
    if (a.per_round != 4 or a.rounds != 8 or a.refine_budget != 1200.0 or a.save_refined
            or a.refine_gamma is not None or a.refine_max_iter != 150) and not a.refine:
        ap.error("--per-round, --rounds, --refine-budget, --refine-gamma, --refine-max-iter and --save-refined "
                 "apply with --refine only")
    if a.certificate and (a.save_certificate or a.upper is not None):
        ap.error("--certificate reads a saved X(rho): --save-certificate and --upper do not apply")
    logging.basicConfig(level=logging.WARNING, format="%(asctime)s %(name)s: %(message)s")
    logging.getLogger("tmfem").setLevel(logging.INFO)
    s = load_preset("2-3-lpv")
    sf = LPVStateFeedback.load(a.design)
    t = time.perf_counter()
    shape = "x".join(str(ax.size) for ax in sf.axes)
    pl = plant_on(s, sf.axes[0], sf.axes[1], sf.rate_bounds, a.cache, f"plant_{shape}")
    t_plant = time.perf_counter() - t
    est = pl
    if a.estimator_refine > 1:
        ea = pl.refined(a.estimator_refine)
        est = plant_on(s, ea[0], ea[1], pl.rate_bounds, a.cache, f"estimator{a.estimator_refine}_{shape}",
                       membrane_points=pl.membrane_points)
    of = design_output_feedback(sf, est, tracked=s.q_names, measured=pl.state_names[:pl.nx // 2],
                                interpolation=a.estimator_interpolation)
    t, cpu = time.perf_counter(), time.process_time()
    if a.certificate:
        X = LPVStateFeedback.load(a.certificate)
        lo, lo_at = _frozen_norms(closed_loop_lpv(of, pl, W_e=0.5, W_u=0.05))
        c = RateBoundedCertificate(lyapunov=X, gamma=X.gamma, lower_bound=lo, lower_bound_at=lo_at, bracket=None,
                                   time_s=time.perf_counter() - t, message=f"loaded from {a.certificate}")
    else:
        c = rate_bounded_certificate(of, pl, W_e=0.5, W_u=0.05, upper=a.upper, rtol=a.rtol, time_budget=a.budget)
        if a.save_certificate and c.found:
            c.lyapunov.save(a.save_certificate)
    out = {"design": a.design, "design_gamma": sf.gamma, "grid": list(pl.grid_shape), "plant_s": t_plant,
           "estimator_grid": list(est.grid_shape), "estimator_interpolation": a.estimator_interpolation,
           "loop_states": of.nx + len(of.tracked_rows) + of.nx, "certificate_cpu_s": time.process_time() - cpu,
           **c.to_dict()}
    if (a.fine or a.refine) and c.found:
        t = time.perf_counter()
        fa = pl.refined(a.fine_refine)
        fine = plant_on(s, fa[0], fa[1], pl.rate_bounds, a.cache,
                        f"fine_{shape}" if a.fine_refine == 4 else f"fine{a.fine_refine}_{shape}",
                        membrane_points=pl.membrane_points)
        out["fine_plant_s"] = time.perf_counter() - t
        if a.refine:
            c = refine_certificate(c, of, fine, W_e=0.5, W_u=0.05, per_round=a.per_round, max_rounds=a.rounds,
                                   time_budget=a.refine_budget, gamma=a.refine_gamma, max_iter=a.refine_max_iter)
            if a.save_refined:
                c.lyapunov.save(a.save_refined)
            # the refined certificate's keys (its gamma, --refine-gamma) replace the design grid's
            out.update(c.to_dict(), rate_bounded_design_grid_gamma=out["rate_bounded_gamma"])
        t = time.perf_counter()
        v = verify_output_feedback(of, fine, W_e=0.5, W_u=0.05, dt=0.01, certificate=c, allow_failure=True)
        out.update({k: val for k, val in v.to_dict().items() if k not in out}, fine_s=time.perf_counter() - t)
    print(json.dumps(out, default=lambda o: o.tolist() if isinstance(o, np.ndarray) else str(o)))


if __name__ == "__main__":
    main()
