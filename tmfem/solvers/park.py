"""Park's three-step implicit integrator, started by the trapezoidal rule (eqs. 5.34-5.35).

The integrator solves any second-order system written as a residual

    r(x, v, a, t) = 0,       v = dx/dt,  a = d^2x/dt^2,

e.g. ``M(x) a + F(x, v) + B(x) u(t)`` for the control-oriented model or the internal minus
external forces of a finite-element model. Park's method (dissertation eq. 5.34) writes

    v_{n+1} = (10 x_{n+1} - 15 x_n + 6 x_{n-1} - x_{n-2}) / (6 dt)
    a_{n+1} = (10 v_{n+1} - 15 v_n + 6 v_{n-1} - v_{n-2}) / (6 dt)

so that r = 0 becomes a nonlinear equation in x_{n+1}, solved by Newton's method with the
Jacobian ``K + (10/(6 dt)) C + (10/(6 dt))^2 M`` (K = dr/dx, C = dr/dv, M = dr/da). The first
two steps use the trapezoidal rule (eq. 5.35), whose v and a are linear in x_{n+1} with
slopes 2/dt and 4/dt^2. The method is second-order accurate and, unlike the trapezoidal
rule, damps the modes with omega dt >> 1 (it is L-stable), which is why it is used for
stiff structural models.

The residual and its Jacobians come from a *system* object with two methods:

``residual(x, v, a, t) -> r`` (n,)
``jacobians(x, v, a, t) -> (K, C, M)``, each (n, n) dense ndarray or scipy sparse matrix.

An optional ``newton_matrix(x, v, a, t, cv, ca)`` returning ``K + cv C + ca M`` directly
(dense or sparse) is used when present (cheaper for models that assemble it at once), and an
optional ``factorize(S) -> solve`` replaces the default LU of the Newton matrix (e.g. a
symmetric-mode sparse LU for finite-element tangents). An optional ``mass_matrix(x, v, t)``
returning M = dr/da alone is used for the acceleration of a state (:func:`initial_acceleration`)
instead of the three Jacobians (for models whose K costs an assembly).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.backends import get_backend

_SCHEMES = ("park", "trapezoidal")


@dataclass
class ParkResult:
    """Histories of an integration (only when ``store=True``) and solver statistics."""

    t: np.ndarray
    x: np.ndarray | None
    v: np.ndarray | None
    a: np.ndarray | None
    newton_iterations: int = 0
    jacobian_evaluations: int = 0
    steps: int = 0
    restarts: int = 0


def _solver(S, system=None):
    """``solve(b)`` of the Newton (or mass) matrix S: the system's own ``factorize``, else
    sparse S by the system's ``backend`` (scipy when it names none), dense S by LU."""
    if system is not None and hasattr(system, "factorize"):
        return system.factorize(S)
    if sp.issparse(S):
        return get_backend(getattr(system, "backend", None)).factorize(S)
    S = np.asarray(S, dtype=float)
    lu = sla.lu_factor(S, check_finite=False)
    return lambda b: sla.lu_solve(lu, b, check_finite=False)


def _newton_matrix(system, x, v, a, t, cv, ca):
    if hasattr(system, "newton_matrix"):
        return system.newton_matrix(x, v, a, t, cv, ca)
    K, C, M = system.jacobians(x, v, a, t)
    return K + cv * C + ca * M


def _mass_matrix(system, x, v, a, t):
    """M = dr/da at (x, v, a, t): the system's ``mass_matrix`` when it has one, else the
    third of its ``jacobians``."""
    if hasattr(system, "mass_matrix"):
        return system.mass_matrix(x, v, t)
    return system.jacobians(x, v, a, t)[2]


def initial_acceleration(system, x0, v0, t0=0.0, *, a0=None, tol=1e-12, max_iter=20) -> np.ndarray:
    """Solve r(x0, v0, a, t0) = 0 for the acceleration a by the iteration a <- a - M^-1 r(a)
    from ``a0`` or 0, with M = dr/da evaluated and factored once at the start: the residual
    is affine in a (M(x) a + F(x, v, t)), so this is Newton's method, converged after one
    step up to round-off (the further steps remove that)."""
    x0 = np.asarray(x0, dtype=float)
    a = np.zeros_like(x0) if a0 is None else np.array(a0, dtype=float)
    solve = _solver(_mass_matrix(system, x0, v0, a, t0), system)
    for it in range(max_iter):
        r = system.residual(x0, v0, a, t0)
        da = -solve(r)
        a = a + da
        if np.linalg.norm(da) <= tol * (1.0 + np.linalg.norm(a)):
            return a
    raise ConvergenceError(f"initial acceleration: Newton did not converge in {max_iter} "
                           f"iterations (last |da| = {np.linalg.norm(da):.3e})")


def park_integrate(system, *, x0, v0, dt: float, n_steps: int, t0: float = 0.0,
                   a0=None, scheme: str = "park", tol: float = 1e-10,
                   max_iter: int = 25, jacobian: str = "iteration", reuse_iter: int = 4,
                   callback: Callable | None = None, store: bool = True,
                   progress: Callable | None = None, sampled: bool = False,
                   predictor: str = "acceleration",
                   line_search: bool = False) -> ParkResult:
    """Integrate r(x, v, a, t) = 0 with Park's method started by the trapezoidal rule.

    Parameters
    ----------
    system : object
        Provides ``residual`` and ``jacobians`` (see the module docstring).
    x0, v0 : array_like (n,)
        Initial state; ``a0`` (optional) the initial acceleration, else solved from r = 0.
    dt : float
        Time step.
    n_steps : int
        Number of steps; the last time is ``t0 + n_steps dt``.
    scheme : {"park", "trapezoidal"}
        ``"park"`` = eq. 5.34 after two trapezoidal steps (eq. 5.35); ``"trapezoidal"`` uses
        eq. 5.35 throughout (energy-conserving for linear systems, no numerical damping).
    tol : float
        Newton stops when |dx| <= tol (1 + |x|) (infinity norm).
    jacobian : {"iteration", "step", "reuse"}
        Re-evaluate and factor the Newton matrix at every iteration (full Newton), once
        per step (modified Newton; cheaper when the Jacobian is costly), or keep it over
        steps and refresh it when a step needs more than ``reuse_iter`` iterations. With
        "step" and "reuse", a step whose Newton corrections grow restarts from the
        predictor with full Newton, and one still unconverged after ``2 reuse_iter``
        iterations continues with full Newton (a stale matrix can make modified Newton
        diverge).
    callback : callable, optional
        ``callback(t, x, v, a)`` after the initial state and after every step (e.g. to
        write a CSV row); a true return value stops the integration.
    store : bool
        Keep the histories in the result (else only the last state).
    progress : callable, optional
        ``progress(step, n_steps)`` called every step (e.g. to print to stderr).
    sampled : bool
        The callback may change the system's inputs (a zero-order-hold controller): after
        each callback that precedes a trapezoidal step (every step of ``"trapezoidal"``, the
        two starting steps of ``"park"``) the acceleration is re-solved from
        r(x, v, a, t) = 0 with the new inputs, so that the trapezoidal rule integrates every
        sample interval as a smooth problem (second order) and the start uses the
        acceleration of the first input, not of the system's inputs before the first
        callback. Park's multistep formula does not use the acceleration: it sees the input
        steps through its history and is first order across them.
    line_search : bool
        Backtracking on the Newton correction of a step (:func:`_line_search`): a correction
        dx larger than 1e3 x the tolerance (not in the quadratic, round-off-limited end of the
        iteration) is scaled by the first alpha = 1, 1/2, ..., 1/64 with
        ||r(x + alpha dx)||_2 <= (1 - 1e-4 alpha) ||r(x)||_2 (Armijo), taken whole when none
        decreases. The Newton direction is a descent direction of ||r||^2, so this only
        shortens corrections that overshoot: a system whose Newton matrix has
        near-singular, strongly nonlinear directions (the thin shell's rotations in the SBC
        model, docs/guides/sbc.md "Free vibration on the fine mesh"). Convergence is still judged on
        the full correction |dx|; a kept (modified-Newton) matrix whose direction does not
        decrease the residual is replaced by a fresh one.
    predictor : {"acceleration", "velocity"}
        Start of each step's Newton iteration: x_n + dt v_n + dt^2 a_n / 2 (constant
        acceleration) or x_n + dt v_n. The second is for systems with dofs of almost no
        inertia (the SBC shell's nodal rotations, rotary inertia rho h^3 / 12): the
        acceleration re-solved after an input step is the residual moment divided by that
        inertia, and extrapolating it puts the predictor at rotations of radians, from where
        Newton diverges (docs/guides/fe-plant.md).

    Returns
    -------
    ParkResult
    """
    if scheme not in _SCHEMES:
        raise InputError(f"integrator scheme: expected one of {_SCHEMES}, found {scheme!r}")
    if jacobian not in ("iteration", "step", "reuse"):
        raise InputError(f"jacobian: expected 'iteration', 'step' or 'reuse', found {jacobian!r}")
    if not (np.isfinite(dt) and dt > 0):
        raise InputError(f"time step: expected dt > 0, found {dt!r}")
    if not (isinstance(n_steps, (int, np.integer)) and n_steps >= 0):
        raise InputError(f"number of steps: expected an integer >= 0, found {n_steps!r}")
    if predictor not in ("acceleration", "velocity"):
        raise InputError(f"predictor: expected 'acceleration' or 'velocity', found {predictor!r}")
    x = np.array(x0, dtype=float)
    v = np.array(v0, dtype=float)
    if x.shape != v.shape or x.ndim != 1:
        raise InputError(f"x0 and v0: expected two vectors of one length, found {x.shape}, {v.shape}")
    a = initial_acceleration(system, x, v, t0) if a0 is None else np.array(a0, dtype=float)
    n = x.size
    if store:
        X = np.empty((n_steps + 1, n))
        V = np.empty_like(X)
        A = np.empty_like(X)
        X[0], V[0], A[0] = x, v, a
    T = t0 + dt * np.arange(n_steps + 1)
    res = ParkResult(t=T, x=None, v=None, a=None)
    if callback is not None and callback(t0, x, v, a):
        n_steps = 0
    elif sampled:
        a = initial_acceleration(system, x, v, t0, a0=a)
    hx = [x.copy()]       # most recent last: x_n, x_{n-1}, x_{n-2}
    hv = [v.copy()]
    c_park = 10.0 / (6.0 * dt)
    last = 0
    solve, kept_coef = None, None
    for k in range(1, n_steps + 1):
        t = t0 + k * dt
        xn, vn, an = hx[-1], hv[-1], a
        if scheme == "park" and len(hx) >= 3:
            xs = (-15 * hx[-1] + 6 * hx[-2] - hx[-3]) / (6 * dt)
            vs = (-15 * hv[-1] + 6 * hv[-2] - hv[-3]) / (6 * dt)

            def kin(xnew, xs=xs, vs=vs):
                vnew = c_park * xnew + xs
                return vnew, c_park * vnew + vs
            cv, ca = c_park, c_park**2
        else:
            def kin(xnew, xn=xn, vn=vn, an=an):
                vnew = 2.0 * (xnew - xn) / dt - vn
                return vnew, 2.0 * (vnew - vn) / dt - an
            cv, ca = 2.0 / dt, 4.0 / dt**2
        xk = xn + dt * vn + (0.5 * dt**2 * an if predictor == "acceleration" else 0.0)
        if jacobian != "reuse" or kept_coef != (cv, ca):
            solve = None
        fresh = False
        full = jacobian == "iteration"
        x_pred = xk.copy()
        dx_prev = np.inf
        r_next = None          # the residual at xk when the line search has evaluated it
        r_first = dx_first = None
        for it in range(1, max_iter + 1):
            vk, ak = kin(xk)
            r = system.residual(xk, vk, ak, t) if r_next is None else r_next
            factored = False
            r_next = None
            if r_first is None:
                r_first = float(np.max(np.abs(r)))
            # a kept (modified-Newton) matrix that has not converged in 2 reuse_iter
            # iterations gives way to full Newton for the step
            full = full or it > 2 * reuse_iter
            if (solve is None or full
                    or (jacobian == "reuse" and it > reuse_iter and not fresh)):
                solve = _solver(_newton_matrix(system, xk, vk, ak, t, cv, ca), system)
                kept_coef = (cv, ca)
                fresh = True
                factored = True
                res.jacobian_evaluations += 1
            dx = -solve(r)
            dx_norm = np.max(np.abs(dx))
            dx_first = dx_norm if dx_first is None else dx_first
            if dx_norm > dx_prev and not full and dx_norm > 1e3 * tol * (1.0 + np.max(np.abs(xk))):
                # growing corrections of a kept matrix: restart the step from the predictor
                # with full Newton
                full = True
                xk, dx_prev = x_pred.copy(), np.inf
                res.restarts += 1
                continue
            dx_prev = dx_norm
            if line_search and dx_norm > 1e3 * tol * (1.0 + np.max(np.abs(xk))):
                alpha, r_next, decreased = _line_search(
                    lambda y: system.residual(y, *kin(y), t), xk, dx, r)
                if not decreased and not factored:
                    full, r_next = True, r     # a kept matrix's direction: refresh, no step
                    continue
                dx = alpha * dx
            xk = xk + dx
            res.newton_iterations += 1
            if not np.all(np.isfinite(xk)):
                raise ConvergenceError(f"Park step {k} (t = {t:.6g}): Newton produced non-finite "
                                       f"values at iteration {it}")
            if dx_norm <= tol * (1.0 + np.max(np.abs(xk))):
                break
        else:
            r_last = float(np.max(np.abs(r)))
            # growing residuals or corrections: divergence, not slow convergence
            grew = r_last > 10.0 * r_first or dx_norm > 10.0 * dx_first
            how = "diverged" if grew else "did not converge"
            raise ConvergenceError(f"Park step {k} (t = {t:.6g} s, dt = {dt:g} s): Newton {how} in "
                                   f"{max_iter} iterations: |r| = {r_first:.3e} at the predictor, "
                                   f"{r_last:.3e} at the last iterate (max norm), last |dx| = "
                                   f"{dx_norm:.3e} (tolerance {tol:g} (1 + |x|))")
        x = xk
        v, a = kin(x)
        hx.append(x.copy())
        hv.append(v.copy())
        if len(hx) > 3:
            hx.pop(0)
            hv.pop(0)
        if store:
            X[k], V[k], A[k] = x, v, a
        last = k
        res.steps = k
        if progress is not None:
            progress(k, n_steps)
        if callback is not None and callback(t, x, v, a):
            break
        if sampled and (scheme == "trapezoidal" or len(hx) < 3):
            a = initial_acceleration(system, x, v, t, a0=a)
    if store:
        res.x, res.v, res.a = X[: last + 1], V[: last + 1], A[: last + 1]
        res.t = T[: last + 1]
    else:
        res.x, res.v, res.a = x[None], v[None], a[None]
        res.t = T[last: last + 1]
    return res


def _line_search(residual, x, dx, r, *, min_alpha: float = 1.0 / 64):
    """Backtracking on a Newton correction (``line_search`` of :func:`park_integrate`):
    ``(alpha, r(x + alpha dx), True)`` for the first alpha = 1, 1/2, ... >= min_alpha with
    ||r(x + alpha dx)||_2 <= (1 - 1e-4 alpha) ||r(x)||_2, else ``(1, r(x + dx), False)``:
    the full correction, as plain Newton takes it."""
    r0 = float(np.linalg.norm(r))
    alpha, full = 1.0, None
    while alpha >= min_alpha:
        rt = residual(x + alpha * dx)
        full = rt if full is None else full
        rn = float(np.linalg.norm(rt))
        if np.isfinite(rn) and rn <= (1.0 - 1e-4 * alpha) * r0:
            return alpha, rt, True
        alpha *= 0.5
    return 1.0, full, False


class LinearSecondOrder:
    """The linear system M a + C v + K x = f(t), as a residual for :func:`park_integrate`."""

    def __init__(self, M, C, K, f: Callable | None = None):
        self.M, self.C, self.K = M, C, K
        self.f = f

    def residual(self, x, v, a, t):
        r = self.M @ a + self.C @ v + self.K @ x
        return r - self.f(t) if self.f is not None else r

    def jacobians(self, x, v, a, t):
        return self.K, self.C, self.M
