"""LPV state-feedback synthesis (eqs. 5.95-5.99): LMI sizes and times.

Run: .venv/bin/python benchmarks/bench_lpv.py [--grid 2x2] [--solver SCS] [--max-iter N]
     .venv/bin/python benchmarks/bench_lpv.py --grid 6x3 --solver EIGOPT [--sample-time 0.01]
         [--gamma-upper G] [--rtol 0.05] [--budget 300] [--grid-continuation auto|on|off]
Prints the plant build time, the LMI sizes, the solve times (wall and CPU: the machine may be
shared) and gamma for the 2-3 system of ch. 8 (preset 2-3-lpv) on a sub-grid of P_D (8.3);
EIGOPT: the gamma bisection (docs/guides/lpv.md) from --gamma-upper (default 2 x the pointwise bound),
with the continuation in the grid (6 x 1 first) as bisect_gamma decides (auto) or forced on/off;
prints every level (also the sub-grid's), the bracket and the CPU time.
"""
import argparse
import time

from tmfem.cli.lpv_options import printed_grid
from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
from tmfem.control.lpv.plant import com_lpv_plant
from tmfem.control.lpv.generalized_plant import interconnection_8_1
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.errors import InfeasibleController
from tmfem.reference.tables import PRINTED, deployment_bases
from tmfem.system import load_preset


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grid", default="2x2")
    ap.add_argument("--solver", default="SCS", choices=["CLARABEL", "SCS", "EIGOPT"])
    ap.add_argument("--max-iter", type=int, default=5000)
    ap.add_argument("--sample-time", type=float, default=None)
    ap.add_argument("--gamma-upper", type=float, default=None)
    ap.add_argument("--rtol", type=float, default=0.05)
    ap.add_argument("--budget", type=float, default=300.0)
    ap.add_argument("--grid-continuation", default="auto", choices=["auto", "on", "off"])
    a = ap.parse_args()
    th, ps = printed_grid(a.grid, PRINTED["8.1"])
    s = load_preset("2-3-lpv")
    t = time.perf_counter()
    pl = com_lpv_plant(s, theta=th, psi=ps, bases=deployment_bases(s))
    print(f"plant: {pl.grid_shape} grid, {pl.nx} states, {pl.nu} inputs: {time.perf_counter() - t:.1f} s")
    gp = interconnection_8_1(pl, tracked=s.q_names)
    t, c = time.perf_counter(), time.process_time()
    try:
        if a.solver == "EIGOPT":
            from tmfem.control.lpv.bisect import bisect_gamma
            lb = pointwise_state_feedback_bound(gp).lower_bound
            print(f"pointwise bound {lb:.4f}: {time.perf_counter() - t:.1f} s wall, "
                  f"{time.process_time() - c:.1f} s CPU")
            gc = {"auto": None, "on": True, "off": False}[a.grid_continuation]
            r, br = bisect_gamma(gp, lower=lb, upper=a.gamma_upper or 2 * lb, rtol=a.rtol, time_budget=a.budget,
                                 max_iter=150, sample_time=a.sample_time, grid_continuation=gc)
            for name, rows in (("sub-grid " + "x".join(map(str, br.start_grid or [])), br.start_levels),
                               ("grid " + a.grid, br.levels)):
                for lv in rows:
                    print(f"  {name} level {lv['gamma']:.4f}: {lv['result']} ({lv['evaluations']} evaluations, "
                          f"{lv['time_s']:.1f} s wall, {lv.get('cpu_s', float('nan')):.1f} s CPU, start {lv['start']})")
            print(f"bracket [{br.lower_bound:.4f} proven, {br.feasible:.4f} feasible], not found at "
                  f"{br.not_found}, stopped on {br.stopped}")
        else:
            r = synthesize_state_feedback(gp, solver=a.solver, max_iter=a.max_iter)
    except InfeasibleController as exc:
        print(f"synthesis failed after {time.perf_counter() - t:.1f} s: {exc}")
        return
    print(f"sizes: {r.sizes}")
    print(f"solve {time.perf_counter() - t:.1f} s wall, {time.process_time() - c:.1f} s CPU ({r.solver}, "
          f"{r.status}), gamma = {r.gamma:.4f} (printed < 4.18)")


if __name__ == "__main__":
    main()
