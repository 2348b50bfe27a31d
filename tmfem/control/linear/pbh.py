"""Popov-Belevitch-Hautus eigenvector tests (eq. 5.71 and the criteria stated after it).

(A, B) is uncontrollable iff some left eigenvector v~ of A has v~^T B = 0; (A, C) is
unobservable iff some right eigenvector v^ has C v^ = 0 (7.4.1). Numerically a product is
never exactly zero, so each eigenvalue gets a margin

    c_i = |v~_i^T B| / (|v~_i| |B|),      o_i = |C v^_i| / (|C| |v^_i|)      (2-norms)

and a mode counts as uncontrollable (unobservable) when its margin is below ``tol``. The
margins are scale-free (they do not change when B or C is multiplied by a constant) and
equal the sine-like measure of how far the mode is from the input (output) directions; the
smallest one names the least controllable (observable) mode. Repeated eigenvalues: the test
is applied to an orthonormal basis of each eigenspace (eigenvalues within ``cluster_rtol``
of each other are grouped; the basis is the numerical null space of A - lambda I, so a
defective eigenvalue contributes only its true eigenvectors), using the smallest singular
value of V^H B over the eigenspace, so a degenerate pair cannot hide an uncontrollable
combination.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InfeasibleController, InputError

DEFAULT_TOL = 1e-8


@dataclass
class PBHResult:
    """Per eigenvalue margins of the PBH tests and the verdicts."""

    eigenvalues: np.ndarray
    controllability_margin: np.ndarray
    observability_margin: np.ndarray
    tol: float
    state_names: list

    @property
    def controllable(self) -> bool:
        return bool(np.all(self.controllability_margin > self.tol))

    @property
    def observable(self) -> bool:
        return bool(np.all(self.observability_margin > self.tol))

    def least(self, which: str) -> dict:
        m = self.controllability_margin if which == "controllable" else self.observability_margin
        i = int(np.argmin(m))
        lam = self.eigenvalues[i]
        return {"margin": float(m[i]), "eigenvalue": [float(lam.real), float(lam.imag)],
                "frequency_hz": float(abs(lam) / (2 * np.pi))}

    def as_dict(self) -> dict:
        return {"controllable": self.controllable, "observable": self.observable, "tol": self.tol,
                "least_controllable": self.least("controllable"),
                "least_observable": self.least("observable"),
                "min_controllability_margin": float(self.controllability_margin.min()),
                "min_observability_margin": float(self.observability_margin.min())}


def _eigenspaces(lam: np.ndarray, cluster_rtol: float):
    """Groups of indices of eigenvalues within cluster_rtol (relative to max(1, |lam|))."""
    order = np.argsort(lam.real + 1e-3 * lam.imag)
    groups, used = [], np.zeros(len(lam), bool)
    for i in order:
        if used[i]:
            continue
        close = np.abs(lam - lam[i]) <= cluster_rtol * max(1.0, abs(lam[i]))
        idx = np.flatnonzero(close & ~used)
        used[idx] = True
        groups.append(idx)
    return groups


def _eigenspace_basis(S: np.ndarray, *, left: bool, tol: float, size: int) -> np.ndarray:
    """Orthonormal basis of the (left) null space of S = A - lambda I for a cluster of
    ``size`` eigenvalues: the singular vectors of S with singular value <= ``tol`` (at least
    one, at most ``size``). A defective eigenvalue (a Jordan block) has fewer eigenvectors
    than its multiplicity; its rounded eigenvectors are nearly parallel and their span would
    contain directions that are not eigenvectors, so the basis is taken from S itself."""
    U, sv, Vh = np.linalg.svd(S)
    k = int(np.clip(np.count_nonzero(sv <= tol), 1, size))
    return U[:, -k:] if left else Vh[-k:].conj().T


def _margins(A: np.ndarray, M: np.ndarray, *, left: bool, cluster_rtol: float) -> tuple:
    import scipy.linalg as sla
    lam, VL, VR = sla.eig(A, left=True, right=True)
    V = VL if left else VR
    nM = np.linalg.norm(M, 2)
    out = np.empty(len(lam))
    scale = max(1.0, float(np.linalg.norm(A, 2)))
    for g in _eigenspaces(lam, cluster_rtol):
        if len(g) == 1:
            Q = V[:, g] / np.linalg.norm(V[:, g])
        else:
            Q = _eigenspace_basis(A - lam[g].mean() * np.eye(A.shape[0]), left=left,
                                  tol=cluster_rtol * scale, size=len(g))
        prod = Q.conj().T @ M if left else M @ Q
        sv = np.linalg.svd(prod, compute_uv=False)
        smin = sv[-1] if len(sv) >= Q.shape[1] else 0.0
        out[g] = smin / nM if nM > 0 else 0.0
    return lam, out


def pbh(A, B, C, *, tol: float = DEFAULT_TOL, cluster_rtol: float = 1e-8,
        state_names=None) -> PBHResult:
    """PBH controllability and observability of (A, B, C) (eq. 5.71).

    Parameters
    ----------
    tol : float
        A mode with margin <= tol is uncontrollable (unobservable). Default 1e-8: about
        1e8 times the double-precision unit roundoff, well above the rounding noise of the
        eigenvectors of a matrix with well-separated eigenvalues, far below the margins of
        the deployed systems (>= 1e-4, docs/guides/control.md).
    """
    A = np.asarray(A, dtype=float)
    B = np.atleast_2d(np.asarray(B, dtype=float))
    C = np.atleast_2d(np.asarray(C, dtype=float))
    n = A.shape[0]
    if A.shape != (n, n) or B.shape[0] != n or C.shape[1] != n:
        raise InputError(f"PBH: expected A (n, n), B (n, m), C (p, n), found {A.shape}, {B.shape}, {C.shape}")
    if not (0 < tol < 1):
        raise InputError(f"PBH tolerance: expected 0 < tol < 1, found {tol!r}")
    lam, c = _margins(A, B, left=True, cluster_rtol=cluster_rtol)
    lam2, o = _margins(A, C, left=False, cluster_rtol=cluster_rtol)
    # the two eig calls return the same eigenvalue order (same routine, same matrix)
    return PBHResult(eigenvalues=lam, controllability_margin=c, observability_margin=o, tol=tol,
                     state_names=list(state_names) if state_names is not None else [])


def pbh_ss(sys, *, tol: float = DEFAULT_TOL) -> PBHResult:
    """:func:`pbh` of a python-control ``StateSpace``."""
    return pbh(sys.A, sys.B, sys.C, tol=tol, state_names=list(sys.state_labels))


def require_stabilizable_detectable(A, B2, C2, *, alpha: float = 0.0, tol: float = DEFAULT_TOL,
                                    state_names=None) -> None:
    """Refuse a plant that no output feedback u = K(s) y can stabilise with all poles left of
    -alpha_1: a mode with Re(lambda) >= -alpha_1 that is uncontrollable from u (PBH margin of
    (A, B2) <= ``tol``) or unobservable from y (margin of (A, C2) <= ``tol``).

    Raises
    ------
    InfeasibleController
        naming the mode (eigenvalue, the state with the largest eigenvector component) and
        its margin.
    """
    import scipy.linalg as sla
    res = pbh(A, B2, C2, tol=tol)
    _, VR = sla.eig(np.asarray(A, dtype=float))
    names = list(state_names) if state_names is not None else [f"x{i + 1}" for i in range(len(VR))]
    bad = res.eigenvalues.real >= -alpha
    for what, margin, pair in (("stabilisable", res.controllability_margin, "(A, B2)"),
                               ("detectable", res.observability_margin, "(A, C2)")):
        hit = np.flatnonzero(bad & (margin <= tol))
        if hit.size:
            i = int(hit[0])
            lam = res.eigenvalues[i]
            state = names[int(np.argmax(np.abs(VR[:, i])))]
            raise InfeasibleController(
                f"plant: expected {pair} {what}{f' with alpha_1 = {alpha:g}' if alpha else ''}, "
                f"found the mode at lambda = {lam.real:.6g}{lam.imag:+.6g}j (mostly state "
                f"{state!r}) {'uncontrollable from u' if what == 'stabilisable' else 'unobservable from y'} "
                f"(PBH margin {margin[i]:.2g} <= {tol:g})")
