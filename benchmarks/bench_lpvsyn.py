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

With ``--conic-states N ...`` instead: the conic state-feedback synthesis of
tmfem.control.lpv.synthesis (``tmfem control lpv --solver CLARABEL|SCS``) on random stable plants
of N states, n/4 inputs w and u, n/2 outputs p, on a 2 x 2 grid with 4 rate vertices, one
subprocess per size and solver (its CPU time and peak resident memory), beside the estimate
of tmfem.control.lpv.cost.conic_cost (SECONDS_PER_VARIABLE_CUBED is fitted from these rows:
8 16 24 take about 4 minutes of CPU, most of it N = 24).
"""
import argparse
import json
import subprocess
import sys
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


def conic_probe(n: int, solver: str) -> dict:
    """One conic synthesis of :func:`conic_plant` (n states) in this process: CPU s, peak RSS."""
    import resource

    from tmfem.control.lpv.synthesis import synthesize_state_feedback
    c0 = time.process_time()
    try:
        status = synthesize_state_feedback(conic_plant(n), solver=solver, time_budget=1e9).status
    except InfeasibleController as exc:
        status = f"failed: {exc}"
    return {"cpu_s": time.process_time() - c0, "status": status,
            "peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / 1e9}


def conic_plant(n: int):
    """A stable random generalised plant of n states on a 2 x 2 grid (module docstring)."""
    from tmfem.control.lpv.generalized_plant import GeneralizedLPV
    nu = nw = max(1, n // 4)
    npp, shp = nw + nu, (2, 2)
    rng = np.random.default_rng(0)
    A0 = -np.eye(n) + 0.3 * rng.standard_normal((n, n)) / np.sqrt(n)
    tile = lambda M: np.broadcast_to(M, shp + M.shape).copy()          # noqa: E731
    return GeneralizedLPV.from_matrices(
        axes=[np.array([0.0, 1.0])] * 2, parameter_names=["rho0", "rho1"], rate_bounds=[[-0.1, 0.1]] * 2,
        A=np.stack([[A0 + 0.1 * (i + j) * np.eye(n) for j in range(2)] for i in range(2)]),
        B1=tile(rng.standard_normal((n, nw))), B2=tile(rng.standard_normal((n, nu))),
        C1=tile(np.vstack([np.eye(nw, n), np.zeros((nu, n))])), D11=np.zeros(shp + (npp, nw)),
        D12=tile(np.vstack([np.zeros((nw, nu)), np.eye(nu)])))


def conic_table(sizes, solvers, timeout: float) -> None:
    """The --conic-states rows: measured against :func:`tmfem.control.lpv.cost.conic_cost`."""
    from tmfem.control.lpv.coordinates import Coordinates
    from tmfem.control.lpv.cost import conic_cost
    print(f"{'solver':8} {'n':>4} {'vars':>6} {'lmi':>4} {'cpu_s':>8} {'est_s':>8} {'peak_GB':>8} {'est_GB':>7} status")
    for n in sizes:
        sz = Coordinates.of(conic_plant(n)).sizes
        for solver in solvers:
            est = conic_cost(sz, solver=solver)
            try:
                out = subprocess.run([sys.executable, __file__, "--probe", str(n), solver], capture_output=True,
                                     text=True, timeout=timeout, check=True).stdout
                r = json.loads(out.splitlines()[-1])
            except subprocess.TimeoutExpired:
                r = {"cpu_s": float("nan"), "peak_gb": float("nan"), "status": f"over {timeout:g} s wall"}
            print(f"{solver:8} {n:4d} {sz['decision_variables']:6d} {sz['lmi_size']:4d} {r['cpu_s']:8.2f} "
                  f"{est.seconds:8.2f} {r['peak_gb']:8.3f} {est.memory_bytes / 1e9:7.3f} {r['status']}", flush=True)


def main():
    if sys.argv[1:2] == ["--probe"]:
        print(json.dumps(conic_probe(int(sys.argv[2]), sys.argv[3])))
        return
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, nargs="+", default=[7, 13, 25])
    ap.add_argument("--rate", type=float, default=0.5)
    ap.add_argument("--feedback", nargs="+", default=["state", "output"], choices=["state", "output"])
    ap.add_argument("--basis", nargs="+", default=["trigonometric", "affine"], choices=["trigonometric", "affine"])
    ap.add_argument("--refine", type=int, default=4)
    ap.add_argument("--backoff", type=float, default=0.05)
    ap.add_argument("--states", type=int, nargs="*", default=[])
    ap.add_argument("--conic-states", type=int, nargs="*", default=[])
    ap.add_argument("--solvers", nargs="+", default=["CLARABEL", "SCS"], choices=["CLARABEL", "SCS"])
    ap.add_argument("--timeout", type=float, default=300.0, help="--conic-states: wall seconds per run")
    a = ap.parse_args()
    if a.conic_states:
        conic_table(a.conic_states, a.solvers, a.timeout)
        return
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
