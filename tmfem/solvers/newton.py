"""Nonlinear static solvers: Newton-Raphson with line search, adaptive load stepping, and
Crisfield's cylindrical arc-length method (dissertation eqs. 4.5-4.6).

All solvers work on a global vector ``u`` (any unknowns: displacements or positions) with a
set of *free* dofs; the others keep the values they have in ``u0`` (prescribed). They know
nothing of elements: a residual callback returns the residual vector and its tangent.
Linear solves go through a backend (:mod:`tmfem.solvers.backends`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.backends import SingularMatrix, get_backend
from tmfem.solvers.singular import SINGULAR_PIVOT_RATIO


def free_index(free, n: int) -> np.ndarray:
    """Integer indices of the free dofs from ``None`` (all), a boolean mask (n,) or indices."""
    if free is None:
        return np.arange(n)
    free = np.asarray(free)
    if free.dtype == bool:
        if free.shape != (n,):
            raise InputError(f"free: expected a boolean mask of shape ({n},), found {free.shape}")
        return np.flatnonzero(free)
    idx = np.unique(free.astype(np.int64))
    if idx.size and (idx[0] < 0 or idx[-1] >= n):
        raise InputError(f"free: expected dof indices in [0, {n}), found [{idx[0]}, {idx[-1]}]")
    return idx


def submatrix(K, idx):
    """The square block K[idx][:, idx] of a sparse or dense matrix (the free dofs); a
    backend's own matrix type (e.g. a distributed PETSc matrix) passes through when every
    dof is free."""
    if not (sp.issparse(K) or isinstance(K, np.ndarray)) and idx.size == K.shape[0] \
            and (idx.size == 0 or (idx[0] == 0 and np.all(np.diff(idx) == 1))):
        return K
    if sp.issparse(K):
        K = sp.csr_matrix(K)
        return K[idx][:, idx]
    return np.asarray(K)[np.ix_(idx, idx)]


def jacobi_scaling(A) -> np.ndarray:
    """Symmetric Jacobi equilibration d_i = 1/sqrt(|A_ii|) (1 where A_ii = 0) of a sparse or
    dense square matrix: D A D (D = diag d) has a unit diagonal."""
    if not (sp.issparse(A) or isinstance(A, np.ndarray)):
        raise InputError(f"equilibration: expected a scipy sparse or dense tangent, found "
                         f"{type(A).__name__} (a backend's own matrix: use equilibrate=False)")
    a = np.abs(np.asarray(A.diagonal(), dtype=float))
    return np.where(a > 0, 1.0 / np.sqrt(np.where(a > 0, a, 1.0)), 1.0)


def factorize(A, backend, *, equilibrate: bool = False):
    """``solve(b)`` of a tangent: a small dense one (ndarray) by LU in place (LAPACK), any other
    (sparse, a backend's distributed matrix) by the backend; a singular matrix raises
    :class:`~tmfem.solvers.backends.SingularMatrix`.

    ``equilibrate``: factorise D A D instead (:func:`jacobi_scaling`) and return
    x = D (D A D)^-1 D b, the same solution with the backward error of the pivots measured on
    the scaled matrix. For tangents whose dofs differ in stiffness by orders of magnitude (the
    rotations of a thin shell carry ~h^2 times the stiffness of its translations,
    docs/guides/shells.md "Thin shells") this keeps the Newton increment accurate."""
    if equilibrate:
        d = jacobi_scaling(A)
        if sp.issparse(A):
            A = sp.csr_matrix(A)
            rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
            As = sp.csr_matrix((A.data * d[rows] * d[A.indices], A.indices, A.indptr), shape=A.shape)
        else:
            As = A * d[:, None] * d[None, :]
        solve_scaled = factorize(As, backend)

        def solve(b):
            dd = d if np.ndim(b) == 1 else d[:, None]
            return dd * solve_scaled(dd * np.asarray(b, dtype=float))
        solve.pivot_ratio = getattr(solve_scaled, "pivot_ratio", None)
        return solve
    if not isinstance(A, np.ndarray):        # sparse, or a backend's own (distributed) matrix
        return backend.factorize(A)
    A = np.asarray(A, dtype=float)
    lu, piv = sla.lu_factor(A, check_finite=False)
    d = np.abs(np.diag(lu))
    if A.size and (not np.all(np.isfinite(d)) or d.min() <= SINGULAR_PIVOT_RATIO * max(d.max(), 1e-300)):
        raise SingularMatrix(f"linear solve: expected a non-singular {A.shape[0]}x{A.shape[0]} "
                             f"matrix, found a singular one (smallest LU pivot {d.min():.3e})")
    return lambda b: sla.lu_solve((lu, piv), b, check_finite=False)


def advance(u, idx, du, n: int, update):
    """The iterate after the increment ``du`` on the free dofs ``idx``: ``u + du`` (additive
    unknowns), or ``update(u, du_full)`` for unknowns that do not add (finite rotations)."""
    if update is None:
        ut = u.copy()
        ut[idx] += du
        return ut
    full = np.zeros(n)
    full[idx] = du
    return update(u, full)


def copy_iterate(u, update):
    """A copy of the iterate ``u`` that later updates leave alone (an iterate of unknowns that
    do not add is a new object at each ``update`` already)."""
    return np.array(u, dtype=float, copy=True) if update is None else u


def convergence_failure(message, *, step=None, history=(), load_factor=None, u=None) -> ConvergenceError:
    """A :class:`ConvergenceError` carrying the failed step, its residual history, the load
    factor reached and the last iterate (for callers that report or continue from them)."""
    err = ConvergenceError(message)
    err.step = step
    err.residual_history = list(history)
    err.load_factor = load_factor
    err.u = u
    return err


@dataclass
class NewtonResult:
    """Outcome of :func:`newton`: solution, iterations, residual norms (free dofs, 2-norm,
    one per evaluated iterate including the start), convergence flag, last residual and tangent."""

    u: np.ndarray
    iterations: int
    residual_history: list
    converged: bool
    r: np.ndarray | None = None
    K: object = None
    floor_limited: bool = False


def newton(residual: Callable, u0, *, free=None, tol: float = 1e-9, atol: float = 0.0,
           scale: float | None = None, max_iter: int = 50, line_search: bool = True,
           backend=None, callback: Callable | None = None, load_factor: float | None = None,
           step: int | None = None, floor_factor: float = 100.0, max_stall: int = 5,
           update: Callable | None = None, equilibrate: bool = False) -> NewtonResult:
    """Newton-Raphson iteration K du = -r on the free dofs, with backtracking line search.

    Parameters
    ----------
    residual : callable
        ``residual(u) -> (r, K)``: residual (n,) (internal minus external forces) and tangent
        (n, n) (sparse or dense), eq. 4.6.
    u0 : array (n,)
        Start; the entries of the fixed dofs are kept (prescribed values).
    free : bool mask, index array or None
        Free dofs (default all).
    tol, atol, scale : float
        Converged when ||r_free|| <= max(tol * scale, atol); ``scale`` defaults to ||r_free(u0)||
        (pass a force scale when starting near equilibrium, e.g. in load stepping).
    max_iter : int
    line_search : bool
        Backtracking (halving, Armijo on ||r||) when the full step does not reduce the residual.
    callback : callable, optional
        ``callback(iteration, u, rnorm)`` after every accepted iterate (iteration histories).
    floor_factor, max_stall :
        An iteration that reduces ||r|| by less than 1 % makes no progress. If that happens with
        ||r|| <= floor_factor * target the iterate is accepted (round-off floor of an
        ill-conditioned problem; ``floor_limited`` is set in the result); ``max_stall``
        such iterations in a row raise ``ConvergenceError`` (stalled).
    load_factor, step : optional
        Only reported in a :class:`ConvergenceError`.
    update : callable, optional
        ``update(u, du) -> u_new`` for unknowns that are not a vector to add to: ``u`` is then
        any object (e.g. a :class:`tmfem.fem.element.State` with finite rotations) and ``du``
        the full increment (zero at fixed dofs). Default: ``u + du``.
    equilibrate : bool
        Solve each Newton system with symmetric Jacobi scaling (:func:`factorize`).

    Raises
    ------
    ConvergenceError
        With attributes ``step``, ``residual_history``, ``load_factor`` and ``u`` (last iterate)
        when the residual is not finite, the tangent is singular or ``max_iter`` is exceeded.
    """
    be = get_backend(backend)
    u = copy_iterate(u0, update)
    r, K = residual(u)
    r = np.asarray(r, dtype=float)
    n = r.size
    idx = free_index(free, n)
    rn = float(np.linalg.norm(r[idx]))
    history = [rn]
    where = (f" (load step {step}, load factor {load_factor:g})" if load_factor is not None
             else (f" (step {step})" if step is not None else ""))
    if not np.isfinite(rn):
        raise convergence_failure(f"newton{where}: expected a finite residual at the start, found {rn}",
                    step=step, history=history, load_factor=load_factor, u=u)
    ref = rn if scale is None else float(scale)
    target = max(tol * ref, atol)
    if callback is not None:
        callback(0, u, rn)
    stalled = 0
    for it in range(1, max_iter + 1):
        if rn <= target:
            return NewtonResult(u=u, iterations=it - 1, residual_history=history, converged=True, r=r, K=K)
        try:
            solve = factorize(submatrix(K, idx), be, equilibrate=equilibrate)
        except ConvergenceError as exc:
            raise convergence_failure(f"newton{where}: iteration {it}: {exc}; residual history "
                        f"{[f'{h:.3e}' for h in history]}", step=step, history=history,
                        load_factor=load_factor, u=u) from None
        du = -solve(r[idx])
        alpha, best = 1.0, None
        while True:
            ut = advance(u, idx, alpha * du, n, update)
            rt, Kt = residual(ut)
            rt = np.asarray(rt, dtype=float)
            rnt = float(np.linalg.norm(rt[idx]))
            ok = np.isfinite(rnt)
            if ok and (best is None or rnt < best[0]):
                best = (rnt, ut, rt, Kt)
            if not line_search or (ok and rnt <= (1.0 - 1e-4 * alpha) * rn) or alpha < 1.0 / 64:
                break
            alpha *= 0.5
        if best is None:
            raise convergence_failure(f"newton{where}: iteration {it}: expected a finite residual after the update, "
                        f"found {rnt}; residual history {[f'{h:.3e}' for h in history]}",
                        step=step, history=history, load_factor=load_factor, u=u)
        progress = best[0] <= 0.99 * rn
        rn, u, r, K = best
        history.append(rn)
        if callback is not None:
            callback(it, u, rn)
        stalled = 0 if progress else stalled + 1
        if stalled and rn <= floor_factor * target:
            # round-off floor: the residual cannot be reduced further and is within
            # floor_factor of the target (ill-conditioned tangent, large internal forces)
            return NewtonResult(u=u, iterations=it, residual_history=history, converged=True,
                                r=r, K=K, floor_limited=True)
        if stalled >= max_stall:
            raise convergence_failure(f"newton{where}: stalled: no reduction of ||r|| in {stalled} iterations at "
                        f"{rn:.3e} (target {target:.3e}); residual history "
                        f"{[f'{h:.3e}' for h in history[-8:]]}", step=step, history=history,
                        load_factor=load_factor, u=u)
    if rn <= target:
        return NewtonResult(u=u, iterations=max_iter, residual_history=history, converged=True, r=r, K=K)
    raise convergence_failure(f"newton{where}: expected ||r|| <= {target:.3e} within {max_iter} iterations, found "
                f"{rn:.3e}; residual history {[f'{h:.3e}' for h in history[-8:]]}",
                step=step, history=history, load_factor=load_factor, u=u)


@dataclass
class LoadPath:
    """Converged states of a continuation: load factors (m,), solutions (m, n), Newton
    iterations per step, and the final :class:`NewtonResult`."""

    lam: np.ndarray
    u: np.ndarray
    iterations: list
    last: NewtonResult | None = None
    rejected: int = 0
    extra: dict = field(default_factory=dict)


def load_stepping(residual_lam: Callable, u0, *, free=None, dlam0: float = 1.0,
                  dlam_min: float = 1e-4, tol: float = 1e-9, atol: float = 0.0,
                  scale: float | None = None, max_iter: int = 25, target_iter: int = 6,
                  line_search: bool = True, backend=None, store: bool = True,
                  callback: Callable | None = None, update: Callable | None = None) -> LoadPath:
    """Adaptive load stepping from load factor 0 to 1 with Newton at each step.

    ``residual_lam(u, lam) -> (r, K)``. A step whose Newton solve fails is retried with half the
    increment; an easy step (fewer than ``target_iter`` iterations) lets the next grow by 1.5.
    The Newton tolerance is relative to ``scale`` (default: the residual norm of the first
    evaluation at lam = dlam0, i.e. of the first load increment). ``update`` as in
    :func:`newton` (then ``LoadPath.u`` is a list of the states).

    Raises
    ------
    ConvergenceError
        When the increment falls below ``dlam_min``; carries the step, the residual history
        of the last failure and the load factor that could not be reached.
    """
    u = copy_iterate(u0, update)
    lam, dlam = 0.0, min(float(dlam0), 1.0)
    lams, us, its = [0.0], [copy_iterate(u, update)] if store else [], []
    r1 = residual_lam(u, dlam)[0] if (scale is None or update is not None) else None
    idx = free_index(free, u.size if update is None else np.asarray(r1).size)
    if scale is None:
        r0, _ = residual_lam(u, 0.0)
        scale = max(float(np.linalg.norm(np.asarray(r1)[idx])), float(np.linalg.norm(np.asarray(r0)[idx])))
        if scale == 0.0:
            scale = 1.0
    rejected, step, last = 0, 0, None
    while lam < 1.0 - 1e-14:
        dlam = min(dlam, 1.0 - lam)
        target = lam + dlam
        step += 1
        try:
            res = newton(lambda v: residual_lam(v, target), u, free=idx, tol=tol, atol=atol,
                         scale=scale, max_iter=max_iter, line_search=line_search, backend=backend,
                         load_factor=target, step=step, update=update)
        except ConvergenceError as exc:
            rejected += 1
            dlam *= 0.5
            if dlam < dlam_min:
                raise convergence_failure(f"load stepping: expected to reach load factor 1, stuck at {lam:g} "
                            f"(increment "
                            f"{2 * dlam:.2e} < {dlam_min:g} failed): {exc}", step=step,
                            history=getattr(exc, "residual_history", []), load_factor=target, u=u) from None
            continue
        u, lam, last = res.u, target, res
        lams.append(lam)
        its.append(res.iterations)
        if store:
            us.append(copy_iterate(u, update))
        if callback is not None:
            callback(lam, u)
        if res.iterations < target_iter:
            dlam *= 1.5
    if update is not None:
        return LoadPath(lam=np.array(lams), u=us if store else [u], iterations=its, last=last,
                        rejected=rejected)
    return LoadPath(lam=np.array(lams), u=np.array(us) if store else u[None], iterations=its,
                    last=last, rejected=rejected)

