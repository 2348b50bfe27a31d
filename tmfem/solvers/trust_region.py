"""Newton's method regularised by a mass-scaled Levenberg-Marquardt trust region on an energy.

For equilibria reached from a singular start (a flat unstressed membrane has no transverse
stiffness; bars pinned at their bases are a mechanism until the tendons pull), each step solves

    (K_T + mu D) du = -r,         D = diag(M) (the lumped mass scale of each dof),

and is accepted when it lowers the energy W (or, on the round-off floor where energy
differences vanish, the residual). The ratio rho = actual / predicted decrease of W
(predicted by the quadratic model -(g du + du K du / 2)) steers mu: rho > 0.75 divides it by 8
(down to 0: pure Newton, quadratic convergence), rho < 0.25 multiplies it by 4; a rejected
step multiplies it by 4 and retries. Converged when |r| <= tol x force scale after a pure
Newton step, or on the round-off floor: a step whose energy change is round-off and which
no longer halves |r| while |r| <= 1e3 tol x force scale (stiff beams and shells put that
floor near tol). The solver knows nothing of tensegrities: it sees a
residual with its tangent, an energy, a dof scale and a convergence scale.

A backend with a nonlinear solver of its own (``backend.solve_equilibrium``: the PETSc
backend's SNES, :mod:`tmfem.solvers.petsc_snes`) solves the problem instead when every
unknown is free (the distributed assembly's numbering).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp

from tmfem.errors import ConvergenceError
from tmfem.solvers.backends import SingularMatrix, get_backend
from tmfem.solvers.newton import free_index, submatrix
from tmfem.solvers.roundoff import FLOOR_FACTOR, floor_hint

log = logging.getLogger(__name__)


@dataclass
class TrustRegionResult:
    """Solution, iterations, residual norms (start included), the mu of every accepted step,
    and the tangent at the solution as ``residual`` returned it (for a modal analysis about
    the equilibrium without assembling it again)."""

    u: np.ndarray
    iterations: int
    residual_history: list
    mu_history: list
    converged: bool = True
    extra: dict = field(default_factory=dict)
    tangent: object = None


def trust_region_newton(residual: Callable, energy: Callable, u0, *, free, scale: np.ndarray,
                        force_scale: Callable, tol: float = 1e-9, max_iter: int = 200,
                        newton_first: bool = False, backend=None, callback: Callable | None = None,
                        describe: Callable | None = None, what: str = "static solve",
                        update: Callable | None = None) -> TrustRegionResult:
    """Minimise the energy to an equilibrium r(u) = 0 on the free dofs (module docstring).

    Parameters
    ----------
    residual : callable
        ``residual(u) -> (r, K)`` on all dofs (for a backend's own solver,
        ``backend.solve_equilibrium``: K distributed and r this rank's rows of it).
    energy : callable
        ``energy(u) -> W`` [J].
    u0 : ndarray
        Start (fixed dofs keep their values).
    free : bool mask
    scale : ndarray (n_free,)
        Positive dof scale D of the regularisation (e.g. the mass diagonal).
    force_scale : callable
        ``force_scale(u) -> float``: converged when |r_free| <= tol * force_scale(u) after a
        pure Newton step (mu = 0) or a step below 1e-9 in every dof.
    newton_first : bool
        Start with mu = 0 (a start near the solution, positive definite tangent).
    callback : callable, optional
        ``callback(iteration, u, rnorm, mu, rho)`` after every accepted step.
    describe : callable, optional
        ``describe(u) -> str``: the state at a failure, for the error message.
    update : callable, optional
        ``update(u, du) -> u_new`` (du on all dofs, zero at the fixed ones) for unknowns that
        are not a vector to add to, e.g. a state with finite rotations composed by the
        exponential map; ``u0`` and the returned ``u`` are then such states.
    """
    be = get_backend(backend)
    free = np.asarray(free, dtype=bool)
    if getattr(be, "solve_equilibrium", None) is not None and free.all():
        # a backend with a nonlinear solver of its own (PETSc's SNES) on a distributed
        # assembly, where every unknown is free
        return TrustRegionResult(**be.solve_equilibrium(
            residual, energy, u0, scale=scale, force_scale=force_scale, tol=tol,
            max_iter=max_iter, newton_first=newton_first, callback=callback, describe=describe,
            what=what, update=update))
    idx = free_index(free, free.size)
    u = np.array(u0, dtype=float, copy=True) if update is None else u0
    Dm = sp.diags(np.asarray(scale, dtype=float))
    r, K = residual(u)
    rn = float(np.linalg.norm(r[free]))
    W = energy(u)
    res_hist, mu_hist = [rn], []
    Kd = np.abs(K.diagonal()[free])
    Md = np.asarray(scale)
    mu_scale = float(np.median(Kd[Kd > 0]) / np.median(Md)) if np.any(Kd > 0) else 1.0
    mu = 0.0 if newton_first else 1e-3 * mu_scale
    it = 0
    converged = floor = False
    for it in range(1, max_iter + 1):
        Kf = submatrix(K, idx)
        g = r[free]
        for _attempt in range(40):
            A = (Kf + mu * Dm) if mu > 0 else Kf
            try:
                du = be.factorize(A)(-g)
            except SingularMatrix:
                du = np.full(g.shape, np.nan)        # regularise harder
            ok = bool(np.all(np.isfinite(du)) and float(g @ du) < 0)
            if ok:
                if update is None:
                    ut = u.copy()
                    ut[free] += du
                else:
                    dfull = np.zeros(free.size)
                    dfull[free] = du
                    ut = update(u, dfull)
                Wt = energy(ut)
                pred = -(float(g @ du) + 0.5 * float(du @ (Kf @ du)))
                actual = W - Wt
                # near the solution energy differences drown in round-off: accept a step
                # that reduces the residual there; the residual and tangent of a trial state
                # are only assembled when the energy does not reject it
                tiny = abs(pred) < 1e-11 * max(abs(W), 1e-30)
                if np.isfinite(Wt) and (actual > 0 or tiny):
                    rt, Kt = residual(ut)
                    rtn = float(np.linalg.norm(rt[free]))
                    if tiny and rtn > 0.5 * rn and rn <= FLOOR_FACTOR * tol * force_scale(u):
                        # the round-off floor: neither the energy nor |r| can fall further;
                        # the last (round-off sized) step is taken and the iteration ends
                        floor, rho = True, 1.0
                        break
                    if (actual > 0 and not tiny) or rtn < rn:
                        rho = actual / pred if pred > 0 and not tiny else 1.0
                        break
            mu = max(4.0 * mu, 1e-8 * mu_scale)
            if mu > 1e12 * mu_scale:
                break
        else:
            ok = False
        if not ok or mu > 1e12 * mu_scale:
            # no step improves the state: accept it if we sit on the round-off floor
            if rn <= FLOOR_FACTOR * tol * force_scale(u):
                converged = True
                break
            raise ConvergenceError(f"{what}: no descent step at iteration {it} (|r| = {rn:.3e} N, "
                                   f"mu = {mu:.3e}); residual history {np.array(res_hist[-6:])} N"
                                   f"{floor_hint(rn, force_scale(u), tol)}")
        mu_used = mu
        u, r, K, W, rn = ut, rt, Kt, Wt, rtn
        if rho > 0.75:
            mu = 0.0 if mu < 1e-10 * mu_scale else mu / 8.0
        elif rho < 0.25:
            mu = max(4.0 * mu, 1e-8 * mu_scale)
        res_hist.append(rn)
        mu_hist.append(mu_used)
        if callback is not None:
            callback(it, u, rn, mu_used, rho)
        log.debug("%s it %3d |r| = %.3e N mu = %.3g rho = %.3g", what, it, rn, mu_used, rho)
        step = float(np.abs(du).max())
        if floor or (rn <= tol * force_scale(u) and (mu_used == 0.0 or step < 1e-9)):
            converged = True
            break
        if it >= 60 and min(res_hist[-40:]) > 0.1 * min(res_hist[:-40]):
            break          # stagnation: no tenfold progress in 40 iterations
    if not converged:
        note = f" ({describe(u)})" if describe is not None else ""
        raise ConvergenceError(f"{what}: no equilibrium after {it} iterations{note}; residual "
                               f"history {np.array(res_hist[-6:])} N, mu = {mu:.3g}"
                               f"{floor_hint(rn, force_scale(u), tol)}")
    return TrustRegionResult(u=u, iterations=it, residual_history=res_hist, mu_history=mu_hist,
                             tangent=K)
