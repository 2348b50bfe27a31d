"""General gridded LPV synthesis (lpvsyn) on the rotating-saddle plant: times and gamma.

Run: .venv/bin/python benchmarks/bench_lpvsyn.py [--points 7 13 25] [--rate 0.5] [--feedback state output]
     [--basis trigonometric affine] [--refine 4] [--states 8 16]
For each design grid size, feedback kind and basis: the LMI sizes, the time of the gamma
minimisation, of the back-off re-solve and of the off-grid verification (wall and process CPU:
the machine may be shared), gamma_min, the certified gamma and whether the verification on a
grid ``refine`` times finer passed, with its worst LMI eigenvalue and frozen norm. The plant is
tmfem.control.lpv.examples.rotating_spring(k0=0.2, k1=1.0, r=1.0); with ``--states`` also
random plants of those sizes, A(rho) = A0 + cos(rho) A1 + sin(rho) A2 with A0 stable (seeded),
two inputs, two measurements, for the size dependence.
"""
import argparse
import time

import numpy as np

from tmfem.control.lpv import lpvsyn
from tmfem.control.lpv.basis import Basis
from tmfem.control.lpv.examples import rotating_spring
from tmfem.errors import InfeasibleController


def random_plant(n: int, seed: int = 0, output_feedback: bool = True):
    """rho -> (A, B, C, D): A0 with eigenvalues in [-2, -0.1], A1, A2 of norm 0.5 (seeded), inputs
    [w (2), v (2, output feedback), u (2)], outputs [x_1..x_2, 0.1 u, y (2)]."""
    rng = np.random.default_rng(seed)
    V = rng.standard_normal((n, n))
    A0 = V @ np.diag(-rng.uniform(0.1, 2.0, n)) @ np.linalg.inv(V)
    A1, A2 = (0.5 * M / np.linalg.norm(M, 2) for M in rng.standard_normal((2, n, n)))
    B1, B2 = rng.standard_normal((n, 2)), rng.standard_normal((n, 2))
    C1 = np.vstack([np.eye(2, n), np.zeros((2, n))])
    D1 = np.zeros((4, 6 if output_feedback else 4))
    D1[2:, -2:] = 0.1 * np.eye(2)
    C2 = rng.standard_normal((2, n))

    def P(rho):
        t = float(rho[0])
        A = A0 + np.cos(t) * A1 + np.sin(t) * A2
        if not output_feedback:
            return A, np.hstack([B1, B2]), C1, D1
        D2 = np.zeros((2, 6))
        D2[:, 2:4] = 0.1 * np.eye(2)
        return A, np.hstack([B1, np.zeros((n, 2)), B2]), np.vstack([C1, C2]), np.vstack([D1, D2])
    return P


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, nargs="+", default=[7, 13, 25])
    ap.add_argument("--rate", type=float, default=0.5)
    ap.add_argument("--feedback", nargs="+", default=["state", "output"], choices=["state", "output"])
    ap.add_argument("--basis", nargs="+", default=["trigonometric", "affine"], choices=["trigonometric", "affine"])
    ap.add_argument("--refine", type=int, default=4)
    ap.add_argument("--backoff", type=float, default=0.05)
    ap.add_argument("--states", type=int, nargs="*", default=[])
    a = ap.parse_args()
    print(f"{'feedback':8} {'basis':13} {'points':>6} {'vars':>5} {'lmis':>5} {'size':>4} {'gamma_min':>10} "
          f"{'gamma':>9} {'verified':>8} {'max_lmi_eig':>11} {'frozen':>8} {'t_gamma':>7} {'t_back':>7} "
          f"{'t_verif':>7} {'wall':>6} {'cpu':>6}")
    cases = [(fb, "rotating", rotating_spring(k0=0.2, k1=1.0, r=1.0, output_feedback=fb == "output"))
             for fb in a.feedback]
    cases += [(fb, f"random n={n}", random_plant(n, output_feedback=fb == "output")) for n in a.states
              for fb in a.feedback]
    for fb, plant_name, P in cases:
        print(f"-- {plant_name}")
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
