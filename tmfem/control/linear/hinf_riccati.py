"""The eliminated H-infinity LMIs solved through their Riccati equivalents (regular plants).

For a *regular* plant (D12 full column rank, D21 full row rank) the projection-lemma LMIs of
:mod:`tmfem.control.linear.hinf_lmi` (eq. 5.65 with the controller variables eliminated) have an exact
Riccati characterisation (Gahinet & Apkarian, Int. J. Robust Nonlinear Control 4 (1994)
421-448, sec. 5; Green & Limebeer, Linear Robust Control, 1995, ch. 6 and 8):

* the R-LMI (null space of [B2^T, D12^T]) is the full-information H-infinity condition. It
  is feasible iff ``gamma^2 I > D11^T Pi D11`` (Pi the projection onto ker D12^T) and the
  game Riccati equation

      A^T X + X A + C1^T C1 - (X B + C1^T D) Rm^-1 (B^T X + D^T C1) = 0,
      B = [B1 B2],  D = [D11 D12],  Rm = D^T D - diag(gamma^2 I, 0)

  has a stabilising solution X >= 0; R = gamma X^-1 lies on the boundary of the LMI (the
  bounded real lemma in the gamma-normalised form of eq. 5.64 is the gamma^2 form scaled by
  gamma);
* the S-LMI (null space of [C2, D21]) is the R-LMI of the dual plant (A^T, C1^T, C2^T, B1^T,
  D11^T, D21^T), so S = gamma Y^-1 with Y the dual game solution;
* [[R, I], [I, S]] > 0 is then rho(X Y) < gamma^2.

So the LMI optimum gamma is found by bisection on these tests (two Riccati equations of
order n per step, against an SDP whose interior-point iterations cost O(n^6) for a dense
Schur complement), and a strictly feasible LMI point for a gamma above the optimum comes from
the Riccati equations with C1^T C1 replaced by C1^T C1 + eps I (a strict Riccati inequality:
the LMI holds with margin). The LMIs are evaluated in floating point afterwards
(:func:`tmfem.control.linear.hinf_lmi.hinf_lmi` checks the residuals and recovers the controller by
eq. 5.67), so the certificate does not rest on this equivalence.
"""
from __future__ import annotations

import logging
import time

import numpy as np
import scipy.linalg as sla

from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


def _projector_off(D: np.ndarray) -> np.ndarray:
    """Pi = I - D D^+ (projection onto ker D^T)."""
    if D.shape[1] == 0:
        return np.eye(D.shape[0])
    Q = sla.orth(D)
    return np.eye(D.shape[0]) - Q @ Q.T


def gamma_lower_bound(P) -> float:
    """The inertia bound of the game Riccati equations: gamma > max(||Pi_12 D11||,
    ||D11 Pi_21||) with Pi_12 onto ker D12^T, Pi_21 onto ker D21 (no controller reaches
    below it: the feedthrough w -> p outside the reach of u and y)."""
    a = np.linalg.norm(_projector_off(P.D12) @ P.D11, 2) if P.D11.size else 0.0
    b = np.linalg.norm(P.D11 @ _projector_off(P.D21.T), 2) if P.D11.size else 0.0
    return float(max(a, b))


def game_riccati(A, B1, B2, C1, D11, D12, gamma: float, *, eps: float = 0.0):
    """Stabilising solution X of the full-information game Riccati equation (module
    docstring) with C1^T C1 + eps I, or None when it does not exist or is not >= 0."""
    n, nw = A.shape[0], B1.shape[1]
    B = np.hstack([B1, B2])
    D = np.hstack([D11, D12])
    Rm = D.T @ D
    Rm[:nw, :nw] -= gamma ** 2 * np.eye(nw)
    Q = C1.T @ C1 + eps * np.eye(n)
    try:
        X = sla.solve_continuous_are(A, B, Q, Rm, s=C1.T @ D)
    except (np.linalg.LinAlgError, ValueError):
        return None
    X = (X + X.T) / 2
    if not np.all(np.isfinite(X)):
        return None
    # stabilising: A - B Rm^-1 (B^T X + D^T C1) Hurwitz (scipy checks it through the pencil)
    ev = np.linalg.eigvalsh(X)
    if ev[0] < -1e-9 * max(1.0, abs(ev[-1])):
        return None
    return X


def _solutions(P, alpha: float, gamma: float, eps: float):
    n = P.A.shape[0]
    Aa = P.A + alpha * np.eye(n)
    if gamma <= gamma_lower_bound(P):
        return None, None
    X = game_riccati(Aa, P.B1, P.B2, P.C1, P.D11, P.D12, gamma, eps=eps)
    if X is None:
        return None, None
    Y = game_riccati(Aa.T, P.C1.T, P.C2.T, P.B1.T, P.D11.T, P.D21.T, gamma, eps=eps)
    return X, Y


def feasible(P, alpha: float, gamma: float, *, eps: float = 0.0) -> bool:
    """Whether the eliminated LMIs of the alpha-shifted plant are feasible at ``gamma``
    (the three Riccati conditions of the module docstring)."""
    X, Y = _solutions(P, alpha, gamma, eps)
    if X is None or Y is None:
        return False
    rho = float(np.max(np.abs(np.linalg.eigvals(X @ Y))))
    return rho < gamma ** 2


def _check_regular(P):
    nu, ny = P.B2.shape[1], P.C2.shape[0]
    if np.linalg.matrix_rank(P.D12) < nu or np.linalg.matrix_rank(P.D21) < ny:
        raise InputError(f"Riccati solution of the eliminated LMIs: expected a regular plant "
                         f"(D12 full column rank {nu}, D21 full row rank {ny}), found ranks "
                         f"{np.linalg.matrix_rank(P.D12)} and {np.linalg.matrix_rank(P.D21)}: "
                         "use an SDP solver (CLARABEL)")


def minimise_gamma(P, *, alpha: float, rtol: float = 1e-6, gamma_max: float = 1e8) -> tuple:
    """Smallest gamma with feasible eliminated LMIs (bisection to ``rtol``): (gamma, steps, s).

    Raises
    ------
    InfeasibleController
        No gamma up to ``gamma_max`` (the shifted plant is not stabilisable/detectable).
    """
    _check_regular(P)
    t0 = time.perf_counter()
    lo = gamma_lower_bound(P)
    hi = max(2.0 * lo, 1e-3)
    steps = 0
    while not feasible(P, alpha, hi):
        steps += 1
        lo, hi = hi, 4.0 * hi
        if hi > gamma_max:
            raise InfeasibleController(f"eliminated H-infinity LMIs (Riccati test): expected a "
                                       f"feasible gamma <= {gamma_max:g}, found none (the plant "
                                       f"shifted by alpha_1 = {alpha:g} is not stabilisable "
                                       "or not detectable)")
    while hi - lo > rtol * hi:
        mid = np.sqrt(lo * hi) if lo > 0 else hi / 2
        steps += 1
        if feasible(P, alpha, mid):
            hi = mid
        else:
            lo = mid
    dt = time.perf_counter() - t0
    log.info("eliminated LMIs by Riccati bisection: gamma = %.8g in %d steps, %.2f s", hi, steps, dt)
    return float(hi), steps, dt


def strict_point(P, *, alpha: float, gamma: float, eps_rel: float = 1e-6):
    """(R, S) strictly satisfying the eliminated LMIs at ``gamma`` (above the optimum):
    R = gamma X_eps^-1, S = gamma Y_eps^-1 from the Riccati equations with C1^T C1 + eps I,
    eps = ``eps_rel`` x ||C1^T C1|| (and the dual likewise).

    Raises
    ------
    InfeasibleController
        When the perturbed Riccati equations have no admissible solution or rho(X Y) >=
        gamma^2 (gamma too close to the optimum for this eps).
    """
    _check_regular(P)
    scale = max(np.linalg.norm(P.C1, 2) ** 2, np.linalg.norm(P.B1, 2) ** 2, 1e-12)
    X, Y = _solutions(P, alpha, gamma, eps_rel * scale)
    if X is None or Y is None:
        raise InfeasibleController(f"eliminated LMIs (Riccati): expected stabilising solutions "
                                   f">= 0 at gamma = {gamma:.6g}, found none")
    rho = float(np.max(np.abs(np.linalg.eigvals(X @ Y))))
    if not rho < gamma ** 2:
        raise InfeasibleController(f"eliminated LMIs (Riccati): expected rho(X Y) < gamma^2 = "
                                   f"{gamma ** 2:.6g}, found {rho:.6g}")
    R = gamma * np.linalg.inv(X)
    S = gamma * np.linalg.inv(Y)
    return (R + R.T) / 2, (S + S.T) / 2, rho


def state_feedback_gamma(A, B1, B2, C1, D11, D12, *, eps: float = 1e-8, rtol: float = 1e-6,
                         gamma_max: float = 1e8) -> float:
    """Optimal level of static state feedback u = K x (the state-feedback LMI of
    :func:`tmfem.control.linear.hinf_lmi.hinf_state_feedback`), by bisection on its Riccati test:
    gamma > ||D11|| (the w -> p feedthrough no static gain changes) and the game Riccati
    equation of the module docstring (with C1^T C1 + eps I: modes on the imaginary axis
    that p does not see, such as integrators of a tracking error outside p, leave the
    unperturbed Hamiltonian without a stabilising solution; gamma(eps) decreases to the
    optimum as eps -> 0).

    Raises
    ------
    InfeasibleController
        No gamma up to ``gamma_max`` (not stabilisable).
    """
    if np.linalg.matrix_rank(D12) < D12.shape[1]:
        raise InputError(f"state-feedback Riccati test: expected D12 of full column rank "
                         f"{D12.shape[1]}, found rank {np.linalg.matrix_rank(D12)}")

    def ok(g):
        return (g > np.linalg.norm(D11, 2) and g > np.linalg.norm(_projector_off(D12) @ D11, 2)
                and game_riccati(A, B1, B2, C1, D11, D12, g, eps=eps) is not None)

    lo = float(np.linalg.norm(D11, 2)) if D11.size else 0.0
    hi = max(2.0 * lo, 1e-3)
    while not ok(hi):
        lo, hi = hi, 4.0 * hi
        if hi > gamma_max:
            raise InfeasibleController(f"state-feedback Riccati test: expected a feasible gamma <= "
                                       f"{gamma_max:g}, found none (not stabilisable)")
    while hi - lo > rtol * hi:
        mid = np.sqrt(lo * hi) if lo > 0 else hi / 2
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return float(hi)


def state_feedback_gain(A, B1, B2, C1, D11, D12, gamma: float, *, eps: float = 1e-8) -> np.ndarray:
    """A static gain K (u = K x) meeting the state-feedback LMI at ``gamma`` (above the
    optimum): Y = gamma X^-1 from the game Riccati equation, W from the projection formula
    of :func:`tmfem.control.linear.hinf_lmi._projection_solution` applied to the LMI in W, K = W Y^-1.

    Raises
    ------
    InfeasibleController
        When the Riccati equation has no admissible solution or the LMI in W fails.
    """
    from tmfem.control.linear.hinf_lmi import _projection_solution
    n, nw, npp = A.shape[0], B1.shape[1], C1.shape[0]
    X = game_riccati(A, B1, B2, C1, D11, D12, gamma, eps=eps)
    if X is None:
        raise InfeasibleController(f"state-feedback Riccati test: expected a stabilising solution at "
                                   f"gamma = {gamma:.6g}, found none")
    Y = gamma * np.linalg.inv(X)
    Y = (Y + Y.T) / 2
    Psi = np.block([[A @ Y + Y @ A.T, B1, Y @ C1.T], [B1.T, -gamma * np.eye(nw), D11.T],
                    [C1 @ Y, D11, -gamma * np.eye(npp)]])
    G = np.vstack([B2, np.zeros((nw, B2.shape[1])), D12])
    L = np.hstack([np.eye(n), np.zeros((n, nw + npp))])
    W, lam = _projection_solution(Psi, G, L)
    if W is None or not lam < 0:
        raise InfeasibleController(f"state-feedback LMI at gamma = {gamma:.6g}: expected a gain, found "
                                   f"largest eigenvalue {lam:.3g}")
    return np.linalg.solve(Y, W.T).T
