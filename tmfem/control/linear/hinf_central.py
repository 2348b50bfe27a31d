"""The central (minimum-entropy) H-infinity controller at gamma = (1 + tol) gamma_opt.

With the constant weights of 7.4 the optimum of eqs. 5.63-5.67 is the degenerate gamma_opt =
||D11|| = W_e (docs/guides/control.md): a whole family of controllers attains it and an LMI solver
returns one of them, solver-dependent. This module picks one member by a stated secondary
objective, independent of any solver:

* **gamma**: gamma_opt from the Riccati test of the eliminated LMIs by a bisection that moves
  down only where the central controller at that level was built and its closed loop with
  the alpha-shifted plant verified (:func:`verified_gamma`,
  :func:`tmfem.control.linear.hinf_riccati.minimize_gamma`: the optimum of eq. 5.65 for the
  alpha-shifted plant A + alpha_1 I), then gamma = (1 + ``tol``) gamma_opt.
* **the controller**: the *central* controller at that gamma, i.e. the member Q = 0 of the
  parametrisation of all gamma-suboptimal controllers K = F_l(M_inf, Q), ||Q||_inf < gamma,
  of Glover & Doyle (Systems Control Lett. 11 (1988) 167-172), for the alpha-shifted plant,
  shifted back (A_k - alpha_1 I, as in :func:`tmfem.control.linear.hinf_lmi.hinf_lmi`). For D11 = 0 it
  is the unique controller that minimises the entropy

      I(T, gamma) = -(gamma^2 / 2 pi) int ln |det(I - gamma^-2 T(jw)^H T(jw))| dw

  of the closed loop among all gamma-suboptimal ones (Mustafa & Glover, Minimum Entropy
  H-infinity Control, LNCIS 146, 1990, ch. 5): an upper bound of ||T||_2^2 that tends to it
  as gamma -> inf, the Bernstein-Haddad auxiliary cost of the mixed H2/H-infinity problem
  with equal channels (Doyle, Zhou, Glover & Bodenheimer, IEEE TAC 39 (1994) 1575-1587).
  With D11 != 0 (here the reference feedthrough W_e, which no controller changes) the
  integral diverges and the central controller is defined by the loop-shifted problem of
  Glover & Doyle's general formulas; it is still unique at a given gamma.
* **computation**: SLICOT SB10FD (Glover-Doyle formulas with the normalisation of SB10PD;
  two Riccati equations of order n) through slycot, 0.01-0.05 s at the 50 states of 2-3.

The central controller is an observer: its state is the worst-case estimate x_hat of the
plant state in the plant's own coordinates (x_k = x is an invariant subspace of the closed
loop; tested), which fixes its initial state at a switch to the measured state perturbation
(:class:`tmfem.control.deployment.switching.SwitchingController`, ``start="estimate"``).
"""
from __future__ import annotations

import logging
import time

import numpy as np

from tmfem.control.linear.verification import HinfDesign, check_loop, closed_loop, controller_ss, verify
from tmfem.control.linear.hinf_riccati import GammaIteration, minimize_gamma
from tmfem.control.linear.lmi import SolverReport
from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)

#: default relative tolerance on the optimal level: gamma = (1 + TOL) gamma_opt
TOL = 1e-2


def central_matrices(plant: GeneralizedPlant, gamma: float, *, alpha: float = 0.0) -> tuple:
    """(A_k, B_k, C_k, D_k) of the central controller at ``gamma`` for the plant shifted by
    alpha_1 (SLICOT SB10FD), shifted back: A_k - alpha_1 I.

    Raises
    ------
    InfeasibleController
        SB10FD refuses (gamma below the optimum, or the Riccati equations of the shifted
        plant have no admissible solution).
    """
    import slycot
    P = plant
    n, nw, nu, np_, ny = (P.sizes[k] for k in ("n", "nw", "nu", "np", "ny"))
    B = np.hstack([P.B1, P.B2])
    C = np.vstack([P.C1, P.C2])
    D = np.block([[P.D11, P.D12], [P.D21, P.D22]])
    try:
        Ak, Bk, Ck, Dk, _ = slycot.sb10fd(n, nw + nu, np_ + ny, nu, ny, gamma,
                                           P.A + alpha * np.eye(n), B, C, D)
    except Exception as exc:            # slycot raises its own error types
        raise InfeasibleController(f"central H-infinity controller (SLICOT SB10FD) at gamma = "
                                   f"{gamma:.6g}, alpha_1 = {alpha:g}: expected a controller, "
                                   f"found the error: {exc}") from None
    return np.asarray(Ak) - alpha * np.eye(n), np.asarray(Bk), np.asarray(Ck), np.asarray(Dk)


def hinf_central(plant: GeneralizedPlant, *, alpha: float = 0.0, tol: float = TOL,
                 rtol: float = 1e-6, verify_rtol: float = 1e-3, operating_point=None) -> HinfDesign:
    """The central H-infinity controller at gamma = (1 + ``tol``) gamma_opt with
    alpha-stability (module docstring), verified on the closed loop (poles left of
    -alpha_1, ``control.norm(T_pw, 'inf') <= gamma``).

    Parameters
    ----------
    plant : GeneralizedPlant
        Eq. 5.62, regular (D12 full column rank, D21 full row rank), D22 = 0.
    alpha : float
        alpha_1 >= 0 (7.3).
    tol : float
        > 0: the level above the optimum, gamma = (1 + tol) gamma_opt.
    rtol : float
        Relative bracket of the verified bisection for gamma_opt (:func:`verified_gamma`).

    Raises
    ------
    InputError
        alpha < 0, tol <= 0, D22 != 0 or a singular plant (D12, D21 rank-deficient).
    InfeasibleController
        No admissible controller, or the closed-loop checks fail.
    """
    if not (np.isfinite(alpha) and alpha >= 0):
        raise InputError(f"alpha_1: expected a finite value >= 0, found {alpha!r}")
    if not (np.isfinite(tol) and tol > 0):
        raise InputError(f"tol: expected gamma = (1 + tol) gamma_opt with tol > 0, found {tol!r}")
    if np.any(plant.D22 != 0):
        raise InputError(f"generalised plant: expected D22 = 0 (7.3), found max |D22| = "
                         f"{np.max(np.abs(plant.D22)):.3g}")
    t0 = time.perf_counter()
    Ps, _ = plant.scaled()
    it = verified_gamma(Ps, alpha=alpha, rtol=rtol)
    g_opt = it.gamma
    gamma = (1 + tol) * g_opt
    Ak, Bk, Ck, Dk = central_matrices(plant, gamma, alpha=alpha)
    dt = time.perf_counter() - t0
    K = controller_ss(plant, Ak, Bk, Ck, Dk)
    T, nrm, re = verify(plant, K, gamma=gamma, alpha=alpha, rtol=verify_rtol)
    rep = SolverReport(solver="ARE + SB10FD", status=f"gamma_opt by verified Riccati bisection "
                       f"({it.steps} steps, certified lower bound {it.lower:.6g}), central "
                       f"controller at (1 + {tol:g}) gamma_opt",
                       solve_time_s=dt, n_variables=0, lmi_sizes={}, iterations=it.steps)
    log.info("central H-infinity controller: gamma_opt %.8g, gamma %.6g, ||T|| %.8g, max Re %.4g, "
             "%.2f s", g_opt, gamma, nrm, re, dt)
    return HinfDesign(controller=K, gamma=gamma, alpha=float(alpha), closed_loop=T,
                      closed_loop_norm=nrm, closed_loop_max_real_part=re, solver=rep,
                      plant=plant, kind="output feedback (central, minimum entropy)",
                      operating_point=dict(operating_point or {}), gamma_lmi=g_opt,
                      gamma_lower=it.lower, info={"unknown_levels": it.unknown})


def verified_gamma(plant: GeneralizedPlant, *, alpha: float = 0.0, rtol: float = 1e-6,
                   check_rtol: float = 1e-6) -> GammaIteration:
    """Optimal level of the alpha-shifted plant by the Riccati bisection whose every step
    down is verified (:func:`tmfem.control.linear.hinf_riccati.minimize_gamma`): the central
    controller at that level (:func:`central_matrices`, unshifted) in closed loop with the
    shifted plant A + alpha_1 I must be stable with ||T_pw||_inf <= gamma (1 + check_rtol).
    ``evidence`` of the result is (controller, closed loop, norm) of the shifted problem."""
    Pa = plant.shifted(alpha)

    def certify(gamma):
        try:
            K = controller_ss(Pa, *central_matrices(Pa, gamma))
            T = closed_loop(Pa, K)
            nrm, _ = check_loop(T, gamma=gamma, alpha=0.0, rtol=check_rtol, sweep=False,
                                what=f"central controller at gamma = {gamma:.8g}")
        except InfeasibleController as exc:
            return False, None, str(exc)
        return True, (K, T, nrm), ""
    return minimize_gamma(plant, alpha=alpha, certify=certify, rtol=rtol)


def entropy(T, gamma: float, *, w_min: float = 1e-4, w_max: float = 1e6, n: int = 4000) -> float:
    """Entropy I(T, gamma) of a stable, strictly proper ``StateSpace`` T with ||T||_inf <
    gamma (module docstring), by the trapezoidal rule on a logarithmic frequency grid
    [w_min, w_max] rad/s (the integrand is even in w and decays as |T|^2 ~ w^-2)."""
    if np.any(np.abs(np.asarray(T.D)) > 0):
        raise InputError("entropy: expected a strictly proper closed loop (D = 0), found "
                         f"max |D| = {np.max(np.abs(np.asarray(T.D))):.3g} (the integral diverges)")
    w = np.logspace(np.log10(w_min), np.log10(w_max), n)
    H = np.asarray(T(1j * w)).reshape(T.noutputs, T.ninputs, n)
    s = np.linalg.svd(np.moveaxis(H, 2, 0), compute_uv=False)      # (n, min(np, nw))
    if s.max() >= gamma:
        k = int(np.argmax(s.max(axis=1)))
        raise InputError(f"entropy: expected ||T||_inf < gamma = {gamma:.6g}, found "
                         f"{s.max():.6g} at {w[k]:.3g} rad/s")
    f = -np.sum(np.log1p(-(s / gamma) ** 2), axis=1)
    return float(gamma ** 2 / np.pi * np.trapezoid(f, w))
