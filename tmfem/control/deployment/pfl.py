"""Collocated partial feedback linearisation of the control-oriented model (eqs. 5.39-5.41).

With z = [q; eta] (q actuated, eta the unactuated membrane coordinates) eq. 5.27 in block
form is (eq. 5.39)

    [M11 M12; M12^T M22] [q''; eta''] + [F1; F2] + [B1; 0] u = 0,

and eliminating eta'' gives (eqs. 5.40-5.41)

    q'' + F_q* + B_q* u = 0,     M22 eta'' + F2 + M12^T q'' = 0,
    M_q = M11 - M12 M22^-1 M12^T,  F_q* = M_q^-1 (F1 - M12 M22^-1 F2),  B_q* = M_q^-1 B1.

The control law of eq. 5.46 inverts B_q (n_q x n_t): square and invertible for 1-N(D) and
two-stage systems; wide with full row rank (n_t > n_q) for an over-actuated system (M >= 3
stages: 13N tendons for 12N bar coordinates), whose rest lengths giving the commanded
acceleration form an affine space of dimension n_t - n_q, from which the one closest to a
reference u_ref is taken (:func:`exact_inversion`); :func:`check_input_matrix` refuses a
B_q without full row rank. With the rest-length limits of 7.4 (r_min <= u <= |tendon|)
the inverse may lie outside them; :func:`bounded_inversion` then returns the admissible
rest lengths whose acceleration is closest to the commanded one.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import lsq_linear

from tmfem.errors import InputError, SingularInputMatrix

#: condition number of B_q above which eq. 5.46 is refused
COND_LIMIT = 1e10
#: weight of the regularisation toward u_ref of the bounded problem of a wide B_q, relative to
#: the largest singular value of R B_q (:func:`bounded_inversion`)
REFERENCE_WEIGHT = 1e-6


@dataclass
class PFLTerms:
    """M_q, F_q*, B_q* of eq. 5.41 and the membrane blocks M12, M22, F2 of eq. 5.39."""

    M_q: np.ndarray
    F_q: np.ndarray
    B_q: np.ndarray
    M12: np.ndarray
    M22: np.ndarray
    F2: np.ndarray


def partition(M_hat, F_hat, B_hat, *, nq: int) -> PFLTerms:
    """Eqs. 5.39-5.41 from M_hat, F_hat, B_hat (eq. 5.28) with the first nq coordinates
    actuated. B_hat's eta rows are zero for the COM (eq. 5.39); they are not used.
    ``F_hat`` may hold several force vectors as columns (n, k): F_q (and F2) are then
    (nq, k), from the same factorisations."""
    M11, M12, M22 = M_hat[:nq, :nq], M_hat[:nq, nq:], M_hat[nq:, nq:]
    F_hat = np.asarray(F_hat, dtype=float)
    Fc = F_hat.reshape(F_hat.shape[0], -1)
    k = Fc.shape[1]
    F1, F2 = Fc[:nq], Fc[nq:]
    if M22.size:
        X = np.linalg.solve(M22, np.column_stack([M12.T, F2]))
        Mq = M11 - M12 @ X[:, :nq]
        rhs = np.column_stack([F1 - M12 @ X[:, nq:], B_hat[:nq]])
    else:
        Mq = M11
        rhs = np.column_stack([F1, B_hat[:nq]])
    sol = np.linalg.solve(Mq, rhs)
    if F_hat.ndim == 1:
        return PFLTerms(M_q=Mq, F_q=sol[:, 0], B_q=sol[:, 1:], M12=M12, M22=M22, F2=F2[:, 0])
    return PFLTerms(M_q=Mq, F_q=sol[:, :k], B_q=sol[:, k:], M12=M12, M22=M22, F2=F2)


def check_input_matrix(B_q, *, where: str = "", cond_limit: float = COND_LIMIT) -> float:
    """Condition number of B_q (n_q x n_t), the ratio of its largest to its smallest singular
    value: eq. 5.46 needs B_q^-1 (n_t = n_q) or, for an over-actuated system (n_t > n_q), a
    B_q of full row rank n_q (every bar acceleration reachable).

    Raises
    ------
    SingularInputMatrix
        B_q has fewer columns (actuated tendons) than rows (bar coordinates), or its
        condition number exceeds ``cond_limit``.
    """
    B_q = np.asarray(B_q)
    if B_q.ndim != 2 or B_q.shape[0] > B_q.shape[1]:
        raise SingularInputMatrix(f"eq. 5.46{where}: expected a B_q with at least as many actuated "
                                  f"tendons as bar coordinates, found shape {B_q.shape}")
    if B_q.shape[0] == B_q.shape[1]:
        c = float(np.linalg.cond(B_q))
    else:
        s = np.linalg.svd(B_q, compute_uv=False)
        c = float(s[0] / s[-1]) if s[-1] > 0 else np.inf
    if not np.isfinite(c) or c > cond_limit:
        kind = "an invertible" if B_q.shape[0] == B_q.shape[1] else "a full-row-rank"
        raise SingularInputMatrix(f"eq. 5.46{where}: expected {kind} B_q (condition number "
                                  f"<= {cond_limit:g}), found {c:.3g}")
    return c


def exact_inversion(B_q, v, *, u_ref=None) -> np.ndarray:
    """Rest lengths u with B_q u = v (eq. 5.46). Square B_q: u = B_q^-1 v. Wide B_q (full
    row rank): the solution closest to ``u_ref`` (default 0) in the Euclidean norm of the
    rest lengths,

        u = u_ref + B_q^+ (v - B_q u_ref),   B_q^+ = B_q^T (B_q B_q^T)^-1,

    the minimum-norm change (``numpy.linalg.lstsq`` of the underdetermined system)."""
    B_q = np.asarray(B_q)
    if B_q.shape[0] == B_q.shape[1]:
        return np.linalg.solve(B_q, v)
    u_ref = np.zeros(B_q.shape[1]) if u_ref is None else np.asarray(u_ref, dtype=float)
    return u_ref + np.linalg.lstsq(B_q, v - B_q @ u_ref, rcond=None)[0]


def bounded_inversion(terms: PFLTerms, v, *, lower, upper, damping: float = 0.0,
                      u_ref=None) -> tuple[np.ndarray, bool]:
    """Rest lengths u with B_q u = v (eq. 5.46, ``v`` = the bracket of eq. 5.58) inside the
    limits [lower, upper]; where the exact solution (:func:`exact_inversion`) leaves them, the
    admissible u whose acceleration q'' = -F_q* - B_q u is closest to the commanded one in the
    kinetic-energy metric of the bars,

        min_u (B_q u - v)^T M_q (B_q u - v)   subject to  lower <= u <= upper,

    a bounded-variable least-squares problem (scipy ``lsq_linear`` on R B_q u = R v with
    M_q = R^T R). Clipping each rest length instead would leave the other tendons
    compensating a force the clipped one does not give.

    A wide B_q (over-actuated, n_t > n_q) leaves this minimum non-unique (any u + n with
    B_q n = 0 inside the limits); the problem is then regularised toward ``u_ref``,

        min_u |R (B_q u - v)|^2 + eps^2 |u - u_ref|^2,   eps = REFERENCE_WEIGHT * s_1,

    s_1 the largest singular value of R B_q: its solution u_eps is unique, and comparing
    it with any minimiser u* gives |R (B_q u_eps - v)| <= |R (B_q u* - v)| + eps |u* - u_ref|,
    an acceleration at most 1e-6 s_1 |u* - u_ref| further from the commanded one (a relative
    1e-6 when s_1 |u* - u_ref| is of the order of the commanded acceleration).

    ``damping`` = mu > 0 replaces the inverse by the damped least-squares one (Tikhonov),

        min_u |R (B_q u - v)|^2 + (mu s_1)^2 |u - u_ref|^2,

    u = u_ref + sum_i s_i / (s_i^2 + mu^2 s_1^2) (U_i^T R (v - B_q u_ref)) V_i with
    R B_q = U S V^T: directions of R B_q with s_i >> mu s_1 are inverted as before, weaker
    ones (which eq. 5.46 amplifies by 1 / s_i) are not driven beyond gain 1 / (2 mu s_1).
    ``u_ref`` (default 0) acts only on a wide B_q or with ``damping``.

    Returns
    -------
    u : ndarray
    active : bool
        True when the limits changed the solution of eq. 5.46.
    """
    if damping < 0:
        raise InputError(f"inversion damping: expected >= 0, found {damping!r}")
    nq, nt = terms.B_q.shape
    u_ref = np.zeros(nt) if u_ref is None else np.asarray(u_ref, dtype=float)
    R = np.linalg.cholesky(0.5 * (terms.M_q + terms.M_q.T)).T if damping else None
    if damping:
        U, s, Vt = np.linalg.svd(R @ terms.B_q, full_matrices=nq == nt)
        lam = damping * s[0]
        u = Vt.T @ (s / (s**2 + lam**2) * (U.T @ (R @ (v - terms.B_q @ u_ref)))) + u_ref
    else:
        u = exact_inversion(terms.B_q, v, u_ref=u_ref)
    if np.all(u >= lower) and np.all(u <= upper):
        return u, False
    R = np.linalg.cholesky(0.5 * (terms.M_q + terms.M_q.T)).T if R is None else R
    A, b = R @ terms.B_q, R @ v
    if not damping and nt > nq:
        lam = REFERENCE_WEIGHT * np.linalg.norm(A, 2)
    if damping or nt > nq:
        A = np.vstack([A, lam * np.eye(nt)])
        b = np.concatenate([b, lam * u_ref])
    sol = lsq_linear(A, b, bounds=(lower, upper), method="bvls")
    return np.clip(sol.x, lower, upper), True
