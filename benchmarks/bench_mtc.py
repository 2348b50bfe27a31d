"""Speed of the MTC model: static + 12 modes of the 1-4 system at growing membrane meshes.

    .venv/bin/python benchmarks/bench_mtc.py [--meshes 10,20,40,80] [--start undeformed]

For each mesh 4 x n x n prints the free DOFs, model build time, Newton iterations on that
mesh (after mesh sequencing from n = 10, halving), time per iteration (static time over all
iterations of all levels), static time (from the undeformed membrane, as `tmfem static`), modal time
(12 modes, shift-invert), peak memory (resident set, and the numpy/Python share traced by
tracemalloc), and, as a same-process baseline, one factorisation of the tangent with
scipy's default spsolve (COLAMD, partial pivoting) against the backend's symmetric-mode
SuperLU (minimum degree on A^T + A) that the model uses.
Targets: ~1.3k DOF static + 12 modes < 1 s; ~100k DOF < 60 s, on 2 cores.
"""
from __future__ import annotations

import argparse
import os
import resource
import sys
import time
import tracemalloc

import numpy as np
import scipy.sparse.linalg as spla


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="10,20,40,80")
    ap.add_argument("--start", choices=("undeformed", "design"), default="undeformed")
    ap.add_argument("--sequence", type=int, default=10,
                    help="coarsest mesh of the mesh sequencing of the static solve (0: none)")
    ap.add_argument("--rest-length", type=float, default=1.5025,
                    help="rest length of the S tendons [m] (default: the value Tables 6.3/6.6 imply)")
    args = ap.parse_args(argv)
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset

    system = load_preset("1-4", as_printed=True).with_rest_lengths({"S1": args.rest_length})
    load = os.getloadavg()[0]
    print(f"# 1-4 MTC benchmark, {os.cpu_count()} cpus, load average {load:.2f} at start, "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}")
    head = (f"{'mesh':>9s} {'dofs':>7s} {'build s':>8s} {'its':>4s} {'s/it':>7s} {'static s':>9s} "
            f"{'modal s':>8s} {'total s':>8s} {'RSS MB':>7s} {'traced MB':>9s} {'LU default':>10s} "
            f"{'LU sym':>7s} {'ratio':>6s}  f1 [Hz]")
    print(head)
    for n in [int(v) for v in args.meshes.split(",")]:
        tracemalloc.start()
        t0 = time.perf_counter()
        m = MTCModel(system, mesh_n=n, tendon_elements=3)
        t1 = time.perf_counter()
        res = m.equilibrium(start=args.start, sequence=args.sequence or None)
        t2 = time.perf_counter()
        modes = m.modes(k=12, at=res.x)
        t3 = time.perf_counter()
        _, traced = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
        # baseline: one factorisation + solve of the converged tangent, both ways
        r, K = m.residual(m.reduce(res.x))
        A = K[m.free][:, m.free].tocsc()
        b = np.ones(A.shape[0])
        ta = time.perf_counter()
        spla.spsolve(A, b)
        tb = time.perf_counter()
        m.backend.factorize(A)(b)
        tc = time.perf_counter()
        its = (res.level_iterations or [res.iterations])[-1]   # on this mesh
        print(f"{'4x%dx%d' % (n, n):>9s} {m.ndof:7d} {t1 - t0:8.2f} {its:4d} "
              f"{(t2 - t1) / res.iterations:7.3f} {t2 - t1:9.2f} {t3 - t2:8.2f} {t3 - t0:8.2f} "
              f"{rss:7.0f} {traced / 2**20:9.0f} {tb - ta:10.3f} {tc - tb:7.3f} "
              f"{(tb - ta) / max(tc - tb, 1e-9):6.2f}  {modes.freq_hz[0]:.5f}", flush=True)
    print(f"# load average {os.getloadavg()[0]:.2f} at end", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
