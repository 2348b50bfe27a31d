"""Speed of the element kernels and of the linear solver.

    .venv/bin/python benchmarks/bench_kernels.py [--sizes 10,20,40,80]

For a square membrane meshed as 4 x n x n quads (n = 10 is the paper's 1.3k-dof mesh) it
prints, per size: the membrane residual + tangent by the einsum kernel and by the scikit-fem
forms (baseline, same process), a truss network of the same node count, and the factorisation
of the tangent with SuperLU's MMD ordering (baseline) and with our nested dissection.
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from timing import best
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def main(argv=None):
    from tmfem.fem.membrane import MembraneTL
    from tmfem.fem.truss import TrussSet, truss_internal
    from tmfem.mesh.polygon import polygon_quad_mesh
    from tmfem.solvers.backends import nested_dissection
    from tmfem.system.materials import MembraneMaterial

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="10,20,40,80")
    args = ap.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    print(f"{'mesh':>10s} {'dofs':>7s} {'kernel':>8s} {'forms':>8s} {'ratio':>6s} {'truss':>8s} "
          f"{'LU mmd':>8s} {'order':>7s} {'LU nd':>8s} {'ratio':>6s}   [s]")
    for n in sizes:
        a = 2.0
        mesh = polygon_quad_mesh(np.array([[0, a, a, 0], [0, 0, a, a]], float), n)
        mem = MembraneTL(mesh=mesh, material=MembraneMaterial(E=1.65e8, nu=0.34, rho=1400.0, h=51e-6))
        x = mem.X.copy()
        x[:2] *= 1.001
        x[2] = 0.01 * np.sin(np.pi * x[0] / a) * np.sin(np.pi * x[1] / a)
        t_kernel = best(lambda: mem.internal(x))
        t_forms = best(lambda: mem.internal_forms(x), repeat=1 if n >= 40 else 3)
        # truss network on the mesh edges (4 per quad, duplicates kept: same work as a model)
        t4 = mesh.t
        conn = np.hstack([t4[[0, 1]], t4[[1, 2]], t4[[2, 3]], t4[[3, 0]]])
        L = np.linalg.norm(mem.X[:, conn[1]] - mem.X[:, conn[0]], axis=0)
        ts = TrussSet(conn=conn, L=L, EA=np.full(L.size, 1e3), rhoA=np.full(L.size, 0.1),
                      tension_only=np.ones(L.size, bool))
        t_truss = best(lambda: truss_internal(x, ts))
        _, K = mem.internal(x)
        free = np.ones((mem.nn, 3), bool)
        free[mesh.corners[0]] = False
        free[mesh.corners[1], 1:] = False
        free[mesh.corners[3], [0, 2]] = False
        idx = np.flatnonzero(free.ravel())
        A = sp.csc_matrix(K[idx][:, idx])
        t_mmd = best(lambda: spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                       options=dict(SymmetricMode=True)), repeat=1 if n >= 40 else 3)
        t0 = time.perf_counter()
        perm = nested_dissection(A)
        t_order = time.perf_counter() - t0
        Ap = sp.csc_matrix(A[perm][:, perm])
        t_nd = best(lambda: spla.splu(Ap, permc_spec="NATURAL", diag_pivot_thresh=0.0,
                                      options=dict(SymmetricMode=True)), repeat=1 if n >= 40 else 3)
        print(f"{'4x%dx%d' % (n, n):>10s} {mem.ndof:7d} {t_kernel:8.3f} {t_forms:8.3f} {t_forms / t_kernel:6.1f} "
              f"{t_truss:8.3f} {t_mmd:8.3f} {t_order:7.2f} {t_nd:8.3f} {t_mmd / t_nd:6.1f}", flush=True)
        print(f"  done 4x{n}x{n}", file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
