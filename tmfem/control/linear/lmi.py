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
