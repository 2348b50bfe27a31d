"""H-infinity synthesis by LMIs with alpha-stability (dissertation 7.3, eqs. 5.62-5.67).

Plant (eq. 5.62, D22 = 0)::

    x' = A x + B1 w + B2 u,   p = C1 x + D11 w + D12 u,   y = C2 x + D21 w

Formulation (see docs/guides/control.md):

* **alpha-stability by a shift.** The LMIs are written for A_a = A + alpha_1 I. A
  controller (A_k', B_k, C_k, D_k) with a closed loop that meets the bounded real lemma
  (eq. 5.64) for the shifted plant gives, with A_k = A_k' - alpha_1 I, a closed loop of the
  original plant with ``A_cl = A_cl' - alpha_1 I``: its (1,1) block is
  ``A_cl^T X + X A_cl + 2 alpha_1 X < 0`` (the alpha-region LMI of eq. 5.65, same X) and, as
  2 alpha_1 X > 0, the bounded real lemma of the original closed loop holds too. So every
  design satisfies both LMIs of eq. 5.65 with one X; the shift is sufficient (it asks the
  H-infinity bound on the line Re s = -alpha_1), and with alpha_1 = 0 it is eq. 5.65 exactly.
* **Elimination (projection lemma).** The controller variables (A_k_bar, B_k_bar,
  C_k_bar, D_k of eq. 5.66) are eliminated (Gahinet & Apkarian, Int. J. Robust Nonlinear
  Control 4 (1994) 421-448, Thm. 4.3): gamma is minimised over R, S only::

      [N_R 0; 0 I]^T [[A_a R + R A_a^T, R C1^T, B1], [C1 R, -g I, D11], [B1^T, D11^T, -g I]] [N_R 0; 0 I] < 0
      [N_S 0; 0 I]^T [[A_a^T S + S A_a, S B1, C1^T], [B1^T S, -g I, D11^T], [C1, D11, -g I]] [N_S 0; 0 I] < 0
      [[R, I], [I, S]] >= 0

  with N_R, N_S bases of the null spaces of [B2^T, D12^T] and [C2, D21]: n(n+1) + 1 scalar
  variables instead of the ~2 n^2 + n (n_y + n_u) + n_u n_y + n(n+1) of eq. 5.65.
* **Controller recovery (eq. 5.67).** M N^T = I - R S from the SVD of I - R S (M = U
  Sigma^(1/2), N = V Sigma^(1/2): both factors carry the square root of its condition
  number); the closed-loop Lyapunov matrix X = [[S, N], [N^T, -N^T R M^-T]] (X Pi_1 = Pi_2);
  then the bounded real lemma is affine in Theta = [[A_k, B_k], [C_k, D_k]] and one solution
  is the explicit formula of Skelton, Iwasaki & Grigoriadis (A Unified Algebraic Approach to
  Linear Control Design, 1998, Thm. 2.3.12) with L = 0. If I - R S is ill conditioned
  (cond > ``max_cond``) the LMIs are re-solved at gamma (1 + ``gamma_relax``) maximising
  the margin of [[R, I], [I, S]] (bounded R, S), which moves R away from S^-1.

All results are verified on the assembled closed loop (poles, ``control.norm(..., 'inf')``).

The gamma minimisation depends on the plant and the options only, not on the level of the
recovery: the last :data:`STAGE1_MEMO_SIZE` results are kept in memory, so the back-off
levels of :func:`tmfem.control.linear.hinf_synthesis.hinfsyn`'s LMI route and a
:func:`hinf_gamma` of the same plant solve the SDP once (each caller gets its own copy).
"""
from __future__ import annotations

import copy
import logging

import numpy as np

from tmfem.cache import MemoryMemo
from tmfem.control.linear.verification import (HinfDesign, check_loop, controller_ss,
                                              verify)
from tmfem.control.linear.hinf_central import verified_gamma
from tmfem.control.linear.hinf_riccati import strict_point
from tmfem.control.linear.lmi import (SolverReport, max_eig, null_basis, projection_solution, solve,
                                      sym)
from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tmfem.control.linear.pbh import require_stabilizable_detectable
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


# ---------------------------------------------------------------------------- LMIs
def _elimination_problem(P: GeneralizedPlant, alpha: float, eps: float, *, gamma_fixed=None,
                         bound=None, regularization: float = 0.0, coupling_weight: float = 1.0):
    """cvxpy problem of the eliminated H-infinity LMIs in (R, S, gamma) for A + alpha I."""
    import cvxpy as cp
    n = P.A.shape[0]
    Aa = P.A + alpha * np.eye(n)
    NR, NS, Bw, Cp, _ = _elimination_bases(P)
    R = cp.Variable((n, n), symmetric=True)
    S = cp.Variable((n, n), symmetric=True)
    g = cp.Variable() if gamma_fixed is None else gamma_fixed
    # re-solve at a fixed gamma: maximise a common margin t of the three LMIs with tr R + tr S <= bound
    # (an interior point: [[R, I], [I, S]] >= t I keeps I - R S away from singular)
    t = cp.Variable() if gamma_fixed is not None else None
    marg = eps if t is None else t
    cons, sizes = [], {}
    B1c, D11w = P.B1 @ Bw, P.D11 @ Bw                         # w -> Bw w_c
    C1c, D11p = Cp.T @ P.C1, Cp.T @ P.D11                     # p_c = Cp^T p
    rw, rp = Bw.shape[1], Cp.shape[1]
    if NR.shape[1] > 0:
        NRx, NRp = NR[:n], NR[n:]
        # [N_R 0; 0 I]^T H_R [N_R 0; 0 I], H_R = [[A R + R A^T, R C1^T, B1], [C1 R, -g, D11], [B1^T, D11^T, -g]]
        T = NRx.T @ (Aa @ R) @ NRx + NRp.T @ (P.C1 @ R) @ NRx
        b11 = T + T.T - g * (NRp.T @ NRp)
        b12 = NRx.T @ B1c + NRp.T @ D11w
        L1 = cp.bmat([[b11, b12], [b12.T, -g * np.eye(rw)]]) if rw else b11
        k = NR.shape[1] + rw
        cons.append(sym(L1) << -marg * np.eye(k))
        sizes["primal (N_R)"] = k
    if NS.shape[1] > 0:
        NSx, NSw = NS[:n], NS[n:]
        T = NSx.T @ (S @ Aa) @ NSx + NSw.T @ (P.B1.T @ S) @ NSx
        b11 = T + T.T - g * (NSw.T @ NSw)
        b12 = NSx.T @ C1c.T + NSw.T @ D11p.T
        L2 = cp.bmat([[b11, b12], [b12.T, -g * np.eye(rp)]]) if rp else b11
        k = NS.shape[1] + rp
        cons.append(sym(L2) << -marg * np.eye(k))
        sizes["dual (N_S)"] = k
    cons.append(sym(cp.bmat([[R, np.eye(n)], [np.eye(n), S]])) >> coupling_weight * marg * np.eye(2 * n))
    if t is not None:
        cons.append(cp.trace(R) + cp.trace(S) <= bound)
    sizes["coupling [R I; I S]"] = 2 * n
    # gamma plus a small trace penalty: with B1 = 0 (Fig. 7.1: w enters through y and p only)
    # S is unbounded in the dual LMI; the penalty picks a bounded, well-scaled point
    obj = (cp.Minimize(g + regularization * (cp.trace(R) + cp.trace(S)) / (2 * n))
           if gamma_fixed is None else cp.Maximize(t))
    return cp.Problem(obj, cons), R, S, g, sizes, (NR, NS)


def _elimination_bases(P: GeneralizedPlant):
    """N_R = ker [B2^T, D12^T], N_S = ker [C2, D21] and the channel compressions Bw, Cp
    (orthonormal bases of the ranges of [B1; D11]^T and [C1, D11]): w enters the primal LMI
    only through [B1; D11], p the dual one only through [C1, D11], so an orthogonal
    congruence splits off the other directions as -g I blocks (exact, they hold for any
    g > 0). Returns (N_R, N_S, Bw, Cp, LMI sizes)."""
    NR = null_basis(np.hstack([P.B2.T, P.D12.T]))           # (n + np) x k_R
    NS = null_basis(np.hstack([P.C2, P.D21]))               # (n + nw) x k_S
    Bw = _range_basis(np.vstack([P.B1, P.D11]))               # nw x r_w
    Cp = _range_basis(np.hstack([P.C1, P.D11]).T)             # np x r_p
    sizes = {}
    if NR.shape[1]:
        sizes["primal (N_R)"] = NR.shape[1] + Bw.shape[1]
    if NS.shape[1]:
        sizes["dual (N_S)"] = NS.shape[1] + Cp.shape[1]
    sizes["coupling [R I; I S]"] = 2 * P.A.shape[0]
    return NR, NS, Bw, Cp, sizes


def _balance_RS(P: GeneralizedPlant, R, S):
    """Plant in coordinates x = T x_b with T^-1 R T^-T = T^T S T = Sigma (diagonal), and
    the transformed R, S. Returns (P unchanged, R, S) when R or S is not positive definite."""
    try:
        Lr = np.linalg.cholesky((R + R.T) / 2)
        Ls = np.linalg.cholesky((S + S.T) / 2)
    except np.linalg.LinAlgError:
        return P, R, S
    U, sig, Vt = np.linalg.svd(Ls.T @ Lr)
    T = Lr @ Vt.T / np.sqrt(sig)[None, :]
    Ti = (np.sqrt(sig)[:, None] * Vt) @ np.linalg.inv(Lr)
    Pb = GeneralizedPlant(A=Ti @ P.A @ T, B1=Ti @ P.B1, B2=Ti @ P.B2, C1=P.C1 @ T, C2=P.C2 @ T,
                          D11=P.D11, D12=P.D12, D21=P.D21, D22=P.D22, state_names=P.state_names,
                          w_names=P.w_names, u_names=P.u_names, p_names=P.p_names,
                          y_names=P.y_names)
    return Pb, np.diag(sig), np.diag(sig)


def _range_basis(M: np.ndarray, *, rtol: float = 1e-12) -> np.ndarray:
    """Orthonormal basis (columns) of the row space of M (right singular vectors)."""
    if M.size == 0:
        return np.zeros((M.shape[1], 0))
    _, sv, Vt = np.linalg.svd(M, full_matrices=False)
    r = int(np.sum(sv > rtol * max(sv[0], 1e-300)))
    return Vt[:r].T


def _lmi_residuals(P, alpha, R, S, g, eps, NR, NS) -> dict:
    n = P.A.shape[0]
    Aa = P.A + alpha * np.eye(n)
    res = {}
    if NR.shape[1]:
        H = np.block([[Aa @ R + R @ Aa.T, R @ P.C1.T, P.B1],
                      [P.C1 @ R, -g * np.eye(P.C1.shape[0]), P.D11],
                      [P.B1.T, P.D11.T, -g * np.eye(P.B1.shape[1])]])
        W = np.zeros((H.shape[0], NR.shape[1] + P.B1.shape[1]))
        W[: NR.shape[0], : NR.shape[1]] = NR
        W[NR.shape[0]:, NR.shape[1]:] = np.eye(P.B1.shape[1])
        res["primal (N_R)"] = max_eig(W.T @ H @ W) + eps
    if NS.shape[1]:
        H = np.block([[Aa.T @ S + S @ Aa, S @ P.B1, P.C1.T],
                      [P.B1.T @ S, -g * np.eye(P.B1.shape[1]), P.D11.T],
                      [P.C1, P.D11, -g * np.eye(P.C1.shape[0])]])
        W = np.zeros((H.shape[0], NS.shape[1] + P.C1.shape[0]))
        W[: NS.shape[0], : NS.shape[1]] = NS
        W[NS.shape[0]:, NS.shape[1]:] = np.eye(P.C1.shape[0])
        res["dual (N_S)"] = max_eig(W.T @ H @ W) + eps
    res["coupling [R I; I S]"] = -float(np.linalg.eigvalsh(np.block([[R, np.eye(n)], [np.eye(n), S]]))[0])
    return res


def _controller_from_RS(P: GeneralizedPlant, alpha: float, R, S, gamma: float):
    """Recover (A_k, B_k, C_k, D_k) from R, S (eq. 5.67 / the closed-loop bounded real lemma).

    Returns the controller matrices for the *shifted* plant and cond(I - R S).
    """
    n, nw, nu, np_, ny = (P.sizes[k] for k in ("n", "nw", "nu", "np", "ny"))
    # uniform state scaling x = c x_c balances R and S (R -> R / c^2, S -> c^2 S): same
    # controller, better-conditioned X
    c = (np.linalg.norm(R, 2) / np.linalg.norm(S, 2)) ** 0.25
    R, S = R / c ** 2, S * c ** 2
    P = GeneralizedPlant(A=P.A, B1=P.B1 / c, B2=P.B2 / c, C1=P.C1 * c, C2=P.C2 * c, D11=P.D11,
                         D12=P.D12, D21=P.D21, D22=P.D22, state_names=P.state_names,
                         w_names=P.w_names, u_names=P.u_names, p_names=P.p_names, y_names=P.y_names)
    Aa = P.A + alpha * np.eye(n)
    E = np.eye(n) - R @ S
    U, sv, Vt = np.linalg.svd(E)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf
    M = U * np.sqrt(sv)
    N = Vt.T * np.sqrt(sv)                                      # M N^T = I - R S (eq. 5.67)
    X22 = -N.T @ R @ np.linalg.inv(M).T
    X = np.block([[S, N], [N.T, (X22 + X22.T) / 2]])
    X = (X + X.T) / 2
    # closed loop: A_cl = A0 + Bt Th Ct, etc. (controller order n)
    A0 = np.zeros((2 * n, 2 * n))
    A0[:n, :n] = Aa
    B0 = np.vstack([P.B1, np.zeros((n, nw))])
    C0 = np.hstack([P.C1, np.zeros((np_, n))])
    Bt = np.block([[np.zeros((n, n)), P.B2], [np.eye(n), np.zeros((n, nu))]])
    Ct = np.block([[np.zeros((n, n)), np.eye(n)], [P.C2, np.zeros((ny, n))]])
    D12t = np.hstack([np.zeros((np_, n)), P.D12])
    D21t = np.vstack([np.zeros((n, nw)), P.D21])
    Psi = np.block([[A0.T @ X + X @ A0, X @ B0, C0.T],
                    [B0.T @ X, -gamma * np.eye(nw), P.D11.T],
                    [C0, P.D11, -gamma * np.eye(np_)]])
    Ug = np.vstack([X @ Bt, np.zeros((nw, n + nu)), D12t])      # Gamma (full column rank)
    Vl = np.hstack([Ct, D21t, np.zeros((n + ny, np_))])         # Lambda (full row rank)
    Th, lam = projection_solution(Psi, Ug, Vl)
    if Th is None:
        return (None, None, None, None), cond, lam
    Ak, Bk = Th[:n, :n], Th[:n, n:]
    Ck, Dk = Th[n:, :n], Th[n:, n:]
    return (Ak, Bk, Ck, Dk), cond, lam


def _solve_stage1(plant, *, alpha, solver, eps, regularization, scale, residual_tol):
    """Stage 1 of :func:`hinf_lmi`: minimise gamma over the eliminated LMIs (eq. 5.65 form)."""
    Ps, t = plant.scaled() if scale else (plant, np.ones(plant.A.shape[0]))
    if solver.upper() == "ARE":
        NR, NS, _, _, sizes = _elimination_bases(Ps)
        it = verified_gamma(Ps, alpha=alpha)
        n = Ps.A.shape[0]
        rep = SolverReport(solver="ARE", status=f"optimal (verified Riccati bisection, {it.steps} "
                           f"steps, certified lower bound {it.lower:.8g})",
                           solve_time_s=it.time_s, n_variables=n * (n + 1) + 1, lmi_sizes=sizes,
                           iterations=it.steps)
        return it.gamma, rep, (Ps, None, None, sizes, NR, NS, max(1.0, it.gamma))
    prob, R, S, g, sizes, (NR, NS) = _elimination_problem(Ps, alpha, eps, regularization=regularization)
    rep = solve(prob, solver=solver, what="H-infinity LMIs (eliminated, eq. 5.65)",
                lmi_sizes=sizes, accept_inaccurate=True)
    g_opt = float(g.value)
    Rv, Sv = R.value, S.value
    rep.residuals = _lmi_residuals(Ps, alpha, Rv, Sv, g_opt, eps, NR, NS)
    scale_RS = max(1.0, g_opt, np.abs(Rv).max(), np.abs(Sv).max())
    if max(rep.residuals.values()) > residual_tol * scale_RS:
        raise InfeasibleController(f"H-infinity LMIs: expected every LMI satisfied at the "
                                   f"returned point (largest eigenvalue <= {residual_tol:g} x "
                                   f"{scale_RS:.3g}), found residuals {rep.residuals} "
                                   f"(solver status {rep.status!r})")
    return g_opt, rep, (Ps, Rv, Sv, sizes, NR, NS, scale_RS)


#: number of gamma minimisations :func:`_minimize_gamma` keeps (module docstring)
STAGE1_MEMO_SIZE = 8
_stage1_memo = MemoryMemo(STAGE1_MEMO_SIZE)


def _minimize_gamma(plant, **options):
    """:func:`_solve_stage1`, solved once per plant and options among the last
    :data:`STAGE1_MEMO_SIZE` (module docstring); the caller owns the returned copy."""
    return copy.deepcopy(_stage1_memo.get((plant, options), lambda: _solve_stage1(plant, **options)))


def hinf_gamma(plant: GeneralizedPlant, *, alpha: float = 0.0, solver: str = "CLARABEL",
               eps: float = 1e-7, regularization: float = 0.0, scale: bool = True,
               residual_tol: float = 1e-6) -> tuple:
    """The optimal H-infinity level of the eliminated LMIs (no controller): (gamma, SolverReport).

    Same LMIs as :func:`hinf_lmi` (default without the trace penalty, so gamma is the LMI
    optimum itself); a lower bound for every alpha-stabilising controller of the shifted
    problem and, with alpha = 0, the H-infinity optimum.
    """
    if not (np.isfinite(alpha) and alpha >= 0):
        raise InputError(f"alpha_1: expected a finite value >= 0, found {alpha!r}")
    g, rep, _ = _minimize_gamma(plant, alpha=alpha, solver=solver, eps=eps,
                                regularization=regularization, scale=scale, residual_tol=residual_tol)
    return g, rep


def hinf_lmi(plant: GeneralizedPlant, *, alpha: float = 0.0, solver: str = "CLARABEL",
             eps: float = 1e-7, gamma_relax: float = 1e-2, max_cond: float = 1e6,
             scale: bool = True, verify_rtol: float = 1e-3, residual_tol: float = 1e-6,
             trace_budget: float = 2.0, regularization: float = 0.0,
             operating_point=None) -> HinfDesign:
    """Full-order H-infinity output feedback with alpha-stability (eqs. 5.63-5.67).

    Parameters
    ----------
    plant : GeneralizedPlant
        Eq. 5.62 (D22 = 0).
    alpha : float
        alpha_1 >= 0: closed-loop poles with Re < -alpha_1 (7.3).
    solver : {"CLARABEL", "SCS", "ARE"}
        SDP solver (SCS: first order, less accurate; see docs/guides/control.md), or "ARE": the
        same LMIs solved through their Riccati characterisation (regular plants only,
        :mod:`tmfem.control.linear.hinf_riccati`; the LMIs are re-evaluated at its point).
    eps : float
        Strictness margin of the LMIs (F <= -eps I), in the units of the scaled plant.
    gamma_relax : float
        The controller is recovered at gamma = (1 + gamma_relax) gamma_LMI, so that the
        strict inequalities have room (the optimum itself is on the boundary).
    max_cond : float
        Largest accepted cond(I - R S) before the conditioning re-solve.
    regularization : float
        mu of the objective gamma + mu (tr R + tr S) / 2n. Default 0: the optimum itself
        (a penalty trades gamma for the size of R, S; 1e-6 made a controller 4 times
        suboptimal on an ill-conditioned plant). A bounded, well-conditioned R, S comes from
        the conditioning re-solve at the relaxed gamma instead.
    trace_budget : float
        Re-solve bound tr R + tr S <= trace_budget x (its value at the gamma optimum).
    residual_tol : float
        Largest accepted LMI eigenvalue at the solver's point, relative to max(1, gamma,
        |R|, |S|) (the gamma minimisation may end ``optimal_inaccurate`` on the boundary;
        the controller then comes from a strictly feasible re-solve at the relaxed gamma,
        which must end ``optimal``).

    Raises
    ------
    InfeasibleController
        infeasible/inaccurate SDP, failed recovery or failed closed-loop checks.
    """
    if not (np.isfinite(alpha) and alpha >= 0):
        raise InputError(f"alpha_1: expected a finite value >= 0, found {alpha!r}")
    if np.any(plant.D22 != 0):
        raise InputError(f"generalised plant: expected D22 = 0 (7.3), found max |D22| = "
                         f"{np.max(np.abs(plant.D22)):.3g}")
    require_stabilizable_detectable(plant.A, plant.B2, plant.C2, alpha=alpha,
                                    state_names=plant.state_names)
    g_opt, rep, (Ps, Rv, Sv, sizes, NR, NS, scale_RS) = _minimize_gamma(
        plant, alpha=alpha, solver=solver, eps=eps, regularization=regularization, scale=scale,
        residual_tol=residual_tol)
    gamma = g_opt * (1 + gamma_relax)
    if rep.solver == "ARE":
        Rv, Sv, (Ak, Bk, Ck, Dk), cond, lam = _are_point(Ps, alpha, gamma, max_cond)
        rep.residuals = _lmi_residuals(Ps, alpha, Rv, Sv, gamma, 0.0, NR, NS)
        scale_RS = max(1.0, gamma, np.abs(Rv).max(), np.abs(Sv).max())
        if max(rep.residuals.values()) > residual_tol * scale_RS:
            raise InfeasibleController(f"H-infinity LMIs (Riccati point): expected every LMI "
                                       f"satisfied, found residuals {rep.residuals}")
    else:
        (Ak, Bk, Ck, Dk), cond, lam = _controller_from_RS(Ps, alpha, Rv, Sv, gamma)
    if rep.solver != "ARE" and not (np.isfinite(cond) and cond <= max_cond and lam < 0):
        log.info("status %s, cond(I - RS) = %.3g, BRL residual %.3g: re-solving at gamma = "
                 "%.6g for a strictly feasible, better-conditioned R, S", rep.status, cond, lam, gamma)
        # state coordinates in which R and S are equal and diagonal (the balancing of
        # balanced truncation, R and S in the roles of the Gramians): a well-scaled re-solve
        Ps, Rb, Sb = _balance_RS(Ps, Rv, Sv)
        bound = trace_budget * (np.trace(Rb) + np.trace(Sb))
        prob2, R2, S2, _, _, (NR, NS) = _elimination_problem(Ps, alpha, eps, gamma_fixed=gamma,
                                                              bound=bound)
        rep2 = solve(prob2, solver=solver, what="H-infinity LMIs (conditioning re-solve)",
                     lmi_sizes=sizes, accept_inaccurate=True)
        rep.status = f"{rep.status}; re-solve at gamma (1 + {gamma_relax:g}): {rep2.status}"
        rep.solve_time_s += rep2.solve_time_s
        Rv, Sv = R2.value, S2.value
        rep.residuals = _lmi_residuals(Ps, alpha, Rv, Sv, gamma, eps, NR, NS)
        if max(rep.residuals.values()) > residual_tol * scale_RS:
            raise InfeasibleController(f"H-infinity LMIs (re-solve): expected every LMI satisfied, "
                                       f"found residuals {rep.residuals} (status {rep2.status!r})")
        (Ak, Bk, Ck, Dk), cond, lam = _controller_from_RS(Ps, alpha, Rv, Sv, gamma)
    rep.residuals["closed-loop bounded real lemma"] = lam
    if Ak is None:
        raise InfeasibleController(f"controller recovery (eq. 5.67): expected the closed-loop "
                                   f"bounded real lemma solvable for the controller, found it "
                                   f"not negative on the null space (cond(I - RS) = {cond:.3e})")
    if not lam < 0:
        # the LMI in floating point is only a sufficient test: the assembled closed loop decides
        log.info("controller recovery: closed-loop bounded real lemma %.3e >= 0 in floating point "
                 "(cond(I - RS) = %.3e); checking the closed loop itself", lam, cond)
    Ak = Ak - alpha * np.eye(Ak.shape[0])
    K = controller_ss(plant, Ak, Bk, Ck, Dk)
    try:
        T, nrm, re = verify(plant, K, gamma=gamma, alpha=alpha, rtol=verify_rtol)
    except InfeasibleController as exc:
        hint = (" (SCS is a first-order solver: its R, S are too inaccurate for the recovery of "
                "eq. 5.67; use CLARABEL)") if rep.solver == "SCS" else ""
        raise InfeasibleController(f"H-infinity LMIs ({rep.solver}, status {rep.status!r}): the "
                                   f"recovered controller (cond(I - RS) = {cond:.3g}, bounded real "
                                   f"lemma {lam:.3g}) fails its closed-loop check: {exc}{hint}") from None
    return HinfDesign(controller=K, gamma=gamma, alpha=float(alpha), closed_loop=T,
                      closed_loop_norm=nrm, closed_loop_max_real_part=re, solver=rep,
                      plant=plant, kind="output feedback (eliminated LMIs)", R=Rv, S=Sv,
                      cond_I_minus_RS=cond, operating_point=dict(operating_point or {}),
                      gamma_lmi=g_opt)


def _are_point(P, alpha, gamma, max_cond, eps_ladder=(1e-3, 1e-4, 1e-5, 1e-6, 1e-2)):
    """(R, S) from the perturbed Riccati equations (:func:`tmfem.control.linear.hinf_riccati.strict_point`)
    and the recovered controller: the first perturbation of ``eps_ladder`` whose recovery
    gives a negative closed-loop bounded real lemma with cond(I - RS) <= ``max_cond``, else
    the first with a negative one. Returns (R, S, (A_k, B_k, C_k, D_k), cond, lam), R and S
    in the coordinates of ``P``."""
    found, why = [], []
    for e in eps_ladder:
        try:
            R, S, _ = strict_point(P, alpha=alpha, gamma=gamma, eps_rel=e)
        except InfeasibleController as exc:
            why.append(f"eps {e:g}: {exc}")
            continue
        # recovered in the coordinates where R = S is diagonal (the controller, a map y -> u,
        # does not depend on the plant's state coordinates)
        Pb, Rb, Sb = _balance_RS(P, R, S)
        K, cond, lam = _controller_from_RS(Pb, alpha, Rb, Sb, gamma)
        why.append(f"eps {e:g}: cond(I - RS) {cond:.3g}, BRL {lam:.3g}")
        if lam < 0:
            found.append((R, S, K, cond, lam))
            if cond <= max_cond:
                break
    if not found:
        raise InfeasibleController(f"controller recovery (eq. 5.67) from the Riccati points at "
                                   f"gamma = {gamma:.6g}: expected a negative closed-loop bounded "
                                   f"real lemma, found {'; '.join(why)}")
    log.info("Riccati points of the eliminated LMIs: %s", "; ".join(why))
    ok = [f for f in found if f[3] <= max_cond]
    return ok[0] if ok else min(found, key=lambda f: f[3])


def hinf_state_feedback(plant: GeneralizedPlant, *, alpha: float = 0.0, solver: str = "CLARABEL",
                        eps: float = 1e-7, gamma_relax: float = 1e-3, scale: bool = True,
                        verify_rtol: float = 1e-3, operating_point=None) -> HinfDesign:
    """State-feedback H-infinity gain u = K x with alpha-stability (eq. 5.64 with
    A_cl = A + B2 K, B_cl = B1, C_cl = C1 + D12 K, change of variables W = K Y)::

        [[He(A_a Y + B2 W), B1, (C1 Y + D12 W)^T], [B1^T, -g I, D11^T], [C1 Y + D12 W, D11, -g I]] < 0,  Y > 0

    The returned controller is a static ``StateSpace`` from the plant states (named as the
    plant's states) to u; its closed loop uses the plant's (A, B1, B2, C1, D11, D12) only
    (y = x, the measurement channel of the plant is ignored).
    """
    import control
    import cvxpy as cp
    if not (np.isfinite(alpha) and alpha >= 0):
        raise InputError(f"alpha_1: expected a finite value >= 0, found {alpha!r}")
    require_stabilizable_detectable(plant.A, plant.B2, np.eye(plant.A.shape[0]), alpha=alpha,
                                    state_names=plant.state_names)
    Ps, t = plant.scaled() if scale else (plant, np.ones(plant.A.shape[0]))
    n, nw, nu, np_ = (Ps.sizes[k] for k in ("n", "nw", "nu", "np"))
    Aa = Ps.A + alpha * np.eye(n)
    Y = cp.Variable((n, n), symmetric=True)
    W = cp.Variable((nu, n))
    g = cp.Variable()
    AY = Aa @ Y + Ps.B2 @ W
    CY = Ps.C1 @ Y + Ps.D12 @ W
    L = cp.bmat([[AY + AY.T, Ps.B1, CY.T], [Ps.B1.T, -g * np.eye(nw), Ps.D11.T],
                 [CY, Ps.D11, -g * np.eye(np_)]])
    cons = [sym(L) << -eps * np.eye(n + nw + np_), Y >> eps * np.eye(n)]
    prob = cp.Problem(cp.Minimize(g), cons)
    sizes = {"bounded real lemma": n + nw + np_, "Y > 0": n}
    rep = solve(prob, solver=solver, what="H-infinity state-feedback LMI", lmi_sizes=sizes)
    g_opt = float(g.value)
    Yv, Wv = Y.value, W.value
    AYv, CYv = Aa @ Yv + Ps.B2 @ Wv, Ps.C1 @ Yv + Ps.D12 @ Wv
    lam1 = max_eig(np.block([[AYv + AYv.T, Ps.B1, CYv.T], [Ps.B1.T, -g_opt * np.eye(nw), Ps.D11.T],
                             [CYv, Ps.D11, -g_opt * np.eye(np_)]]))
    log.info("state feedback: gamma %.6g, LMI max eigenvalue %.3g", g_opt, lam1)
    # re-solve at a relaxed gamma for an interior point (the optimum is on the boundary)
    gamma = g_opt * (1 + gamma_relax)
    s = cp.Variable()
    prob2 = cp.Problem(cp.Maximize(s), [sym(cp.bmat([[AY + AY.T, Ps.B1, CY.T],
                                                     [Ps.B1.T, -gamma * np.eye(nw), Ps.D11.T],
                                                     [CY, Ps.D11, -gamma * np.eye(np_)]]))
                                        << -s * np.eye(n + nw + np_), Y >> eps * np.eye(n),
                                        Y << 1e3 * max(1.0, np.linalg.norm(Y.value, 2)) * np.eye(n)])
    solve(prob2, solver=solver, what="H-infinity state-feedback LMI (interior point)", lmi_sizes=sizes)
    Kb = W.value @ np.linalg.inv(Y.value)
    Lv = np.block([[(Aa @ Y.value + Ps.B2 @ W.value) + (Aa @ Y.value + Ps.B2 @ W.value).T, Ps.B1,
                    (Ps.C1 @ Y.value + Ps.D12 @ W.value).T],
                   [Ps.B1.T, -gamma * np.eye(nw), Ps.D11.T],
                   [Ps.C1 @ Y.value + Ps.D12 @ W.value, Ps.D11, -gamma * np.eye(np_)]])
    rep.residuals = {"bounded real lemma": max_eig(Lv)}
    Kx = Kb / t[None, :]                                        # x_b = x / t
    Kss = control.ss(np.zeros((0, 0)), np.zeros((0, n)), np.zeros((nu, 0)), Kx,
                     inputs=list(plant.state_names), outputs=list(plant.u_names), name="K_sf")
    Acl = plant.A + plant.B2 @ Kx
    T = control.ss(Acl, plant.B1, plant.C1 + plant.D12 @ Kx, plant.D11,
                   inputs=list(plant.w_names), outputs=list(plant.p_names), name="T_pw")
    nrm, re = check_loop(T, gamma=gamma, alpha=alpha, rtol=verify_rtol, what="state feedback")
    return HinfDesign(controller=Kss, gamma=gamma, alpha=float(alpha), closed_loop=T,
                      closed_loop_norm=nrm, closed_loop_max_real_part=re, solver=rep, plant=plant,
                      kind="state feedback", operating_point=dict(operating_point or {}),
                      gamma_lmi=g_opt)
