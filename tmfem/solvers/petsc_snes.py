"""Equilibrium by PETSc's SNES: the static solves of the PETSc backend.

The finite-element statics start from a singular state (the flat, unstretched membrane has no
transverse stiffness), so a plain Newton iteration cannot start there. The continuation is
*pseudo-transient continuation* in its implicit form, the proximal-point method on the energy
W: each continuation step solves the nonlinear system

    G(u) = r(u) + mu D (u - u_k) = 0,        J_G = K_T(u) + mu D,        D = diag(M),

by one SNES solve from u_k (backward Euler on the gradient flow D du/dt = -r with the pseudo
time step 1 / mu). Its solution minimises W(u) + mu/2 |u - u_k|_D^2, so an accepted step
lowers the energy: the iteration slides down the energy to a minimum, the same equilibrium
as the trust region of :mod:`tmfem.solvers.trust_region` (whose step is one Newton iteration
of this problem). A step is accepted when it lowers W; then, if its SNES solve converged,
mu falls eightfold; a failed or rejected step multiplies mu by 4. Below :data:`MU_NEWTON` of
the stiffness-to-mass scale mu becomes 0 and the last SNES solve is Newton's method on
r(u) = 0 itself, stopping at ||r|| <= tol x force scale (SNES ``atol``: the test of the trust
region).

Every SNES solve reads the options database (``-snes_*``, ``-ksp_*``, ``-pc_*`` of
``PETSC_OPTIONS`` and of the backend's ``options=``), so ``-snes_monitor`` prints every
iteration, ``-snes_linesearch_type``, ``-snes_type`` or ``-snes_rtol`` change the solver; the
defaults are Newton (``newtonls``) on MUMPS (Cholesky, LU where the tangent is
unsymmetric), ``atol`` as above, ``rtol = stol = 0`` for the final solve and ``rtol = 1e-2``
with at most 3 iterations for a continuation step (an inexact proximal step only needs to
lower the energy), and full steps (line search ``basic``: the continuation, whose energy
test accepts or rejects a step, is the globalisation; PETSc's backtracking on ||r|| took
20-50 tiny steps near the MTC equilibria, where full Newton steps converge quadratically).
A final solve that does not converge within 20 iterations sends the iteration back to the
continuation; when that runs out (mu beyond 1e12 of its scale, or ``max_iter`` SNES
iterations), :class:`~tmfem.errors.ConvergenceError` names the last SNES converged reason.
The final solve also stops on the round-off floor (a step whose predicted energy change is
round-off, below 1e-11 of the energy, and that no longer halves ||r|| while ||r|| <= 1e3 tol
x force scale, as in the trust region: stiff shells put it near tol).

The unknowns are the free dofs of a distributed assembly (``residual(u) -> (r, K)`` with K a
:class:`tmfem.solvers.distributed.DistributedMatrix` and r this rank's rows of the residual,
those of K's rows: norms and dot products are collective, no rank holds the whole residual);
the state u is whole on every rank. States that do not add (finite rotations) advance by
``update(u, du)``: SNES iterates on the increment from a base state, which is moved to the
current iterate at every Newton iteration (``SNESSetUpdate``), so that the tangent K_T(u) is
the Jacobian of the increment.

Memory: the SNES's preconditioner matrix is a copy of the tangent (shifted by mu D during
the continuation), which MUMPS factorises; the model's tangent itself is refilled in place
at every evaluation (nothing holds the last one: an evaluation's r and K are cached until
the next), so a solve holds two tangent-sized matrices besides MUMPS' factors. A step that
fails costs one evaluation more: the accepted state's r and K are computed again.
"""
from __future__ import annotations

import logging

import numpy as np

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.distributed import DistributedMatrix, gather, rows_dot, rows_norm
from tmfem.solvers.mumps import is_singular, mumps_error, mumps_failure
from tmfem.solvers.petsc_options import SOLVER_PREFIXES, option_error, set_from_options
from tmfem.solvers.roundoff import FLOOR_FACTOR, floor_hint

log = logging.getLogger(__name__)

#: mu (in units of the stiffness-to-mass scale) below which the continuation ends with a
#: plain Newton solve of r(u) = 0
MU_NEWTON = 1e-8
#: SNES iterations of the final Newton solve before the continuation takes over again
NEWTON_MAX_IT = 20
#: SNES iterations of a continuation step (an inexact proximal step: accepted when it lowers
#: the energy)
STEP_MAX_IT = 3
#: relative tolerance of a continuation step's SNES solve
STEP_RTOL = 1e-2


#: the "converged reason" of a final solve stopped on the round-off floor
FLOOR = 1000


class _Floor(Exception):
    """Raised by the monitor of the final solve on the round-off floor (stops SNES)."""


def reason_name(PETSc, reason: int) -> str:
    """The name of a SNES converged reason (``CONVERGED_FNORM_ABS``, ``DIVERGED_LINE_SEARCH``)."""
    names = {v: k for k, v in vars(PETSc.SNES.ConvergedReason).items()
             if isinstance(v, int) and not k.startswith("_")}
    return names.get(int(reason), str(reason))


class _Problem:
    """The residual and Jacobian callbacks of one SNES: G(x) = r(u(x)) + mu D (offset + x)
    with u(x) the base state advanced by the increment x (module docstring). The residual
    r, the scale D, the offset and the increment are held as this rank's rows; the state u,
    which the model's residual reads, is whole."""

    def __init__(self, backend, residual, u0, *, comm, D, update, first):
        self.backend, self.residual, self.update = backend, residual, update
        self.comm, self.D = comm, D
        self.base, self.offset, self.mu = u0, np.zeros(D.size), 0.0
        self.cache = {"x": np.zeros(D.size), "u": u0, "r": first[0], "K": first[1]}

    def state(self, x: np.ndarray):
        """The state of the increment x (whole) from the base."""
        if self.update is None:
            return self.base + x
        return self.update(self.base, x)

    def evaluate(self, X):
        """(u, r, K) at the increment X (a PETSc Vec; the last evaluation reused).
        Collective: every rank evaluates, or none.

        The tangent of the last evaluation is let go before the next one, so that the
        model refills it in place (:meth:`tmfem.fem.distributed.DistributedElements.residual`
        reuses a tangent nobody references): one tangent of the model lives through the
        solve, beside the SNES's preconditioner matrix. Callers hold K only while they use it."""
        c = self.comm
        x = X.getArray(readonly=True)
        new = self.cache["x"] is None or not np.array_equal(self.cache["x"], x)
        if (c.allreduce(int(new)) if c.size > 1 else new):
            u = self.state(gather(X))
            self.cache = {"x": None}
            r, K = self.residual(u)
            self.cache.update(x=x.copy(), u=u, r=np.asarray(r, dtype=float), K=K)
        return self.cache["u"], self.cache["r"], self.cache["K"]

    def start(self, u, mu: float) -> None:
        """A new solve from the state u with the shift mu: the cached evaluation when it is
        u's, else the first evaluation computes r and K at u again (a rejected step's
        evaluation is the last one)."""
        self.base, self.offset, self.mu = u, np.zeros(self.D.size), float(mu)
        if self.cache.get("u") is u:
            self.cache["x"] = np.zeros(self.D.size)
        else:
            self.cache = {"x": None}

    def tangent_at(self, u):
        """The tangent K at the state u: the cached one when the last evaluation was u's."""
        if self.cache.get("u") is u:
            return self.cache["K"]
        return self.residual(u)[1]

    def function(self, snes, X, F) -> None:
        _, r, _ = self.evaluate(X)
        g = r
        if self.mu > 0:
            g = r + self.mu * self.D * (self.offset + X.getArray(readonly=True))
        F.setArray(g)

    def jacobian(self, snes, X, J, P) -> None:
        PETSc = self.backend.PETSc
        _, _, K = self.evaluate(X)
        K.mat.copy(P, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        if self.mu > 0:
            d = P.createVecLeft()
            d.setArray(self.mu * self.D)
            P.setDiagonal(d, addv=PETSc.InsertMode.ADD_VALUES)
            d.destroy()         # petsc4py 3.18 frees a PETSc object on destroy() only
        sym = self.backend._symmetric(K, K.mat)
        P.setOption(PETSc.Mat.Option.SYMMETRIC, sym)
        pc = snes.getKSP().getPC()
        if not sym and pc.getType() == "cholesky":     # the default, for a symmetric tangent
            pc.setType("lu")
            pc.setFactorSolverType("mumps")
            log.debug("SNES: unsymmetric tangent, MUMPS LU")
        P.assemble()

    def release(self) -> None:
        """Drop the model's callbacks and matrices: the SNES, kept by the backend with its
        factorisation, holds this object through its callbacks, and must not keep the model
        (its assembler, whose lifetime ends the factorisation's: a coarse level of a mesh
        sequencing) alive."""
        self.residual = self.update = None
        self.cache = {}

    def rebase(self, snes, its: int) -> None:
        """SNESSetUpdate: move the base to the current iterate and the increment to 0."""
        X = snes.getSolution()
        x = X.getArray(readonly=True)
        moved = bool(np.any(x))
        if not (self.comm.allreduce(int(moved)) if self.comm.size > 1 else moved):
            return
        u, _, _ = self.evaluate(X)
        self.base = u
        self.offset = self.offset + x
        self.cache["x"] = np.zeros(x.size)
        X.set(0.0)


def _options_note(backend) -> str:
    """`` with the PETSc options ...``: the solver options in effect besides tmfem's
    defaults (``PETSC_OPTIONS`` and the backend's ``options=``), which a failed solve may
    owe to; empty when there are none."""
    given = {**{k: v for k, v in backend.PETSc.Options().getAll().items()
                if k.startswith(SOLVER_PREFIXES)}, **backend.options}
    if not given:
        return ""
    return " with the PETSc options " + " ".join(
        f"-{k}" + (f" {v}" if v not in (None, "") else "") for k, v in given.items())


def _refuse_mumps_failure(snes, what: str) -> None:
    """Raise the named error of a failed MUMPS factorisation of the SNES' tangent that no
    shift of the continuation can cure (anything but a singular matrix: a workspace that
    ran short, memory, an option this MUMPS cannot honour, :mod:`tmfem.solvers.mumps`)."""
    failure = mumps_failure(snes.getKSP())
    if failure is not None and not is_singular(failure[0]):
        raise mumps_error(*failure, f"{what} (SNES)")


def _mu_scale(K: DistributedMatrix, scale: np.ndarray) -> float:
    """The stiffness-to-mass scale of the shift mu: median |K_ii| over the nonzero diagonal
    entries of the tangent / median of the scale D (whole)."""
    Kd = np.abs(K.diagonal())
    return float(np.median(Kd[Kd > 0]) / np.median(scale)) if np.any(Kd > 0) else 1.0


def snes_equilibrium(backend, residual, energy, u0, *, scale, force_scale, tol: float = 1e-9,
                     max_iter: int = 200, newton_first: bool = False, callback=None,
                     describe=None, what: str = "static solve", update=None):
    """The equilibrium r(u) = 0 of the energy W by SNES solves (module docstring); the
    arguments are those of :func:`tmfem.solvers.trust_region.trust_region_newton` with every
    dof free, the result the fields of its result: ``dict(u, iterations, residual_history,
    mu_history, tangent)``. ``max_iter`` bounds the SNES iterations over all solves."""
    PETSc = backend.PETSc
    comm = backend.comm.tompi4py()
    u = np.asarray(u0, dtype=float) if update is None else u0     # never changed in place
    r, K = residual(u)
    if not isinstance(K, DistributedMatrix):
        raise InputError(f"{what} (SNES): expected the tangent of a distributed assembly "
                         f"(DistributedMatrix), found {type(K).__name__}")
    rows = slice(*K.mat.getOwnershipRange())
    if np.shape(r) != (rows.stop - rows.start,):
        raise InputError(f"{what} (SNES): expected the residual as this rank's rows "
                         f"({rows.stop - rows.start},), found shape {np.shape(r)}")
    scale = np.asarray(scale, dtype=float)
    mu_scale = _mu_scale(K, scale)
    prob = _Problem(backend, residual, u, comm=comm, D=scale[rows].copy(), update=update,
                    first=(r, K))
    del scale
    rn = rows_norm(r, comm)
    W = energy(u)
    mu = 0.0 if newton_first else 1e-3 * mu_scale
    mu_last = MU_NEWTON * mu_scale      # the shift to come back to after a failed Newton solve
    res_hist, mu_hist = [rn], []
    total = 0

    snes = PETSc.SNES().create(comm=backend.comm)
    P = K.mat.duplicate(copy=True)
    F, X = P.createVecs()[1], P.createVecs()[0]
    snes.setFunction(prob.function, F)
    snes.setJacobian(prob.jacobian, P, P)
    snes.setUpdate(prob.rebase)
    snes.setType("newtonls")
    backend._configure(snes.getKSP(), backend._symmetric(K, K.mat))
    pattern = K.pattern
    del K                      # the solve's evaluations hold the tangent (_Problem.evaluate)

    last = {"r": r}            # the residual at the start of the current iteration

    def monitor(s, its, fnorm):
        if its == 0:
            return
        X = s.getSolution()
        uu, rr, _ = prob.evaluate(X)
        rnorm = rows_norm(rr, comm)
        res_hist.append(rnorm)
        mu_hist.append(prob.mu)
        if callback is not None:
            callback(total + its, uu, rnorm, prob.mu, 1.0)
        log.debug("%s SNES it %3d |r| = %.3e N mu = %.3g", what, total + its, rnorm, prob.mu)
        # x is this iteration's step (the update hook zeroes it at each start): a Newton
        # step du = -K^-1 r lowers the energy by -r.du / 2 to second order
        r_start, last["r"] = last["r"], rr
        tiny = abs(0.5 * rows_dot(r_start, X.getArray(readonly=True), comm)) \
            < 1e-11 * max(abs(W), 1e-30)
        if prob.mu == 0.0 and tiny and rnorm > 0.5 * res_hist[-2] \
                and rnorm <= FLOOR_FACTOR * tol * force_scale(uu):
            raise _Floor    # the round-off floor: a Newton step no longer halves |r|
    snes.setMonitor(monitor)

    def solve(mu_step: float, atol: float):
        """One SNES solve from u with the shift mu_step: (state, r, its, reason)."""
        prob.start(u, mu_step)
        last["r"] = r
        # full Newton steps unless -snes_linesearch_type is given (module docstring)
        search = {} if PETSc.Options().hasName("snes_linesearch_type") else \
            {"snes_linesearch_type": "basic"}
        with backend._database({**search, **backend.options}):
            snes.setTolerances(atol=atol, rtol=STEP_RTOL if mu_step > 0 else 0.0, stol=0.0,
                               max_it=max(1, min(STEP_MAX_IT if mu_step > 0 else NEWTON_MAX_IT,
                                                 max_iter - total)))
            set_from_options(snes, f"{what} (SNES)")
            X.set(0.0)
            try:
                snes.solve(None, X)
            except _Floor:
                return (*prob.evaluate(X)[:2], snes.getIterationNumber(), FLOOR)
            except PETSc.Error as exc:
                if (refused := option_error(exc, f"{what} (SNES)")) is not None:
                    raise refused from None
                log.debug("%s: SNES error %s", what, exc.ierr)
                _refuse_mumps_failure(snes, what)
                return None, None, snes.getIterationNumber(), -100
        if snes.getConvergedReason() == PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE:
            _refuse_mumps_failure(snes, what)
        un, rr, _ = prob.evaluate(X)
        log.debug("%s: SNES solve of %d unknowns with mu = %.3g: %s after %d iterations", what,
                  X.getSize(), mu_step,
                  reason_name(PETSc, snes.getConvergedReason()), snes.getIterationNumber())
        return un, rr, snes.getIterationNumber(), snes.getConvergedReason()

    try:
        while True:
            un, rr, its, reason = solve(mu, tol * force_scale(u))
            total += its
            rnn = rows_norm(rr, comm) if un is not None else np.nan
            ok = bool(np.isfinite(rnn))
            if ok and mu == 0.0:
                # converged: by the residual (tmfem's test, or -snes_atol/-snes_rtol given),
                # or on the round-off floor
                if reason == FLOOR or (reason > 0 and reason_name(PETSc, reason).startswith(
                        "CONVERGED_FNORM")):
                    u, r = un, rr
                    break
                if reason > 0 and rnn < rows_norm(r, comm):
                    u, r = un, rr      # stopped on a step test: Newton again from there
                    W = energy(u)
                    if total < max_iter:
                        continue
            elif ok:
                if its == 0 and reason > 0:
                    # the state meets the tolerance already (a loose tol): the final Newton
                    # solve from it, not a harder regularisation of a step that cannot move
                    mu = 0.0
                    continue
                Wn = energy(un)
                if np.isfinite(Wn) and Wn < W:
                    u, r, W = un, rr, Wn
                    mu_last = mu
                    if reason > 0:       # the step's system solved: a longer pseudo time step
                        mu = mu / 8.0 if mu / 8.0 >= MU_NEWTON * mu_scale else 0.0
                    if total >= max_iter:
                        break
                    continue
            # the step failed: regularise harder from the last accepted state (the next
            # solve's first evaluation is u's again, :meth:`_Problem.start`)
            mu = 4.0 * (mu if mu > 0 else mu_last)
            if mu > 1e12 * mu_scale or total >= max_iter:
                note = f" ({describe(u)})" if describe is not None else ""
                rn = rows_norm(r, comm)
                raise ConvergenceError(
                    f"{what}: SNES {reason_name(PETSc, reason)} (expected an equilibrium with "
                    f"|r| <= {tol:g} x force scale, found |r| = {rn:.3e} N "
                    f"after {total} SNES iterations, mu = {mu:.3g}){note}{_options_note(backend)}"
                    f"{floor_hint(rn, force_scale(u), tol)}")
        K = prob.tangent_at(u)
    finally:
        # the SNES, its KSP (MUMPS' analysis of the tangent's pattern) and matrix stay with
        # the backend for the eigen solve about this equilibrium
        ksp = snes.getKSP()
        snes.cancelMonitor()
        backend.adopt(pattern, P, ksp, symmetric=ksp.getPC().getType() == "cholesky", owner=snes)
        prob.release()
        F.destroy()
        X.destroy()
    rn = rows_norm(r, comm)
    if not rn <= FLOOR_FACTOR * tol * force_scale(u):
        note = f" ({describe(u)})" if describe is not None else ""
        raise ConvergenceError(f"{what}: SNES stopped after {total} iterations (max_iter {max_iter}) "
                               f"at |r| = {rn:.3e} N, expected <= {tol:g} x force scale{note}"
                               f"{_options_note(backend)}{floor_hint(rn, force_scale(u), tol)}")
    return dict(u=u, iterations=total, residual_history=res_hist, mu_history=mu_hist, tangent=K)
