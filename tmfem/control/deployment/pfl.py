"""Collocated partial feedback linearisation of the control-oriented model (eqs. 5.39-5.41).

With z = [q; eta] (q actuated, eta the unactuated membrane coordinates) eq. 5.27 in block
form is (eq. 5.39)

    [M11 M12; M12^T M22] [q''; eta''] + [F1; F2] + [B1; 0] u = 0,

and eliminating eta'' gives (eqs. 5.40-5.41)

    q'' + F_q* + B_q* u = 0,     M22 eta'' + F2 + M12^T q'' = 0,
    M_q = M11 - M12 M22^-1 M12^T,  F_q* = M_q^-1 (F1 - M12 M22^-1 F2),  B_q* = M_q^-1 B1.

The control law of eq. 5.46 inverts B_q: it must be square and invertible
(:func:`check_input_matrix`). With the rest-length limits of 7.4 (r_min <= u <= |tendon|)
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
    """Condition number of B_q (eq. 5.46 needs B_q^-1).

    Raises
    ------
    SingularInputMatrix
        B_q is not square (as many rest lengths as bar coordinates) or its 2-norm condition
        number exceeds ``cond_limit``.
    """
    B_q = np.asarray(B_q)
    if B_q.ndim != 2 or B_q.shape[0] != B_q.shape[1]:
        raise SingularInputMatrix(f"eq. 5.46{where}: expected a square B_q (as many actuated "
                                  f"tendons as bar coordinates), found shape {B_q.shape}")
    c = float(np.linalg.cond(B_q))
    if not np.isfinite(c) or c > cond_limit:
        raise SingularInputMatrix(f"eq. 5.46{where}: expected an invertible B_q (condition number "
                                  f"<= {cond_limit:g}), found {c:.3g}")
    return c


def bounded_inversion(terms: PFLTerms, v, *, lower, upper,
                      damping: float = 0.0) -> tuple[np.ndarray, bool]:
    """Rest lengths u with B_q u = v (eq. 5.46, ``v`` = the bracket of eq. 5.58) inside the
    limits [lower, upper]; where the exact solution leaves them, the admissible u whose
    acceleration q'' = -F_q* - B_q u is closest to the commanded one in the kinetic-energy
    metric of the bars,

        min_u (B_q u - v)^T M_q (B_q u - v)   subject to  lower <= u <= upper,

    a bounded-variable least-squares problem (scipy ``lsq_linear`` on R B_q u = R v with
    M_q = R^T R). Clipping each rest length instead would leave the other tendons
    compensating a force the clipped one does not give.

    ``damping`` = mu > 0 replaces the inverse by the damped least-squares one (Tikhonov),

        min_u |R (B_q u - v)|^2 + (mu s_1)^2 |u|^2,   s_1 the largest singular value of R B_q,

    u = sum_i s_i / (s_i^2 + mu^2 s_1^2) (U_i^T R v) V_i with R B_q = U S V^T: directions of
    R B_q with s_i >> mu s_1 are inverted as before, weaker ones (which eq. 5.46 amplifies by
    1 / s_i) are not driven beyond gain 1 / (2 mu s_1).

    Returns
    -------
    u : ndarray
    active : bool
        True when the limits changed the solution of eq. 5.46.
    """
    if damping < 0:
        raise InputError(f"inversion damping: expected >= 0, found {damping!r}")
    R = np.linalg.cholesky(0.5 * (terms.M_q + terms.M_q.T)).T if damping else None
    if damping:
        U, s, Vt = np.linalg.svd(R @ terms.B_q)
        lam = damping * s[0]
        u = Vt.T @ (s / (s**2 + lam**2) * (U.T @ (R @ v)))
    else:
        u = np.linalg.solve(terms.B_q, v)
    if np.all(u >= lower) and np.all(u <= upper):
        return u, False
    R = np.linalg.cholesky(0.5 * (terms.M_q + terms.M_q.T)).T if R is None else R
    A, b = R @ terms.B_q, R @ v
    if damping:
        A = np.vstack([A, lam * np.eye(A.shape[1])])
        b = np.concatenate([b, np.zeros(A.shape[1])])
    sol = lsq_linear(A, b, bounds=(lower, upper), method="bvls")
    return np.clip(sol.x, lower, upper), True
