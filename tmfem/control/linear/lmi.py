"""Semidefinite-programme plumbing shared by the LMI syntheses: solver choice, status checks.

cvxpy with Clarabel (interior point; default) or SCS (first order; fallback). An LMI
``F < 0`` is imposed as ``F <= -eps I`` with an explicit margin ``eps``; after the solve
every LMI is re-evaluated in floating point and its largest eigenvalue reported as the
residual, so a solution the solver calls optimal but that violates an LMI is caught.
"""
from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)

SOLVERS = ("CLARABEL", "SCS")


@dataclass
class SolverReport:
    """What the SDP solver did: name, status, time, problem size and LMI residuals.

    ``residuals`` maps each LMI's name to the largest eigenvalue of ``F + eps I`` (``F <=
    -eps I`` holds iff it is <= 0; for ``G >= eps I`` the sign is flipped), evaluated in
    floating point from the returned variables.
    """

    solver: str
    status: str
    solve_time_s: float
    n_variables: int
    lmi_sizes: dict
    residuals: dict = field(default_factory=dict)
    iterations: int | None = None

    def as_dict(self) -> dict:
        return {"solver": self.solver, "status": self.status, "solve_time_s": self.solve_time_s,
                "n_variables": self.n_variables, "lmi_sizes": dict(self.lmi_sizes),
                "residuals": {k: float(v) for k, v in self.residuals.items()},
                "iterations": self.iterations}


def sym(expr):
    """Symmetric part of a cvxpy expression (cvxpy requires exactly symmetric PSD arguments)."""
    return (expr + expr.T) / 2


def solve(problem, *, solver: str, what: str, lmi_sizes: dict, tol: float = 1e-8,
          accept_inaccurate: bool = False) -> SolverReport:
    """Solve a cvxpy problem with ``solver`` and refuse anything but an optimal status.

    ``accept_inaccurate=True`` also accepts ``optimal_inaccurate`` (used for a gamma
    minimisation whose optimum lies on the boundary of the LMI cone; the caller then checks
    the residuals and re-solves a strictly feasible problem before recovering a controller).

    Raises
    ------
    InfeasibleController
        Status infeasible, unbounded, inaccurate or a solver failure.
    """
    import cvxpy as cp
    solver = solver.upper()
    if solver not in SOLVERS:
        raise InputError(f"LMI solver: expected one of {SOLVERS}, found {solver!r}")
    opts = {}
    if solver == "CLARABEL":
        opts = dict(tol_gap_abs=tol, tol_gap_rel=tol, tol_feas=tol, max_iter=200)
    else:
        opts = dict(eps=1e-9, max_iters=100000)
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            # cvxpy's warning of an inaccurate solution: its status is checked (and logged) below
            warnings.filterwarnings("ignore", message="Solution may be inaccurate",
                                    category=UserWarning)
            problem.solve(solver=solver, **opts)
    except cp.error.SolverError as exc:
        raise InfeasibleController(f"{what}: expected the SDP solver {solver} to finish, it "
                                   f"failed: {exc}") from None
    dt = time.perf_counter() - t0
    status = problem.status
    nvar = int(sum(v.size for v in problem.variables()))
    stats = problem.solver_stats
    rep = SolverReport(solver=solver, status=status, solve_time_s=dt, n_variables=nvar,
                       lmi_sizes=lmi_sizes, iterations=getattr(stats, "num_iters", None))
    log.info("%s: %s %s in %.2f s (%d variables, LMIs %s)", what, solver, status, dt, nvar, lmi_sizes)
    ok = (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) if accept_inaccurate else (cp.OPTIMAL,)
    if status not in ok:
        raise InfeasibleController(f"{what}: expected solver status 'optimal', found {status!r} "
                                   f"({solver}, {dt:.1f} s, {nvar} variables); the LMIs are "
                                   "infeasible or the solution is inaccurate")
    return rep


def max_eig(F: np.ndarray) -> float:
    """Largest eigenvalue of the symmetric part of ``F``."""
    F = np.asarray(F, dtype=float)
    return float(np.linalg.eigvalsh((F + F.T) / 2)[-1])


def null_basis(M: np.ndarray, *, rtol: float = 1e-10) -> np.ndarray:
    """Orthonormal basis of the null space of ``M`` (columns); rank by the SVD with
    threshold ``rtol * sigma_max``."""
    import scipy.linalg as sla
    return sla.null_space(np.asarray(M, dtype=float), rcond=rtol)


def projection_solution(Psi, G, L, *, factor: float = 2.0):
    """One solution Theta of  Psi + G Theta L + (G Theta L)^T < 0  (G full column rank, L full
    row rank), by the explicit formula of Skelton, Iwasaki & Grigoriadis (1998, Thm. 2.3.12)
    with the free contraction L = 0:

        Theta = -Rs^-1 G^T Phi L^T (L Phi L^T)^-1,   Phi = (G Rs^-1 G^T - Psi)^-1 > 0.

    The free weight is chosen in the coordinates of a QR factorisation G = Q [G1; 0]:
    Rs^-1 = rho G1^-1 G1^-T, so that G Rs^-1 G^T = rho Q diag(I, 0) Q^T and rho is compared
    with Psi itself (rho = ``factor`` x the largest eigenvalue of the Schur complement of
    Q^T Psi Q on the range of G), not with Psi seen through an ill-conditioned G (a weight
    rho I makes rho G G^T swamp Psi in floating point when G is badly scaled). Returns
    (Theta, max eigenvalue of the LMI); (None, inf) when Psi is not negative definite on the
    null space of G^T (the elimination condition fails in floating point) or L Phi L^T is
    singular in floating point.
    """
    import scipy.linalg as sla
    m = G.shape[1]
    Q, Rg = np.linalg.qr(G, mode="complete")
    G1 = Rg[:m]
    Pt = Q.T @ Psi @ Q
    Pt = (Pt + Pt.T) / 2
    P22 = Pt[m:, m:]
    if P22.size and np.linalg.eigvalsh(P22)[-1] >= 0:
        return None, np.inf
    Z = Pt[:m, :m] - (Pt[:m, m:] @ np.linalg.solve(P22, Pt[m:, :m]) if P22.size else 0.0)
    ez = np.linalg.eigvalsh((Z + Z.T) / 2)
    rho = factor * max(float(ez[-1]), 0.0) + 1e-6 * max(float(np.abs(ez).max()), 1e-300)
    Mt = -Pt.copy()
    Mt[:m, :m] += rho * np.eye(m)
    try:
        Lc = sla.cho_factor(Mt)
    except np.linalg.LinAlgError:
        return None, np.inf
    Lq = L @ Q                                                   # L in the QR coordinates
    PhiLt = sla.cho_solve(Lc, Lq.T)                              # Phi_q L_q^T
    try:
        Th = -rho * sla.solve_triangular(G1, np.linalg.solve(Lq @ PhiLt, PhiLt[:m].T).T)
    except np.linalg.LinAlgError:                                # L Phi L^T singular in floating point
        return None, np.inf
    GTL = G @ Th @ L
    lam = max_eig(Psi + GTL + GTL.T)
    return Th, lam
