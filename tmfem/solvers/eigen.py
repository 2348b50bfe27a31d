"""Lowest modes of the generalised eigenproblem (M omega^2 - K_T) phi = 0 (eq. 5.32).

K_T is the tangent about a (prestressed) equilibrium, M the mass matrix. The k eigenpairs
nearest to a shift sigma are found by shift-invert Lanczos (ARPACK through the backend; a
dense solver for small problems). The shift defaults to a small *negative* value, so that
the eigenvalues nearest to it are the lowest ones and K_T - sigma M is non-singular even when
the structure has rigid-body modes. The computed vectors are then refined by a Rayleigh-Ritz
step in their span, which makes them exactly M-orthonormal, also inside clusters of equal
eigenvalues (the pairs of cyclically symmetric structures).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.solvers.backends import get_backend
from tmfem.solvers.newton import submatrix, free_index


@dataclass
class Modes:
    """Eigenpairs sorted by eigenvalue.

    Attributes
    ----------
    omega2 : (k,) eigenvalues omega^2 [rad^2/s^2]; negative values mean an unstable state.
    omega : (k,) sign(omega2) sqrt|omega2| [rad/s].
    freq_hz : (k,) omega / (2 pi) [Hz].
    shapes : (ndof, k) M-orthonormal mode shapes, full vectors with zeros at fixed dofs.
    """

    def __repr__(self) -> str:
        f = ", ".join(f"{v:.4g}" for v in self.freq_hz[:6])
        return (f"Modes({self.freq_hz.size} modes of {self.shapes.shape[0]} dofs, f = [{f}"
                + (", ..." if self.freq_hz.size > 6 else "") + "] Hz)")


    omega2: np.ndarray
    omega: np.ndarray
    freq_hz: np.ndarray
    shapes: np.ndarray


def lowest_modes(K, M, *, k: int, free=None, sigma: float | None = None, backend=None) -> Modes:
    """The k lowest modes of (M omega^2 - K) phi = 0 on the free dofs (eq. 5.32).

    Parameters
    ----------
    K, M : (n, n) sparse or dense
        Tangent stiffness about the equilibrium and mass matrix.
    k : int
        Number of modes.
    free : bool mask, index array or None
        Free dofs; the shapes are zero at the others.
    sigma : float, optional
        Shift; default -1e-6 * mean(diag K / diag M) over the free dofs (below the spectrum).
    """
    n = K.shape[0]
    if K.shape != (n, n) or M.shape != (n, n):
        raise InputError(f"eigen: expected square K and M of equal shape, found {K.shape} and {M.shape}")
    idx = free_index(free, n)
    nf = idx.size
    if not (isinstance(k, (int, np.integer)) and 1 <= k <= nf):
        raise InputError(f"eigen: expected 1 <= k <= {nf} (free dofs), found k={k!r}")
    Kf, Mf = submatrix(K, idx), submatrix(M, idx)
    if sp.issparse(Kf):
        Kf, Mf = sp.csr_matrix(Kf), sp.csr_matrix(Mf)
    dK, dM = Kf.diagonal(), Mf.diagonal()        # sparse, dense or a backend's distributed matrix
    if np.any(dM <= 0):
        raise InputError(f"eigen: expected positive mass on every free dof, found {np.sum(dM <= 0)} "
                         f"free dofs with diagonal mass <= 0")
    if sigma is None:
        sigma = -1e-6 * float(np.mean(np.abs(dK) / dM))
    be = get_backend(backend)
    w, V = be.eigsh(Kf, Mf, int(k), float(sigma))
    # Rayleigh-Ritz in span(V): M-orthonormal vectors, also within repeated eigenvalues (one
    # product of a matrix with V alive at a time; eigh's pairs come ascending)
    Kr = V.T @ (Kf @ V)
    Mr = V.T @ (Mf @ V)
    w, Y = la.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T))
    V = V @ Y
    # deterministic sign: largest component positive (column by column: no copy of V)
    for c in range(V.shape[1]):
        V[:, c] *= np.sign(V[np.argmax(np.abs(V[:, c])), c])
    if nf == n:
        shapes = V
    else:
        shapes = np.zeros((n, V.shape[1]))
        shapes[idx] = V
    omega = np.sign(w) * np.sqrt(np.abs(w))
    return Modes(omega2=w, omega=omega, freq_hz=omega / (2 * np.pi), shapes=shapes)
