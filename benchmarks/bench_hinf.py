"""H-infinity synthesis routes on the regression family and the 2-3 design: gamma, verified
norm and time per plant and route.

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 python benchmarks/bench_hinf.py [--skip-slicot] [--no-2-3]
    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 python benchmarks/bench_hinf.py --budget

The family is tests/control/linear/family.py (random plants of several kinds and sizes,
closed-form and published examples, near-integrating and ill-conditioned mixed-sensitivity
plants, COMPleib plants). "verified" is python-control's norm(CL, "inf") of the
returned closed loop; "lower" the certified lower bound of the Riccati route. The last line
is the H-infinity design of the 50-state 2-3 plant by the default route (``tmfem control
hinf --preset 2-3-deploy``), whose target is under 30 s.

``--budget`` prints instead the CPU time of syntheses of random regular plants against the
estimate by which a synthesis too large for the machine is refused before it starts
(:func:`tmfem.resources.synthesis_seconds`; measured/estimate between 0.2 and 3 is what the
estimate was fitted for).
"""
from __future__ import annotations

import argparse
import time

import control

from tests.control.linear.family import family
from tests.control.linear.test_hinf_budget import plant
from tmfem.control import hinfsyn
from tmfem.errors import TmfemError
from tmfem.resources import synthesis_seconds

ROUTES = ("auto", "riccati", "lmi", "slicot")
#: (states, route) of the --budget syntheses
BUDGET = ((50, "riccati"), (100, "riccati"), (20, "lmi"), (30, "lmi"))


def budget() -> None:
    """CPU time of a synthesis against :func:`tmfem.resources.synthesis_seconds`."""
    print(f"{'n':>4s} {'route':8s} {'CPU s':>8s} {'estimate s':>10s} {'ratio':>6s}")
    for n, route in BUDGET:
        c0 = time.process_time()
        hinfsyn(plant(n), 2, 2, method=route)
        cpu = time.process_time() - c0
        est = synthesis_seconds(route=route, n=n)
        print(f"{n:4d} {route:8s} {cpu:8.2f} {est:10.2f} {cpu / est:6.2f}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--skip-slicot", action="store_true", help="leave out python-control's hinfsyn")
    ap.add_argument("--no-2-3", action="store_true", help="leave out the 2-3 design")
    ap.add_argument("--budget", action="store_true",
                    help="only the CPU time of syntheses against the refusal's estimate")
    args = ap.parse_args()
    if args.budget:
        return budget()
    routes = [r for r in ROUTES if not (args.skip_slicot and r == "slicot")]
    print(f"{'plant':34s} {'n':>3s} {'route':8s} {'gamma':>12s} {'verified':>12s} {'lower':>12s} "
          f"{'time s':>7s}  chosen / refusal")
    slowest = {}
    for name, (P, ny, nu, ref) in family().items():
        for r in routes:
            t0 = time.perf_counter()
            try:
                res = hinfsyn(P, ny, nu, method=r)
            except TmfemError as exc:
                res = exc
            dt = time.perf_counter() - t0
            if P.nstates <= 20:
                slowest[r] = max(slowest.get(r, (0.0, "")), (dt, name))
            if isinstance(res, TmfemError):
                print(f"{name:34s} {P.nstates:3d} {r:8s} {'-':>12s} {'-':>12s} {'-':>12s} "
                      f"{dt:7.2f}  refused: {str(res)[:90]}")
                continue
            low = res.info["gamma_lower"]
            print(f"{name:34s} {P.nstates:3d} {r:8s} {res.gamma:12.6g} "
                  f"{float(control.norm(res.CL, p='inf')):12.6g} "
                  f"{'-' if low is None else format(low, '12.6g'):>12s} {dt:7.2f}  "
                  f"{res.info['method']}" + (f" (published/closed form {ref:g})" if ref else ""))
    print("\nslowest call on the plants of up to 20 states (target 10 s): " +
          ", ".join(f"{r} {t:.2f} s ({nm})" for r, (t, nm) in slowest.items()))
    if not args.no_2_3:
        from tmfem.control.linear.deployed_design import deployed_hinf
        from tmfem.system import load_preset
        t0 = time.perf_counter()
        d = deployed_hinf(load_preset("2-3-deploy"))
        dt = time.perf_counter() - t0
        g = d.design
        print(f"\n2-3-deploy (n = {d.plant.ss.nstates}, alpha_1 = {g.alpha:g}): gamma {g.gamma:.6g}, "
              f"verified {g.closed_loop_norm:.6g}, lower {g.gamma_lower}, route "
              f"{g.info['route']['method']}, design {dt:.1f} s (plant build included)")


if __name__ == "__main__":
    main()
