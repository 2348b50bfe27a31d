"""Does a start from the coarse mesh's modes save eigen solves? (1-4 MTC, 12 modes, 1 rank)

    .venv/bin/python benchmarks/eigen_coarse_start.py COARSE FINE
    .venv/bin/python benchmarks/eigen_coarse_start.py 40 80

Solves the static equilibrium and the 12 modes on the COARSE mesh (scipy backend), the
equilibrium on the FINE mesh from the interpolated coarse one, then runs
:func:`tmfem.solvers.block_krylov.block_krylov_schur` (tolerance 1e-12, sigma = -1 as
``MTCModel.modes``) on the fine K, M from four start blocks: random blocks of 8 and 12
columns, the 12 coarse modes interpolated like the static solution
(``MTCModel.interpolate_from`` of x + phi_j, minus that of x), and those plus 4 random
columns. Prints the number of solved columns and restarts of each, and the first
frequencies (the same for every start). The counts do not depend on the machine's load.
"""
from __future__ import annotations

import os
import sys

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_backends import system_1_4  # noqa: E402


def main(argv=None) -> int:
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.backends import get_backend
    from tmfem.solvers.block_krylov import block_krylov_schur, start_block
    argv = sys.argv[1:] if argv is None else argv
    nc, nf = int(argv[0]), int(argv[1])
    system = system_1_4(1.5025)
    mc = MTCModel(system, mesh_n=nc, tendon_elements=3)
    rc = mc.equilibrium(sequence=10)
    xc = rc.x
    coarse = mc.modes(k=12, at=rc)
    mf = MTCModel(system, mesh_n=nf, tendon_elements=3)
    rf = mf.equilibrium(x0=mf.interpolate_from(mc, xc))
    S = mc.full_shapes(coarse.shapes)
    base = mf.reduce(mf.interpolate_from(mc, xc))
    idx = np.flatnonzero(mf.free)
    V0 = np.column_stack([mf.reduce(mf.interpolate_from(mc, xc + S[:, :, j])) - base
                          for j in range(12)])[idx]
    K, M = sp.csr_matrix(rf.tangent)[idx][:, idx], sp.csr_matrix(mf.mass())[idx][:, idx]
    sigma, n = -1.0, idx.size
    lu = get_backend("scipy").factorize(sp.csc_matrix(K - sigma * M))
    columns = [0]

    def solve(B):
        columns[0] += B.shape[1]
        return lu(B)

    starts = {"random, b = 8": start_block(0, n, 8), "random, b = 12": start_block(0, n, 12),
              "coarse modes, b = 12": V0,
              "coarse modes + 4 random, b = 16": np.column_stack([V0, start_block(0, n, 4)])}
    print(f"# 4x{nc}x{nc} -> 4x{nf}x{nf}: {n} free dofs; coarse f1..3 {coarse.freq_hz[:3]} Hz")
    for name, X0 in starts.items():
        columns[0] = 0
        b = X0.shape[1]
        theta, _, restarts = block_krylov_schur(solve, lambda X: M @ X, lambda X, Y: X.T @ Y, X0,
                                                k=12, max_basis=max(48, 12 + 4 * b), tol=1e-12)
        f = np.sqrt(np.sort(sigma + 1.0 / theta)[:3]) / (2 * np.pi)
        print(f"{name:32s} solved columns {columns[0]:4d}  restarts {restarts}  f1..3 {f} Hz",
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
