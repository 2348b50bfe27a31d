"""Rate-bounded certificate of the 2-3 output-feedback LPV loop (tmfem.control.lpv_certificate;
docs/lpv.md, output feedback) for a saved state-feedback design.

Run: .venv/bin/python benchmarks/lpv_certificate.py --design F.npz [--budget 900] [--rtol 0.05]
         [--upper G] [--fine] [--cache DIR]

Builds the design plant on the design's grid (COM linearisations at the symmetric equilibria
of eq. 5.97), the gridded Kalman estimator (W_d = W_n = 0.001) on q and the membrane points,
the 121-state loops and the EIGOPT bisection of the analysis LMI (X(rho) affine, +-10 deg/s)
between the largest frozen norm and --upper (default 2 x it). With --fine, a found certificate
is re-checked on the 4x finer grid (new linearisations) with the frozen checks of
verify_output_feedback. --cache keeps the plants as pickles. Prints one JSON object.
"""
import argparse
import json
import logging
import pickle
import time
from pathlib import Path

import numpy as np

from tmfem.control.lpv_certificate import rate_bounded_certificate
from tmfem.control.lpv_output import design_output_feedback, verify_output_feedback
from tmfem.control.lpv_plant import com_lpv_plant
from tmfem.control.lpv_synthesis import LPVStateFeedback
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
    a = ap.parse_args()
    logging.basicConfig(level=logging.WARNING, format="%(asctime)s %(name)s: %(message)s")
    logging.getLogger("tmfem").setLevel(logging.INFO)
    s = load_preset("2-3-lpv")
    sf = LPVStateFeedback.load(a.design)
    t = time.perf_counter()
    shape = "x".join(str(ax.size) for ax in sf.axes)
    pl = plant_on(s, sf.axes[0], sf.axes[1], sf.rate_bounds, a.cache, f"plant_{shape}")
    t_plant = time.perf_counter() - t
    of = design_output_feedback(sf, pl, tracked=s.q_names, measured=pl.state_names[:pl.nx // 2])
    c = rate_bounded_certificate(of, pl, W_e=0.5, W_u=0.05, upper=a.upper, rtol=a.rtol, time_budget=a.budget)
    out = {"design": a.design, "design_gamma": sf.gamma, "grid": list(pl.grid_shape), "plant_s": t_plant,
           "loop_states": of.nx + len(of.tracked_rows) + of.nx, **c.to_dict()}
    if a.fine and c.found:
        t = time.perf_counter()
        fa = pl.refined(4)
        fine = plant_on(s, fa[0], fa[1], pl.rate_bounds, a.cache, f"fine_{shape}", membrane_points=pl.membrane_points)
        v = verify_output_feedback(of, fine, W_e=0.5, W_u=0.05, dt=0.01, certificate=c, allow_failure=True)
        out.update({k: val for k, val in v.to_dict().items() if k not in out}, fine_s=time.perf_counter() - t)
    print(json.dumps(out, default=lambda o: o.tolist() if isinstance(o, np.ndarray) else str(o)))


if __name__ == "__main__":
    main()
