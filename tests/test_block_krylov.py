"""Block Krylov-Schur shift-invert eigensolver (tmfem.solvers.block_krylov) and the PETSc
backend's use of it.

Sources of the expected numbers: the closed-form spectrum of the 5-point Laplacian on a
square grid, lambda_ij = (4 / h^2) (sin^2(i pi h / 2) + sin^2(j pi h / 2)), h = 1 / (q + 1)
(repeated for i != j: the pairs of a symmetric structure); LAPACK's dense eigh; SLEPc's
Krylov-Schur on the same model.
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.block_krylov import block_krylov_schur, start_block

ROOT = Path(__file__).resolve().parents[1]

try:
    import petsc4py  # noqa: F401
    import slepc4py  # noqa: F401
    HAVE_PETSC = True
except ImportError:
    HAVE_PETSC = False
needs_petsc = pytest.mark.skipif(not HAVE_PETSC, reason="petsc4py/slepc4py not importable "
                                 "(install: make install)")


def laplacian(q):
    """5-point Laplacian (q^2 unknowns) and its exact eigenvalues, ascending."""
    h = 1.0 / (q + 1)
    T = sp.diags([-np.ones(q - 1), 2 * np.ones(q), -np.ones(q - 1)], [-1, 0, 1]) / h ** 2
    K = sp.csr_matrix(sp.kron(T, sp.identity(q)) + sp.kron(sp.identity(q), T))
    s = (4 / h ** 2) * np.sin(np.arange(1, q + 1) * np.pi * h / 2) ** 2
    return K, np.sort((s[:, None] + s[None, :]).ravel())


def test_start_block_does_not_depend_on_the_row_split():
    full = start_block(0, 1000, 3, chunk=64)
    parts = np.concatenate([start_block(0, 333, 3, chunk=64), start_block(333, 1000, 3, chunk=64)])
    assert np.array_equal(full, parts)
    assert full.shape == (1000, 3) and np.all(np.abs(full) <= 0.5)


@pytest.mark.parametrize("b", [4, 8])
def test_laplacian_modes_match_the_closed_form_with_full_pairs(b):
    K, exact = laplacian(24)
    n = K.shape[0]
    M = sp.diags(np.full(n, 2.0))               # lambda(K, M) = lambda(K) / 2
    sigma = -1.0
    lu = spla.splu(sp.csc_matrix(K - sigma * M))
    theta, X, _ = block_krylov_schur(lambda B: lu.solve(B), lambda Y: M @ Y, lambda P, Q: P.T @ Q,
                                     start_block(0, n, b), k=12, max_basis=48, tol=1e-12)
    lam = sigma + 1.0 / theta
    o = np.argsort(lam)
    lam, X = lam[o], X[:, o]
    assert np.allclose(lam, exact[:12] / 2, rtol=1e-10, atol=0)
    assert np.allclose(X.T @ (M @ X), np.eye(12), atol=1e-10)
    assert np.linalg.norm(K @ X - M @ X * lam) <= 1e-8 * np.linalg.norm(K @ X)
    # a repeated eigenvalue (i != j) comes out as a pair spanning the exact eigenspace
    pair = np.flatnonzero(np.isclose(lam, exact[1] / 2, rtol=1e-9))
    assert pair.size == 2
    w, V = la.eigh(K.toarray(), M.toarray(), subset_by_index=[0, 11])
    ref = V[:, np.isclose(w, exact[1] / 2, rtol=1e-9)]
    P = X[:, pair] @ X[:, pair].T @ M
    assert np.abs(P @ ref - ref).max() <= 1e-8


def test_too_small_a_basis_and_an_exhausted_space_are_named():
    K, exact = laplacian(4)                      # 16 unknowns
    lu = spla.splu(sp.csc_matrix(K + sp.identity(16)))
    ops = (lambda B: lu.solve(B), lambda Y: Y, lambda P, Q: P.T @ Q)
    with pytest.raises(ConvergenceError, match="max_basis >= k \\+ b"):
        block_krylov_schur(*ops, start_block(0, 16, 8), k=6, max_basis=12)
    # two blocks of 8 span the whole space: every pair exact, nothing left to expand
    theta, _, _ = block_krylov_schur(*ops, start_block(0, 16, 8), k=6, max_basis=48)
    assert np.allclose(np.sort(1.0 / theta - 1.0), exact[:6], rtol=1e-10)
    # 12 unknowns: the second block of 8 has only 4 new directions
    K12 = sp.diags([-np.ones(11), 2 * np.ones(12), -np.ones(11)], [-1, 0, 1])
    lu12 = spla.splu(sp.csc_matrix(K12 + sp.identity(12)))
    with pytest.raises(ConvergenceError, match="exhausted"):
        block_krylov_schur(lambda B: lu12.solve(B), lambda Y: Y, lambda P, Q: P.T @ Q,
                           start_block(0, 12, 8), k=10, max_basis=48, tol=1e-14)


@needs_petsc
def test_petsc_block_and_slepc_agree_on_the_mtc_modes():
    # the 1-4 MTC model at its equilibrium (531 free dofs: the block solver's path)
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.petsc import EIG_BLOCK_MIN_N, PetscBackend
    from tmfem.system import load_preset
    m = MTCModel(load_preset("1-4"), mesh_n=6, backend=PetscBackend())
    assert m.distributed.N >= EIG_BLOCK_MIN_N
    st = m.solve_static(start="design")
    block = m.modes(st.x, k=12)
    m.backend = PetscBackend(eig_solver="slepc")
    slepc = m.modes(st.x, k=12)
    assert np.allclose(block.freq_hz, slepc.freq_hz, rtol=1e-10, atol=0)


@needs_petsc
def test_slepc_options_choose_slepc_and_are_refused_by_the_block_solver():
    from tmfem.solvers.petsc import PetscBackend
    assert PetscBackend().eig_solver == "block"                  # one rank
    assert PetscBackend(options="-eps_ncv 40").eig_solver == "slepc"
    with pytest.raises(InputError, match="expected eig_solver='slepc'"):
        PetscBackend(options="-eps_ncv 40", eig_solver="block")
    with pytest.raises(InputError, match="expected eig_solver 'auto', 'block' or 'slepc'"):
        PetscBackend(eig_solver="arpack")


MPIEXEC = shutil.which("mpiexec")


@pytest.mark.skipif(not (HAVE_PETSC and MPIEXEC), reason="petsc4py or mpiexec missing")
def test_block_solver_under_two_ranks_agrees_with_scipy():
    # source: the scipy model's 12 modes at its own equilibrium from the design; under 2
    # ranks the default is SLEPc, the block solver is asked for (rows of the basis
    # distributed, inner products summed over the ranks)
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "ORTE_")) or "ALLOW_RUN_AS_ROOT" in k}
    cmd = [MPIEXEC, "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable,
           str(ROOT / "tests" / "mpi" / "fe_distributed.py"), "1-4", "6", "--start", "design",
           "--eig-solver", "block"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=120, cwd=ROOT, env=env)
    assert p.returncode == 0, p.stderr
    run = json.loads(p.stdout.strip())
    m = MTCModel(load_preset("1-4"), mesh_n=6)
    assert m.free.sum() >= 400                                   # the block solver's size
    ref = m.modes(m.solve_static(start="design").x, k=12)
    assert np.allclose(run["omega2"], ref.omega2, rtol=2e-8, atol=0)
