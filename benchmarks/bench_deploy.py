"""Speed of a 20 s deployment at dt = 0.01 s (issue 13 target: >= 10x faster than real time).

Prints, per system, the wall time of the run, the real-time factor and where the time goes
(cProfile cumulative times of the Park Newton matrix, the residual, the controller and the
recording with its stress recovery).

    .venv/bin/python benchmarks/bench_deploy.py [--preset 1-4D] [--t-end 20] [--uncertainty exact]
"""
import argparse
import cProfile
import pstats
import time

from tmfem.cli.deploy import setup
from tmfem.control.deploy import run_deployment

PARTS = {"newton_matrix": "model.py:.*(newton_matrix)", "residual": "model.py:.*(residual)",
         "controller": "adaptive.py:.*(_terms)", "record": "deploy.py:.*(record)",
         "stress recovery": "design.py:.*(membrane_state)", "zeta": "model.py:.*(zeta)"}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--preset", action="append")
    ap.add_argument("--t-end", type=float, default=20.0)
    ap.add_argument("--uncertainty", default=None)
    a = ap.parse_args()
    for p in a.preset or ["1-4D", "1-6D", "2-3-deploy"]:
        t0 = time.perf_counter()
        s = setup(p, controller="adaptive-lqr", uncertainty=a.uncertainty)
        t_setup = time.perf_counter() - t0
        prof = cProfile.Profile()
        t0 = time.perf_counter()
        prof.enable()
        try:
            r = run_deployment(model=s.model, reference=s.reference, controller=s.controller,
                               z0=s.z0, t_end=a.t_end, dt=0.01)
            ok = "ok"
        except Exception as exc:                       # report a diverging run, keep going
            ok = f"failed: {exc}"
            r = None
        prof.disable()
        wall = time.perf_counter() - t0
        print(f"{p}: setup {t_setup:.2f} s, run {wall:.2f} s for {a.t_end:g} s "
              f"({a.t_end / wall:.1f}x real time, profiled) {ok}")
        st = pstats.Stats(prof)
        for name, pat in PARTS.items():
            import re
            tot = sum(v[3] for k, v in st.stats.items()
                      if re.search(pat, f"{k[0].rsplit('/', 1)[-1]}:{k[1]}({k[2]})"))
            print(f"    {name:16s} {tot:6.2f} s")
        if r is not None:
            print(f"    switch {r.switch_time}, Park steps {r.t.size - 1}")


if __name__ == "__main__":
    main()
