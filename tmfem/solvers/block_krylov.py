"""Block Krylov-Schur shift-invert eigensolver for K v = lambda M v (eq. 5.32), K, M symmetric.

The operator Op = (K - sigma M)^-1 M is self-adjoint in the M-inner product; its
eigenvalues theta = 1 / (lambda - sigma) are largest in magnitude for the lambda nearest to
sigma. A block Krylov space of Op (block size b) is built with an M-orthonormal basis V
(block classical Gram-Schmidt, twice, and a Cholesky QR of each new block, twice):

    Op V_m = V_m H_m + V_{m+1} R_{m+1} E_m^T,      H_m = V_m^T M Op V_m,

the Ritz pairs (theta_i, V_m y_i) of H_m have the residuals
||Op x_i - theta_i x_i||_M = ||R_{m+1} y_i[last block]||, and a pair has converged when
that residual is at most ``tol`` |theta_i| (the convergence test of SLEPc's Krylov-Schur,
relative to the eigenvalue). When the basis is full, it is restarted Krylov-Schur style
with the ``keep`` wanted Ritz vectors and the last block (Op X = X Theta + V_{m+1} R y^T).

Why blocks: a direct solver applies (K - sigma M)^-1 to b right-hand sides at once for a
fraction of b single solves (MUMPS: 5-7x less time per column at b = 12-24 on 78k DOF,
the triangular solves being bound by reading the factors), and the eigen solve of
:func:`tmfem.solvers.eigen.lowest_modes` is mostly such solves.

The caller supplies the operations on row blocks of this rank (the vectors are distributed:
each rank holds rows [lo, hi) of every basis vector): ``solve(B)`` = (K - sigma M)^-1 B,
``mass(X)`` = M X and ``dot(X, Y)`` = X^T Y summed over the ranks.
"""
from __future__ import annotations

import logging

import numpy as np
import scipy.linalg as la

from tmfem.errors import ConvergenceError

log = logging.getLogger(__name__)


def start_block(lo: int, hi: int, b: int, *, seed: int = 7, chunk: int = 65536) -> np.ndarray:
    """Rows [lo, hi) of a fixed pseudo-random (n, b) start block, uniform in [-1/2, 1/2):
    the same numbers for any split of the rows over the ranks (generated in chunks of
    ``chunk`` rows, each from its own seed)."""
    out = np.empty((hi - lo, b))
    for c in range(lo // chunk, (hi - 1) // chunk + 1 if hi > lo else lo // chunk):
        a, z = max(lo, c * chunk), min(hi, (c + 1) * chunk)
        rows = np.random.default_rng([seed, c]).random((z - c * chunk, b)) - 0.5
        out[a - lo:z - lo] = rows[a - c * chunk:]
    return out


def _orthonormalize(W, MW, dot):
    """W R^-1, M W R^-1 and R with W^T M W = R^T R (Cholesky QR, twice for round-off) of a
    block W of full rank."""
    R = np.eye(W.shape[1])
    for _ in range(2):
        G = dot(W, MW)
        C = la.cholesky(0.5 * (G + G.T), lower=False)
        Ci = la.solve_triangular(C, np.eye(C.shape[0]), lower=False)
        W, MW = W @ Ci, MW @ Ci
        R = C @ R
    return W, MW, R


def block_krylov_schur(solve, mass, dot, X0, *, k: int, max_basis: int, keep: int | None = None,
                       tol: float = 1e-12, max_restarts: int = 200):
    """The k eigenpairs of Op = (K - sigma M)^-1 M largest in magnitude (module docstring).

    Parameters
    ----------
    solve : callable
        ``solve(B)``: (K - sigma M)^-1 B for a block B (n_local, b).
    mass : callable
        ``mass(X)``: M X (n_local, b).
    dot : callable
        ``dot(X, Y)``: X^T Y (summed over the ranks), (p, q) the same on every rank.
    X0 : (n_local, b)
        Start block (this rank's rows; :func:`start_block`).
    k : int
        Number of wanted pairs.
    max_basis : int
        Largest basis size (a multiple of b is best); at least k + b.
    keep : int, optional
        Ritz vectors kept at a restart (default: half the basis, at least k).
    tol : float
        Relative residual ||Op x - theta x||_M <= tol |theta| of a converged pair.

    Returns
    -------
    theta : (k,) eigenvalues of Op, by decreasing magnitude (lambda = sigma + 1 / theta)
    X : (n_local, k) M-orthonormal eigenvectors (this rank's rows)
    restarts : int
    """
    n_loc, b = X0.shape
    if max_basis < k + b:
        raise ConvergenceError(f"block Krylov-Schur: expected max_basis >= k + b = {k + b}, "
                               f"found {max_basis}")
    keep = max(k, max_basis // 2) if keep is None else max(int(keep), k)
    keep = min(keep, max_basis - b)
    cap = max_basis + b
    V = np.empty((n_loc, cap), order="F")      # columns contiguous: V[:, :m] is one block
    H = np.zeros((cap, cap))
    V[:, :b], MVm, _ = _orthonormalize(X0, mass(X0), dot)
    m = 0                              # columns with their image Op V expanded
    restarts = 0
    while True:
        # expand the newest block V[:, m:m+b] (M V of it: MVm): W = Op V_new - V (V^T M Op V_new)
        W = solve(MVm)
        MW = mass(W)
        C = np.zeros((m + b, b))
        norm2 = np.diag(dot(W, MW))
        for sweep in range(2):         # classical Gram-Schmidt, repeated when it cancelled
            D = dot(V[:, :m + b], MW)
            W -= V[:, :m + b] @ D
            C += D
            MW = mass(W)
            G = dot(W, MW)
            if sweep == 0 and np.all(np.diag(G) > 0.5 * norm2):
                break                  # no column lost more than 1 - 1/sqrt(2) of its M-norm
        H[:m + b, m:m + b] = C
        m += b
        # Rayleigh-Ritz in span V[:, :m]: Op V = V H + W E^T, the residual of (theta, V y)
        # is W y[last block], of M-norm^2 y_l^T (W^T M W) y_l
        Hm = H[:m, :m]
        theta, Y = la.eigh(0.5 * (Hm + Hm.T))
        order = np.argsort(-np.abs(theta), kind="stable")
        theta, Y = theta[order], Y[:, order]
        Yl = Y[m - b:m, :]
        res = np.sqrt(np.maximum(np.einsum("ij,ik,kj->j", Yl, G, Yl), 0.0))
        done = res[:k] <= tol * np.abs(theta[:k])
        if done.all():
            log.debug("block Krylov-Schur: %d pairs after %d restarts, basis %d", k, restarts, m)
            return theta[:k], V[:, :m] @ Y[:, :k], restarts
        if la.eigvalsh(0.5 * (G + G.T))[0] <= 1e-20 * norm2.max():
            raise ConvergenceError("block Krylov-Schur: expected a new block of full rank, found a "
                                   f"rank-deficient one with {int(done.sum())} of k={k} pairs "
                                   "converged (the Krylov space is exhausted: too small a problem "
                                   "for blocks of this size)")
        Wn, MVm, R = _orthonormalize(W, MW, dot)
        H[m:m + b, m - b:m] = R
        V[:, m:m + b] = Wn
        if m + b > max_basis:          # restart with the kept Ritz vectors and the last block
            restarts += 1
            if restarts > max_restarts:
                raise ConvergenceError(f"block Krylov-Schur: {int(done.sum())} of k={k} pairs "
                                       f"converged to {tol:g} in {max_restarts} restarts")
            p = keep
            V[:, :p] = V[:, :m] @ Y[:, :p]
            V[:, p:p + b] = V[:, m:m + b]
            H[:] = 0.0
            H[:p, :p] = np.diag(theta[:p])
            H[p:p + b, :p] = R @ Yl[:, :p]
            m = p
