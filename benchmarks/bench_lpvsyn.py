"""General gridded LPV synthesis (lpvsyn) on the rotating-saddle plant: times and gamma.

Run: .venv/bin/python benchmarks/bench_lpvsyn.py [--points 7 13 25] [--rate 0.5] [--feedback state output]
     [--basis trigonometric affine] [--refine 4]
For each design grid size, feedback kind and basis: the LMI sizes, the time of the gamma
minimisation, of the back-off re-solve and of the off-grid verification (wall and process CPU:
the machine may be shared), gamma_min, the certified gamma and whether the verification on a
grid ``refine`` times finer passed, with its worst LMI eigenvalue and frozen norm. The plant is
tmfem.control.lpv.examples.rotating_spring(k0=0.2, k1=1.0, r=1.0).
"""
import argparse
import time

import numpy as np

from tmfem.control.lpv import lpvsyn
from tmfem.control.lpv.basis import Basis
from tmfem.control.lpv.examples import rotating_spring
from tmfem.errors import InfeasibleController


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, nargs="+", default=[7, 13, 25])
    ap.add_argument("--rate", type=float, default=0.5)
    ap.add_argument("--feedback", nargs="+", default=["state", "output"], choices=["state", "output"])
    ap.add_argument("--basis", nargs="+", default=["trigonometric", "affine"], choices=["trigonometric", "affine"])
    ap.add_argument("--refine", type=int, default=4)
    ap.add_argument("--backoff", type=float, default=0.05)
    a = ap.parse_args()
    print(f"{'feedback':8} {'basis':13} {'points':>6} {'vars':>5} {'lmis':>5} {'size':>4} {'gamma_min':>10} "
          f"{'gamma':>9} {'verified':>8} {'max_lmi_eig':>11} {'frozen':>8} {'t_gamma':>7} {'t_back':>7} "
          f"{'t_verif':>7} {'wall':>6} {'cpu':>6}")
    for fb in a.feedback:
        P = rotating_spring(k0=0.2, k1=1.0, r=1.0, output_feedback=fb == "output")
        for bname in a.basis:
            basis = Basis.trigonometric() if bname == "trigonometric" else "affine"
            for n in a.points:
                grid = np.linspace(-np.pi, np.pi, n)
                t0, c0 = time.perf_counter(), time.process_time()
                try:
                    r = lpvsyn(P, 2 if fb == "output" else 0, 2, grid=grid, rate_bounds=a.rate, basis=basis,
                               backoff=a.backoff, verify_refine=a.refine, require_verified=False)
                except InfeasibleController as exc:
                    print(f"{fb:8} {bname:13} {n:6d} refused: {exc}")
                    continue
                wall, cpu = time.perf_counter() - t0, time.process_time() - c0
                s, i, v = r.info["sizes"], r.info, r.verification
                print(f"{fb:8} {bname:13} {n:6d} {s['decision_variables']:5d} {s['lmis']:5d} {s['lmi_size']:4d} "
                      f"{r.gamma_min:10.5f} {r.gamma:9.5f} {v['passed']!s:>8} {v['max_lmi_eig']:11.3e} "
                      f"{v['max_frozen_norm']:8.5f} {i['solve_time_gamma_s']:7.2f} {i['solve_time_backoff_s']:7.2f} "
                      f"{i['verify_time_s']:7.2f} {wall:6.1f} {cpu:6.1f}", flush=True)


if __name__ == "__main__":
    main()
