"""Path following with the load factor as an unknown: arc length and displacement control.

The equilibrium r(u, lam) = 0 is followed from a converged point (u_0, lam_0) with a system
callback ``system(u, lam) -> (r, K, q)``: the residual, its tangent K = dr/du and the load
vector q = -dr/dlam (for r = f_int(u) - lam f(u): q = f(u), so follower loads are allowed;
K then includes -lam df/du). Each step adds one constraint to the equations:

- **arc length** (Crisfield 1981, spherical with psi > 0, cylindrical with psi = 0):
  ||Du||^2 + psi^2 Dlam^2 q.q = dl^2 on the step's increments. Predictor du_t = K^-1 q,
  Dlam = s dl / sqrt(du_t.du_t + psi^2 q.q), with the sign s of the previous converged
  increment's projection on the predictor (du_t . Du_prev + psi^2 q.q Dlam_prev), so that
  the path goes on through limit points and never turns back; corrector: of the two roots
  of the constraint the one whose increment has the larger projection on the previous
  converged increment (Crisfield's angle criterion). A converged step whose increment
  points backwards (negative projection) is rejected like a failed one (cut back).
- **displacement control** (Batoz & Dhatt 1979): one chosen free dof c advances by du_c
  per step and lam follows: Du_c fixed, dlam = -(du_r)_c / (du_t)_c in every iteration.

A failed step (no convergence in ``max_iter`` iterations, a non-finite residual, a singular
tangent, no real root of the arc constraint, or a backward step) is retried with the arc
(or increment) times ``cutback`` down to ``dl_min``; then the run stops with the reason
"divergence". After a converged step the arc adapts as dl (target_iter / iterations)^(1/2),
its change limited to the factors [cutback, growth] and to [dl_min, dl_max].

Every run returns every converged point with a :class:`StepInfo` (load factor, Newton
iterations, residual norms, arc, number of negative pivots of the tangent, event) and why
it stopped: "completed" (``lam_max`` or the displacement target reached), "budget"
(``max_steps``), "divergence", "stopped" (``stop`` callback), or an event named in
``stop_at``: "limit point" or "bifurcation". Both are seen in the number of negative pivots
of the tangent (Sylvester's law of inertia on its LDL^T pivots): when it changes in a step,
an eigenvalue crossed zero; if the current stiffness q.K^-1 q changed sign with it, q has a
component on that mode and the load passed a maximum or minimum (limit point), else the
path crossed a bifurcation point. Without the pivot count (``stability=False``) a change of
sign of the load increment marks a limit point. The result holds
the last increment and arc, so a run can be continued where it stopped (``start_increment``,
``dl``).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.backends import get_backend
from tmfem.solvers.newton import (LoadPath, advance, convergence_failure, copy_iterate, factorize,
                                  free_index, submatrix)

log = logging.getLogger(__name__)

#: why a continuation stopped
REASONS = ("completed", "budget", "divergence", "stopped", "limit point", "bifurcation")


def negative_pivots(K) -> int | None:
    """Number of negative eigenvalues of the symmetric matrix K (Sylvester: the negative
    pivots of K = L D L^T), from a sparse LU in symmetric mode without row pivoting (U's
    diagonal is D); None when the factorization had to pivot off the diagonal or K is
    singular."""
    A = sp.csc_matrix(K)
    if A.shape[0] == 0:
        return 0
    try:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:
        return None
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return None
    return int(np.sum(lu.U.diagonal() < 0))


@dataclass
class StepInfo:
    """One converged point of a path: load factor, Newton iterations, residual norms of the
    iterations (free dofs), the arc (or increment) of the step, the number of negative
    pivots of the tangent there (None when not computed) and an event ("limit point",
    "bifurcation") passed in the step."""

    lam: float
    iterations: int = 0
    residuals: list = field(default_factory=list)
    arc: float | None = None
    negative_pivots: int | None = None
    event: str | None = None


@dataclass
class ContinuationResult:
    """Converged points ``u`` (list) with their :class:`StepInfo` ``steps`` (the start first),
    the ``reason`` (one of :data:`REASONS`) with a ``message``, the last converged increment
    ``increment`` = (Du, Dlam) (free dofs) and the arc ``dl`` for the next step."""

    u: list
    steps: list
    reason: str
    message: str
    increment: tuple | None = None
    dl: float | None = None

    @property
    def lam(self) -> np.ndarray:
        return np.array([s.lam for s in self.steps])


def follow(system: Callable, u0, *, lam0: float = 0.0, free=None, method: str = "arc-length",
           dl: float, control: int | None = None, psi: float = 0.0, max_steps: int = 100,
           lam_max: float | None = None, u_target: float | None = None, tol: float = 1e-8,
           scale: float | None = None, max_iter: int = 25, target_iter: int = 5,
           dl_min: float | None = None, dl_max: float | None = None, growth: float = 2.0,
           cutback: float = 0.5, stability: bool = True, stop_at=(), stop: Callable | None = None,
           start_increment: tuple | None = None, start_pivots: int | None = None,
           update: Callable | None = None, backend=None, equilibrate: bool = True,
           callback: Callable | None = None) -> ContinuationResult:
    """Follow the equilibrium path of ``system`` from the converged point (u0, lam0)
    (module docstring).

    Parameters
    ----------
    system : callable
        ``system(u, lam) -> (r, K, q)`` on all (reduced) dofs; only ``free`` ones are solved.
    method : "arc-length" or "displacement"
        The step constraint; "displacement" needs ``control`` (index of a free dof).
    dl : float
        First arc length (2-norm of the increment on the free dofs, plus psi^2 Dlam^2 q.q) or
        first increment of the control dof (its sign sets the direction).
    psi : float
        Load term of the arc (0: cylindrical arc length).
    max_steps, lam_max, u_target, stop :
        Budget of steps; stop when lam reaches ``lam_max`` (from either side of lam0) or the
        control dof ``u_target`` (displacement control; the last step is shortened to land on
        it), or when ``stop(u, lam)`` is True.
    tol, scale :
        Converged when ||r|| <= tol * scale (free dofs; default scale ||q|| at the start).
    max_iter, target_iter, dl_min, dl_max, growth, cutback :
        Iterations per step; arc adaptation and cut-back (module docstring); defaults
        dl_min = 1e-4 |dl|, dl_max = 10 |dl|.
    stability, stop_at :
        Count the negative pivots of the tangent at every converged point (an extra sparse
        factorization); stop at the events named in ``stop_at`` ("limit point",
        "bifurcation").
    start_increment, start_pivots :
        The last increment (Du, Dlam) and pivot count of a previous run, to continue it in
        the same direction.
    update, backend, equilibrate, callback :
        As in :func:`tmfem.solvers.newton.newton`; ``callback(u, step_info)`` after each
        converged step.
    """
    if method not in ("arc-length", "displacement"):
        raise InputError(f"path following: expected method 'arc-length' or 'displacement', found {method!r}")
    if not (np.isfinite(dl) and dl != 0 and (method == "displacement" or dl > 0)):
        raise InputError(f"path following: expected a finite non-zero first step dl (> 0 for arc length), found {dl!r}")
    unknown = set(stop_at) - {"limit point", "bifurcation"}
    if unknown:
        raise InputError(f"path following: expected stop_at events from 'limit point', 'bifurcation', "
                         f"found {sorted(unknown)}")
    be = get_backend(backend)
    u = copy_iterate(u0, update)
    lam = float(lam0)
    r, K, q = system(u, lam)
    n = np.asarray(r).size
    idx = free_index(free, n)
    if method == "displacement":
        pos = np.flatnonzero(idx == control) if control is not None else np.zeros(0)
        if pos.size != 1:
            raise InputError(f"displacement control: expected the control dof among the free dofs, found {control!r}")
        c = int(pos[0])
    qn = float(np.linalg.norm(np.asarray(q)[idx]))
    if scale is None:
        scale = qn
    if not scale > 0:
        raise InputError("path following: expected a non-zero load vector q on the free dofs, found 0")
    step_abs = abs(dl)
    sgn_dl = np.sign(dl)
    dl_min = step_abs * 1e-4 if dl_min is None else dl_min
    dl_max = step_abs * 10 if dl_max is None else dl_max
    pivots = negative_pivots(submatrix(K, idx)) if (stability and start_pivots is None) else start_pivots
    steps = [StepInfo(lam=lam, negative_pivots=pivots)]
    us = [copy_iterate(u, update)]
    prev = None if start_increment is None else (np.asarray(start_increment[0], float), float(start_increment[1]))
    u_c = 0.0                                     # control dof's displacement from the start
    reason, message = "budget", f"{max_steps} steps done"

    def solve_tangent(Kt):
        return factorize(submatrix(Kt, idx), be, equilibrate=equilibrate)

    for step in range(1, max_steps + 1):
        if method == "displacement" and u_target is not None:
            step_abs = min(step_abs, abs(u_target - u_c))
        while True:
            ok, why = False, ""
            history = []
            try:
                solve = solve_tangent(K)
                qf = np.asarray(q)[idx]
                dut = solve(qf)
                stiff = float(qf @ dut)                   # current stiffness q.K^-1 q at the point
                if method == "arc-length":
                    w2 = psi**2 * float(qf @ qf)
                    norm_t = np.sqrt(float(dut @ dut) + w2)
                    sign = 1.0 if prev is None else (1.0 if dut @ prev[0] + w2 * prev[1] >= 0 else -1.0)
                    Dlam = sign * step_abs / norm_t
                else:
                    if dut[c] == 0:
                        raise ConvergenceError("the control dof does not respond to the load")
                    Dlam = sgn_dl * step_abs / dut[c]
                Du = Dlam * dut
                ref = (Du, Dlam) if prev is None else prev
                ut = advance(u, idx, Du, n, update)
                for it in range(1, max_iter + 1):
                    r, Kt, q = system(ut, lam + Dlam)
                    rf = np.asarray(r)[idx]
                    rn = float(np.linalg.norm(rf))
                    history.append(rn)
                    if not np.isfinite(rn):
                        why = "non-finite residual"
                        break
                    if rn <= tol * scale:
                        ok = True
                        break
                    solve = solve_tangent(Kt)
                    qf = np.asarray(q)[idx]
                    dur, dut = -solve(rf), solve(qf)
                    if method == "arc-length":
                        w2 = psi**2 * float(qf @ qf)
                        wv = Du + dur
                        a = float(dut @ dut) + w2
                        b = 2.0 * float(dut @ wv) + 2.0 * w2 * Dlam
                        cc = float(wv @ wv) + w2 * Dlam**2 - step_abs**2
                        disc = b * b - 4.0 * a * cc
                        if disc < 0:
                            why = "no real root of the arc constraint"
                            break
                        roots = ((-b + np.sqrt(disc)) / (2 * a), (-b - np.sqrt(disc)) / (2 * a))
                        proj = [(wv + s * dut) @ ref[0] + w2 * (Dlam + s) * ref[1] for s in roots]
                        dlam = roots[int(np.argmax(proj))]
                    else:
                        dlam = -dur[c] / dut[c]
                    d = dur + dlam * dut
                    Du, Dlam = Du + d, Dlam + dlam
                    ut = advance(ut, idx, d, n, update)
                else:
                    why = f"no convergence in {max_iter} iterations"
                if ok and method == "arc-length" and prev is not None and \
                        Du @ prev[0] + psi**2 * float(qf @ qf) * Dlam * prev[1] < 0:
                    ok, why = False, "the step turned back along the path"
            except ConvergenceError as exc:             # singular tangent
                why = str(exc)
            if ok:
                break
            step_abs *= cutback
            log.info("path following: step %d failed (%s); arc cut to %.3e", step, why, step_abs)
            if step_abs < dl_min:
                reason = "divergence"
                message = (f"step {step}: expected convergence, found none down to the step {step_abs / cutback:.3e} "
                           f"(dl_min {dl_min:.3e}) at load factor {lam:g}: {why}; residuals "
                           f"{[f'{h:.2e}' for h in history[-6:]]}")
                break
        if reason == "divergence":
            break
        event = None
        new_piv = negative_pivots(submatrix(Kt, idx)) if stability else None
        if new_piv is not None and pivots is not None and new_piv != pivots:
            # an eigenvalue of K crossed zero: at a limit point q has a component on its mode
            # and the current stiffness q.K^-1 q changes sign with it; at a bifurcation not
            try:
                qn_new = np.asarray(q)[idx]
                turned = np.sign(qn_new @ solve_tangent(Kt)(qn_new)) != np.sign(stiff)
            except ConvergenceError:
                turned = True
            event = "limit point" if turned else "bifurcation"
        elif new_piv is None and prev is not None and prev[1] != 0 and Dlam != 0 and \
                np.sign(Dlam) != np.sign(prev[1]):
            event = "limit point"
        u, lam, K, pivots = ut, lam + Dlam, Kt, new_piv if stability else pivots
        if method == "displacement":
            u_c += sgn_dl * step_abs
        prev = (Du, Dlam)
        info = StepInfo(lam=lam, iterations=it, residuals=history, arc=step_abs,
                        negative_pivots=new_piv, event=event)
        steps.append(info)
        us.append(copy_iterate(u, update))
        if callback is not None:
            callback(u, info)
        step_abs = float(np.clip(step_abs * np.clip(np.sqrt(target_iter / max(it, 1)), cutback, growth),
                                 dl_min, dl_max))
        if event is not None and event in stop_at:
            reason, message = event, f"step {step}: {event} at load factor {lam:g}"
            break
        if lam_max is not None and (lam - lam_max) * np.sign(lam_max - lam0) >= 0:
            reason, message = "completed", f"load factor {lam:g} reached {lam_max:g}"
            break
        if method == "displacement" and u_target is not None and abs(u_target - u_c) <= 1e-12 * max(abs(u_target), 1.0):
            reason, message = "completed", f"control displacement {u_c:g} reached"
            break
        if stop is not None and stop(u, lam):
            reason, message = "stopped", f"stop() at step {step}, load factor {lam:g}"
            break
    if reason in ("divergence", "budget"):
        log.warning("path following stopped (%s): %s", reason, message)
    return ContinuationResult(u=us, steps=steps, reason=reason, message=message, increment=prev, dl=step_abs)


def arc_length(internal: Callable, f_ext, u0, *, free=None, dl: float, n_steps: int = 100,
               lam_max: float | None = None, stop: Callable | None = None, tol: float = 1e-9,
               max_iter: int = 25, target_iter: int = 5, dl_min: float | None = None,
               dl_max: float | None = None, backend=None, update: Callable | None = None) -> LoadPath:
    """Crisfield's cylindrical arc-length method: f_int(u) = lam f_ext with ||Delta u|| = dl.

    Parameters
    ----------
    internal : callable
        ``internal(u) -> (f_int, K)`` internal force and tangent.
    f_ext : array (n,)
        Reference external load; the load factor lam scales it (may become negative: the
        method follows the path through limit points and snap-backs).
    u0 : array (n,)
        Equilibrium start at lam = 0 (fixed dofs keep their values).
    dl : float
        Arc length (2-norm of the displacement increment on the free dofs).
    n_steps, lam_max, stop :
        Stop after ``n_steps`` steps, when lam exceeds ``lam_max``, or when ``stop(u, lam)`` is True.
    tol : float
        Converged when ||f_int - lam f_ext|| <= tol ||f_ext|| (free dofs).
    target_iter, dl_min, dl_max :
        The arc length adapts as dl *= sqrt(target_iter / iterations) within [dl_min, dl_max];
        a failed step is retried with half the arc length.

    The predictor follows the previous increment's direction (sign of Delta u_prev . du_t), so
    the path goes through limit points; of the two roots of the constraint in each corrector
    iteration the one closer to the previous increment direction is taken. This is
    :func:`tmfem.solvers.continuation.follow` for a fixed load f_ext (no pivot counts, plain
    solves), raising when it stops short.

    Returns
    -------
    LoadPath with ``lam`` (m,) and ``u`` (m, n), the starting state included.
    """
    f_ext = np.asarray(f_ext, dtype=float)
    if float(np.linalg.norm(f_ext[free_index(free, f_ext.size)])) == 0.0:
        raise InputError("arc length: expected a non-zero reference load on the free dofs, found 0")

    def system(u, lam):
        fint, K = internal(u)
        return np.asarray(fint) - lam * f_ext, K, f_ext
    res = follow(system, u0, free=free, dl=dl, max_steps=n_steps, lam_max=lam_max, tol=tol, max_iter=max_iter,
                 target_iter=target_iter, dl_min=dl_min, dl_max=dl_max, growth=np.inf, stability=False,
                 stop=stop, update=update, backend=backend, equilibrate=False)
    if res.reason == "divergence":
        raise convergence_failure(f"arc length: {res.message}", step=len(res.steps), history=res.steps[-1].residuals,
                    load_factor=res.steps[-1].lam, u=res.u[-1])
    its = [st.iterations for st in res.steps[1:]]
    return LoadPath(lam=res.lam, u=np.array(res.u) if update is None else res.u, iterations=its)
