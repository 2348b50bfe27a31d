"""Speed of a 20 s deployment at dt = 0.01 s (target: >= 10x faster than real time).

Per system: the real-time factor t_end / time of the closed-loop run (Park's method with
the controller in the loop), by wall time and by the process's CPU time (the machine is
shared: wall time includes waiting for a core), then the time of the recovery after the
run (outputs, reference, stresses), and where the time goes from a cProfile run.

    .venv/bin/python benchmarks/bench_deploy.py [--preset 1-4D] [--t-end 20] [--uncertainty exact]
        [--controller adaptive-lqr] [--profile-t-end 5]
"""
import argparse
import cProfile
import pstats
import re
import time

from tmfem.reference.deployments import setup
from tmfem.control.deployment.run import run_deployment

#: (label, regular expression on "file:line(function)") of the profile breakdown
PARTS = [("controller: M_hat, F_hat, B_hat (casadi)", r"model\.py:\d+\(matrices\)"),
         ("controller: M G term (no-MG model)", r"model\.py:\d+\(mg_term\)"),
         ("controller: partition eqs. 5.39-5.41", r"pfl\.py:\d+\(partition\)"),
         ("controller: bounded inversion", r"pfl\.py:\d+\(bounded_inversion\)"),
         ("controller: reference q_d", r"reference_trajectory\.py:\d+\(__call__\)"),
         ("controller: B_q condition number", r"pfl\.py:\d+\(check_input_matrix\)"),
         ("controller: all of eq. 5.58", r"adaptive\.py:\d+\(_terms\)"),
         ("limits: tendon lengths", r"limits\.py:\d+\(tendon_lengths\)"),
         ("linear controller (after the switch)", r"controllers\.py:\d+\((output|update)\)"),
         ("Park: residual (casadi)", r"model\.py:\d+\(residual\)"),
         ("Park: Newton matrix", r"model\.py:\d+\(newton_matrix\)"),
         ("Park: LU solves", r"_decomp_lu\.py:\d+\(lu_(factor|solve)\)"),
         ("Park: whole integration", r"park\.py:\d+\(park_integrate\)"),
         ("recovery: outputs w, |tendon|", r"model\.py:\d+\(fast_outputs\)"),
         ("recovery: bars and membrane", r"recovery\.py:\d+\(bars_and_membrane\)"),
         ("recovery: unit membrane solutions", r"recovery\.py:\d+\(__init__\)")]


def run(s, t_end):
    return run_deployment(model=s.model, reference=s.reference, controller=s.controller,
                          z0=s.z0, t_end=t_end, dt=0.01)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--preset", action="append")
    ap.add_argument("--t-end", type=float, default=20.0)
    ap.add_argument("--profile-t-end", type=float, default=5.0)
    ap.add_argument("--uncertainty", default=None)
    ap.add_argument("--controller", default="adaptive-lqr")
    a = ap.parse_args()
    for p in a.preset or ["1-4D", "1-6D", "2-3-deploy"]:
        t0 = time.perf_counter()
        s = setup(p, controller=a.controller, uncertainty=a.uncertainty)
        t_setup = time.perf_counter() - t0
        w0, c0 = time.perf_counter(), time.process_time()
        r = run(s, a.t_end)
        wall, cpu = time.perf_counter() - w0, time.process_time() - c0
        print(f"{p} ({s.adaptive.uncertainty}, {a.controller}): setup {t_setup:.2f} s; "
              f"closed-loop run {r.wall_time:.2f} s wall = {a.t_end / r.wall_time:.1f}x real "
              f"time; run + recovery {wall:.2f} s wall, {cpu:.2f} s CPU "
              f"({a.t_end / cpu:.1f}x real time by CPU); switch {r.switch_time} s")
        s = setup(p, controller=a.controller, uncertainty=a.uncertainty)
        prof = cProfile.Profile()
        prof.enable()
        run(s, a.profile_t_end)
        prof.disable()
        st = pstats.Stats(prof)
        total = max(v[3] for v in st.stats.values())
        print(f"    profile of a {a.profile_t_end:g} s run ({total:.2f} s under cProfile):")
        for label, pat in PARTS:
            tot = sum(v[3] for k, v in st.stats.items()
                      if re.search(pat, f"{k[0].rsplit('/', 1)[-1]}:{k[1]}({k[2]})"))
            print(f"      {label:42s} {tot:6.2f} s  {100 * tot / total:5.1f} %")


if __name__ == "__main__":
    main()
