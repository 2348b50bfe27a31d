"""Block Krylov-Schur shift-invert eigensolver (tmfem.solvers.block_krylov); the PETSc
backend's use of it is tested in tests/solvers/test_petsc_backend.py.

Sources of the expected numbers: the closed-form spectrum of the 5-point Laplacian on a
square grid, lambda_ij = (4 / h^2) (sin^2(i pi h / 2) + sin^2(j pi h / 2)), h = 1 / (q + 1)
(repeated for i != j: the pairs of a symmetric structure); LAPACK's dense eigh.
"""
import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from tmfem.errors import ConvergenceError
from tmfem.solvers.block_krylov import block_krylov_schur, start_block

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
