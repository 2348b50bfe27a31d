"""LMI sizes and solve times of the H-infinity designs of the three deployed systems (7.4).

    .venv/bin/python benchmarks/bench_control.py [--systems 1-4D,1-6D,2-3-deploy] [--method lmi,riccati,central]

Prints, per system: plant size, LMI variables and block sizes, solver status and time,
gamma, closed-loop max Re and ||T_pw||_inf. A failed synthesis is printed, not hidden.
Target: each synthesis < 60 s on the 2-core machine. ``central``: the central
controller at 1.01 gamma_opt, whose solve time is the Riccati bisection plus SLICOT
SB10FD (docs/guides/control.md).
"""
import argparse
import time

from tmfem.control.linear.deployed_design import deployed_hinf
from tmfem.errors import InfeasibleController
from tmfem.system import load_preset


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--systems", default="1-4D,1-6D,2-3-deploy")
    ap.add_argument("--method", default="lmi,riccati,central")
    a = ap.parse_args()
    for name in a.systems.split(","):
        for method in a.method.split(","):
            t0 = time.perf_counter()
            try:
                d = deployed_hinf(load_preset(name), method=method)
            except InfeasibleController as exc:
                print(f"{name:11s} {method:8s} FAILED after {time.perf_counter() - t0:.1f} s: {exc}")
                continue
            s = d.design.solver
            print(f"{name:11s} {method:8s} n = {d.plant.ss.nstates:3d}, variables {s.n_variables:5d}, "
                  f"LMIs {s.lmi_sizes}, {s.solver} {s.status}, solve {s.solve_time_s:6.1f} s, "
                  f"total {time.perf_counter() - t0:6.1f} s, gamma {d.design.gamma:.6g}, "
                  f"||T||_inf {d.design.closed_loop_norm:.6g}, max Re {d.design.closed_loop_max_real_part:.4g}")


if __name__ == "__main__":
    main()
