"""How MUMPS (through the PETSc backend) scales from 1 to 2 ranks: factorisation and solves.

    .venv/bin/python benchmarks/mumps_scaling.py [--mesh 160] [--ranks 1,2] [--concurrent]

The matrix is K + M of the 1-4 MTC model (4 x MESH x MESH membrane, 3 elements per tendon)
at the design, assembled rank by rank (:mod:`tmfem.fem.distributed`): symmetric positive
definite, the pattern of the static solve's tangents and of K - sigma M. For each number of
ranks (a fresh ``mpiexec -n P`` process) it prints the free dofs, MUMPS' factor entries
(INFOG(29)), the first factorisation (analysis + numeric), the best of 2 numeric
refactorisations, the median and best of 15 single-vector solves and the best of 4 solves
of 8 right-hand sides (PETSc's MatMatSolve), all wall times of rank 0 between barriers.
``PETSC_OPTIONS`` passes through (e.g. ``-mat_mumps_icntl_13 1``, or
``-pc_type lu -pc_factor_mat_solver_type superlu_dist``).

--concurrent: also run two 1-rank processes at the same time and print both (do two
sequential factorisations and solves on the two cores slow each other down?).
--stream: first the memory bandwidth of a numpy copy of 512 MB (median of 30), by one
process and by two at once (started at the same instant): is one core's bandwidth all the
memory bus gives?

OPENBLAS_NUM_THREADS=1 is set for every run, as in ``bench_backends.py``.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_backends import system_1_4  # noqa: E402

HERE = os.path.abspath(__file__)


def run_one(mesh: int) -> dict:
    """Factorise and solve in this process (under mpiexec: every rank); rank 0's figures."""
    from tmfem.fem.element import State
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.distributed import comm_world
    from tmfem.solvers.petsc import PetscBackend
    comm = comm_world()
    be = PetscBackend()
    m = MTCModel(system_1_4(1.5025), mesh_n=mesh, tendon_elements=3, backend=be)
    dist = m.distributed
    _, K = dist.residual(State(x=m.initial_positions("design")))
    K.mat.axpy(1.0, dist.mass().mat, structure=be.PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)

    def timed(f, repeat):
        out = []
        for _ in range(repeat):
            comm.Barrier()
            t = time.perf_counter()
            f()
            out.append(time.perf_counter() - t)
        return out

    first = timed(lambda: be.factorize(K), 1)[0]
    numeric = min(timed(lambda: be.factorize(K), 2))
    solve = be.factorize(K)
    rng = np.random.default_rng(0)
    b, B = rng.standard_normal(K.shape[0]), rng.standard_normal((K.shape[0], 8))
    single = timed(lambda: solve(b), 15)
    block = min(timed(lambda: solve(B), 4))
    pc = next(iter(be._cache.values())).ksp.getPC()
    solver = pc.getFactorSolverType()
    entries = pc.getFactorMatrix().getMumpsInfog(29) if solver == "mumps" else None
    return dict(ranks=comm.size, dofs=K.shape[0], solver=solver, entries=entries, first_s=first,
                numeric_s=numeric, solve_ms=1e3 * float(np.median(single)),
                solve_best_ms=1e3 * min(single), block8_ms=1e3 * block)


def stream(start: float) -> float:
    """Copy bandwidth [GB/s] of this process (median of 30 copies of 512 MB), from ``start``
    (a time.time() instant) on."""
    a = np.ones(2**26)
    b = np.empty_like(a)
    np.copyto(b, a)
    time.sleep(max(start - time.time(), 0.0))
    ts = []
    for _ in range(30):
        t = time.perf_counter()
        np.copyto(b, a)
        ts.append(time.perf_counter() - t)
    return 2 * a.nbytes / float(np.median(ts)) / 1e9


def launch_stream(start: float) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, HERE, "--stream-at", repr(start)],
                            stdout=subprocess.PIPE, text=True)


def launch(mesh: int, ranks: int) -> subprocess.Popen:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "ORTE_")) or "ALLOW_RUN_AS_ROOT" in k}
    env["OPENBLAS_NUM_THREADS"] = "1"
    cmd = [sys.executable, HERE, "--run", str(mesh)]
    if ranks > 1:
        cmd = [shutil.which("mpiexec"), "--allow-run-as-root", "--oversubscribe", "-n", str(ranks)] + cmd
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def result(p: subprocess.Popen) -> dict:
    out, err = p.communicate()
    if p.returncode != 0:
        return dict(error=(err.strip().splitlines() or ["no output"])[-1])
    return json.loads(out.strip().splitlines()[-1])


def row(r: dict, label: str) -> str:
    if "error" in r:
        return f"{label:>12s}  error: {r['error']}"
    entries = f"{r['entries'] / 1e6:8.2f}" if r["entries"] is not None else f"{'-':>8s}"
    return (f"{label:>12s} {r['dofs']:8d} {r['solver']:>12s} {entries} {r['first_s']:8.2f} "
            f"{r['numeric_s']:9.3f} {r['solve_ms']:9.1f} {r['solve_best_ms']:9.1f} "
            f"{r['block8_ms']:9.1f}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=int, default=160)
    ap.add_argument("--ranks", default="1,2")
    ap.add_argument("--concurrent", action="store_true",
                    help="also two 1-rank runs at the same time")
    ap.add_argument("--stream", action="store_true", help="first the copy bandwidth of 1 and 2 processes")
    ap.add_argument("--run", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--stream-at", type=float, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.stream_at:
        print(stream(args.stream_at))
        return 0
    if args.run:
        from tmfem.cli import rank_report
        from tmfem.solvers.distributed import mpi_main
        return mpi_main(lambda: json.dumps(run_one(args.run)), report=rank_report())
    print(f"# 1-4 MTC K + M at the design, 4x{args.mesh}x{args.mesh}; load average "
          f"{os.getloadavg()[0]:.2f}; PETSC_OPTIONS={os.environ.get('PETSC_OPTIONS', '')!r}")
    if args.stream:
        for n in (1, 2):
            start = time.time() + 2.0
            rates = [float(p.communicate()[0]) for p in [launch_stream(start) for _ in range(n)]]
            print(f"# copy bandwidth, {n} process{'es at once' if n > 1 else ''}: "
                  + ", ".join(f"{r:.1f}" for r in rates) + " GB/s", flush=True)
    print(f"{'run':>12s} {'dofs':>8s} {'solver':>12s} {'entries M':>8s} {'first s':>8s} "
          f"{'numeric s':>9s} {'solve ms':>9s} {'best ms':>9s} {'8 rhs ms':>9s}")
    for ranks in [int(v) for v in args.ranks.split(",")]:
        print(row(result(launch(args.mesh, ranks)), f"{ranks} rank" + "s" * (ranks > 1)), flush=True)
    if args.concurrent:
        pair = [launch(args.mesh, 1), launch(args.mesh, 1)]
        for k, p in enumerate(pair):
            print(row(result(p), f"1 of 2 ({k + 1})"), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
