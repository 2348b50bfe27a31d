"""LPV state-feedback synthesis (eqs. 5.95-5.99): LMI sizes and times.

Run: .venv/bin/python benchmarks/bench_lpv.py [--grid 2x2] [--solver SCS] [--max-iter N]
Prints the plant build time, the LMI sizes, the conic build and solve times and gamma for
the 2-3 system of ch. 8 (preset 2-3-lpv) on a sub-grid of P_D (8.3).
"""
import argparse
import time

import numpy as np

from tmfem.control.lpv_plant import com_lpv_plant
from tmfem.control.lpv_synthesis import interconnection_8_1, synthesize_state_feedback
from tmfem.errors import InfeasibleController
from tmfem.reference.tables import PRINTED, deployment_bases
from tmfem.system import load_preset


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grid", default="2x2")
    ap.add_argument("--solver", default="SCS", choices=["CLARABEL", "SCS"])
    ap.add_argument("--max-iter", type=int, default=5000)
    a = ap.parse_args()
    nt, nps = (int(v) for v in a.grid.split("x"))
    P = PRINTED["8.1"]
    th = np.radians(P["theta_grid_deg"]); ps = np.radians(P["psi_grid_deg"])
    th = th[np.round(np.linspace(0, th.size - 1, nt)).astype(int)]
    ps = ps[np.round(np.linspace(0, ps.size - 1, nps)).astype(int)]
    s = load_preset("2-3-lpv")
    t = time.perf_counter()
    pl = com_lpv_plant(s, theta=th, psi=ps, bases=deployment_bases(s))
    print(f"plant: {pl.grid_shape} grid, {pl.nx} states, {pl.nu} inputs: {time.perf_counter() - t:.1f} s")
    gp = interconnection_8_1(pl, tracked=s.q_names)
    t = time.perf_counter()
    try:
        r = synthesize_state_feedback(gp, solver=a.solver, max_iter=a.max_iter)
    except InfeasibleController as exc:
        print(f"synthesis failed after {time.perf_counter() - t:.1f} s: {exc}")
        return
    print(f"sizes: {r.sizes}")
    print(f"build {r.build_time:.1f} s, solve {r.solve_time:.1f} s ({r.solver}, {r.status}), "
          f"gamma = {r.gamma:.4f} (printed < 4.18)")


if __name__ == "__main__":
    main()
