"""Feasible points of the gridded LPV LMIs (eqs. 5.95-5.96) by eigenvalue optimisation, for
problems too large for the interior-point solvers (the 2-3 system: 72 LMIs of size 155, 12142
variables; docs/guides/lpv.md).

With P(rho) = P_0 + rho_1 P_1 + rho_2 P_2 and Q(rho) likewise (eq. 5.99, normalised
parameters), the LMIs M_iv(P, Q) < 0 (grid point i, rate vertex v) and P(rho_i) > 0 hold iff
the largest eigenvalue over all of them is negative. Its smooth upper bound

    f_t = t log sum_{i,v,j} exp(lambda_j(M_iv / s_iv) / t) >= max lambda

(s_iv: each matrix's scale at the start of a level; t -> 0 along ``t_schedule``) is convex in
(P, Q) and minimised by L-BFGS (scipy), with the gradient <Z, dM> in closed form (Z = V diag(w)
V^T from the eigenvectors; d/dP of tr(Z11 (A P + P A^T)) = 2 A^T Z11, and so on), all grid
points and vertices at once (batched ``eigh``, the stack split over ``workers`` threads: numpy's
``eigh`` releases the GIL, so LAPACK's ``syevd`` of different matrices runs on different cores
with one BLAS thread each; about 80 % of an evaluation of the 2-3 LMIs). A level stops as soon
as the largest scaled eigenvalue is below ``-margin``. Starting point: the pointwise
state-feedback solutions (Riccati, :mod:`tmfem.control.linear.hinf_riccati`) P_i = gamma X_i^-1,
Q_i = K_i P_i, fitted affine in rho by least squares, or (continuation in gamma,
:mod:`tmfem.control.lpv.bisect`) the point found at a higher level; coordinates: the diagonal
balancing of the synthesis, then x = L x_b with L L^T the centre point's P_i at the first
level (so P_b ~ I).
This is a feasibility method: failing at a level does not prove the level infeasible.
"""
from __future__ import annotations

import logging
import os
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import ExitStack

import numpy as np
import scipy.linalg as sla
import scipy.optimize as so
from threadpoolctl import threadpool_limits

from tmfem.control.linear.hinf_riccati import game_riccati, state_feedback_gain
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


class _Stop(Exception):
    """Raised inside the objective to end L-BFGS: a feasible point or the deadline."""


def _weighted(V, w, cut: float = 1e-14):
    """V diag(w) V^T over the last axes, from the largest eigenvalues whose weight exceeds
    ``cut`` (``eigh`` sorts them ascending: the last columns)."""
    k = max(int((w > cut).sum(axis=-1).max()), 1)
    Vk = V[..., -k:]
    return (Vk * w[..., None, -k:]) @ Vk.swapaxes(-1, -2)


def _eigh(X, pool, parts: int):
    """``np.linalg.eigh`` of a stack X (..., N, N), split along its leading axis into
    ``parts`` run on the threads of ``pool`` (None: one call); each part is an independent
    batch, so the result is the one of a single call, bit for bit, at one BLAS thread."""
    if pool is None or X.shape[0] < 2:
        return np.linalg.eigh(X)
    w, V = np.empty(X.shape[:-1]), np.empty(X.shape)

    def part(sl):
        w[sl], V[sl] = np.linalg.eigh(X[sl])

    edges = np.linspace(0, X.shape[0], min(parts, X.shape[0]) + 1).astype(int)
    for f in [pool.submit(part, slice(a, b)) for a, b in zip(edges[:-1], edges[1:])]:
        f.result()                                 # re-raises a part's LinAlgError
    return w, V


def zoh(A, B, dt):
    """Zero-order-hold discretisation A_d = e^(A dt), B_d = int_0^dt e^(A s) ds B of stacked
    (A, B) (the exponential of [[A, B], [0, 0]] dt)."""
    n, m = A.shape[-1], B.shape[-1]
    E = np.array([sla.expm(np.block([[a, b], [np.zeros((m, n + m))]]) * dt) for a, b in zip(A, B)])
    return E[:, :n, :n], E[:, :n, n:]


class EigOpt:
    """The LMIs of one gridded generalised plant in balanced coordinates, minimised level by
    level (module docstring).

    Parameters
    ----------
    gp : GeneralizedLPV
    T : (n,) array
        Diagonal state scaling of the synthesis (x = T x_s).
    c_of : callable
        rho -> the coefficients [1, rho_n...] of P_k at a grid point.
    dvs : list of arrays
        The coefficients of P_k in dP/dt at each rate vertex.
    gamma : float
        The first level (its Riccati solutions fix the balancing and the variable scaling).
    sample_time, radius : float, optional
        With a sample time dt, also the discrete Lyapunov LMI of the zero-order-hold loop at
        every grid point, [[-r P, Phi], [Phi^T, -r P]] < 0 with Phi = A_d P + B_d Q
        (A_d = e^(A dt), B_d = int_0^dt e^(A s) ds B2): the frozen sampled loop
        A_d + B_d K has spectral radius < r (a controller sampled at dt must be stable there;
        the continuous LMI of eq. 5.95 does not bound the gain).
    balance_on : (P_k, Q_k), optional
        Coefficients (coordinates x = T x_s) whose values at the grid points replace the
        pointwise Riccati solutions at ``gamma`` for the balancing and the variable scale (a
        given start; the analysis LMI of a loop without control input, whose Riccati equation
        fails numerically for the lightly damped 121-state 2-3 loop: :mod:`tmfem.control.lpv.certificate`).
    points : list of index tuples, optional
        Impose the LMIs at these points of the grid of ``gp`` only (default: every point; the
        cutting-plane refinement of :mod:`tmfem.control.lpv.certificate` imposes the design
        points and the failing points of a finer grid). The balancing uses the listed point
        nearest to the grid centre.
    workers : int, optional
        Threads for the eigendecompositions of :meth:`solve` (default: the cores this process
        may run on; 1: no threads). With more than one, :meth:`solve` limits BLAS to one
        thread per worker.
    """

    def __init__(self, gp, *, T, c_of, dvs, gamma: float, eps: float = 1e-4, sample_time: float | None = None,
                 radius: float = 1.0, balance_on=None, points=None, workers: int | None = None):
        if workers is None:                          # the cores this process may run on
            workers = (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                       else os.cpu_count() or 1)
        if not (isinstance(workers, (int, np.integer)) and workers >= 1):
            raise InputError(f"EIGOPT: expected workers a positive integer, found {workers!r}")
        self.workers, self._pool = int(workers), None
        Ti = 1.0 / T
        self.eps, self.gamma0 = eps, gamma
        shp = gp.grid_shape
        idx = list(np.ndindex(*shp)) if points is None else [tuple(int(i) for i in k) for k in points]
        if not idx or any(len(k) != len(shp) or not all(0 <= i < s for i, s in zip(k, shp)) for k in idx):
            raise InputError(f"EIGOPT: expected points as index tuples of the {shp} grid, found {points!r}")
        self.c = np.array([c_of(np.array([a[i] for a, i in zip(gp.axes, k)])) for k in idx])
        self.A = np.array([Ti[:, None] * gp.A[k] * T[None, :] for k in idx])
        self.B1 = np.array([Ti[:, None] * gp.B1[k] for k in idx])
        self.B2 = np.array([Ti[:, None] * gp.B2[k] for k in idx])
        self.C1 = np.array([gp.C1[k] * T[None, :] for k in idx])
        self.D11 = np.array([gp.D11[k] for k in idx])
        self.D12 = np.array([gp.D12[k] for k in idx])
        self.dvs = np.array(dvs, dtype=float)
        if balance_on is None:
            Pi, Qi = self._riccati(gamma)
        else:
            Pi, Qi = (np.einsum("ik,kab->iab", self.c, np.asarray(X, dtype=float)) for X in balance_on)
        mid = np.array([k // 2 for k in shp])
        L = np.linalg.cholesky(Pi[int(np.argmin([np.abs(np.array(k) - mid).sum() for k in idx]))])
        Li = np.linalg.inv(L)
        self.L = L
        self.A, self.B1, self.B2 = Li @ self.A @ L, Li @ self.B1, Li @ self.B2
        self.C1 = self.C1 @ L
        self.radius = float(radius)
        self.Ad = self.Bd = None
        if sample_time is not None:                 # zero-order hold of (A, B2), balanced
            self.Ad, self.Bd = zoh(self.A, self.B2, sample_time)
        self._Pi, self._Qi = Li @ Pi @ Li.T, Qi @ Li.T
        n, nu = self.A.shape[-1], self.B2.shape[-1]
        self.nb, self.n, self.nu = self.c.shape[1], n, nu
        P0, Q0 = self._fit(self._Pi, self._Qi)
        self.nP = P0.size
        self.sig = np.concatenate([np.full(P0.size, max(np.abs(P0).max(), 1e-300)),
                                   np.full(Q0.size, max(np.abs(Q0).max(initial=0.0), 1e-300))])
        self.evaluations = 0

    # ------------------------------------------------------------------ start points
    def _riccati(self, gamma):
        Pi, Qi = [], []
        for args in zip(self.A, self.B1, self.B2, self.C1, self.D11, self.D12):
            X = game_riccati(*args, gamma, eps=self.eps)
            if X is None or gamma <= np.linalg.norm(args[4], 2):
                raise InfeasibleController(
                    f"LPV eigenvalue optimisation: expected gamma = {gamma:.4g} above every grid "
                    "point's state-feedback optimum, found a point below (see the pointwise bound, "
                    "tmfem.control.lpv.bounds)")
            Y = gamma * np.linalg.inv(X)
            Y = (Y + Y.T) / 2
            Pi.append(Y)
            Qi.append(state_feedback_gain(*args, gamma, eps=self.eps) @ Y if args[2].shape[1]
                      else np.zeros((0, Y.shape[0])))        # no input: the analysis LMI of a loop
        return np.array(Pi), np.array(Qi)

    def _fit(self, Pi, Qi):
        m = self.c.shape[0]
        P0 = np.linalg.lstsq(self.c, Pi.reshape(m, -1), rcond=None)[0]
        Q0 = np.linalg.lstsq(self.c, Qi.reshape(m, -1), rcond=None)[0]
        return P0.reshape(-1, *Pi.shape[1:]), Q0.reshape(len(P0), *Qi.shape[1:])

    def riccati_start(self, gamma) -> np.ndarray:
        """z of the affine fit of the pointwise Riccati solutions at ``gamma`` (balanced)."""
        Pi, Qi = (self._Pi, self._Qi) if gamma == self.gamma0 else self._riccati(gamma)
        P0, Q0 = self._fit(Pi, Qi)
        return np.concatenate([P0.ravel(), Q0.ravel()]) / self.sig

    def start_from(self, P, Q) -> np.ndarray:
        """z of given coefficients P_k, Q_k in the coordinates x = T x_s of the synthesis
        (e.g. a design on a sub-grid, its missing coefficients zero: continuation in the grid)."""
        Li = np.linalg.inv(self.L)
        Pb = np.array([Li @ Pk @ Li.T for Pk in P])
        Qb = np.array([Qk @ Li.T for Qk in Q])
        if Pb.shape != (self.nb, self.n, self.n) or Qb.shape != (self.nb, self.nu, self.n):
            raise InputError(f"EIGOPT start: expected {self.nb} coefficients P_k ({self.n} x {self.n}) and "
                             f"Q_k ({self.nu} x {self.n}), found shapes {Pb.shape} and {Qb.shape}")
        return np.concatenate([Pb.ravel(), Qb.ravel()]) / self.sig

    # ------------------------------------------------------------------ the LMIs
    def unpack(self, z):
        x = z * self.sig
        S = x[:self.nP].reshape(self.nb, self.n, self.n)
        return (S + S.transpose(0, 2, 1)) / 2, x[self.nP:].reshape(self.nb, self.nu, self.n)

    def matrices(self, z, gamma):
        """The LMIs of eq. 5.95 (grid point, rate vertex, N, N), -P(rho_i) (point, n, n) and
        the discrete Lyapunov LMIs (point, 2n, 2n; None without a sample time)."""
        P, Q = self.unpack(z)
        n, nw, npp = self.n, self.B1.shape[-1], self.C1.shape[-2]
        Pr, Qr = np.einsum("ik,kab->iab", self.c, P), np.einsum("ik,kab->iab", self.c, Q)
        APBQ = self.A @ Pr + self.B2 @ Qr
        F = self.C1 @ Pr + self.D12 @ Qr
        m, N = Pr.shape[0], n + nw + npp
        base = np.zeros((m, N, N))
        base[:, :n, :n] = APBQ + APBQ.transpose(0, 2, 1)
        base[:, :n, n:n + nw] = self.B1
        base[:, n:n + nw, :n] = self.B1.transpose(0, 2, 1)
        base[:, n + nw:, :n] = F
        base[:, :n, n + nw:] = F.transpose(0, 2, 1)
        base[:, n + nw:, n:n + nw] = self.D11
        base[:, n:n + nw, n + nw:] = self.D11.transpose(0, 2, 1)
        d = np.arange(n, N)
        base[:, d, d] = -gamma
        M = np.repeat(base[:, None], len(self.dvs), axis=1)
        M[:, :, :n, :n] -= np.einsum("jk,kab->jab", self.dvs, P)[None]
        if self.Ad is None:
            return M, -Pr, None
        Phi = self.Ad @ Pr + self.Bd @ Qr
        D = np.zeros((m, 2 * n, 2 * n))
        D[:, :n, :n] = D[:, n:, n:] = -self.radius * Pr
        D[:, :n, n:] = Phi
        D[:, n:, :n] = Phi.transpose(0, 2, 1)
        return M, -Pr, D

    def scales(self, z, gamma, matrices=None) -> tuple:
        """Each matrix's scale at ``z`` (its largest |entry|; None for an absent block): the
        divisors s_iv of the scaled eigenvalues (module docstring), fixed for a level.
        ``matrices``: those of :meth:`matrices` at (z, gamma) when already computed."""
        return tuple(None if X is None else np.maximum(np.abs(X).max(axis=(-2, -1)), 1e-300)
                     for X in (self.matrices(z, gamma) if matrices is None else matrices))

    def largest(self, z, gamma, scale=None) -> float:
        """The largest scaled eigenvalue over every LMI at ``z`` (``scale``: default
        :meth:`scales` at ``z`` itself)."""
        Ms = self.matrices(z, gamma)
        if scale is None:
            scale = self.scales(z, gamma, Ms)
        return float(max(np.linalg.eigvalsh(X / s[..., None, None])[..., -1].max()
                         for X, s in zip(Ms, scale) if X is not None))

    def _fg(self, z, t, gamma, scale, margin, deadline, found):
        self.evaluations += 1
        M, Pn, D = self.matrices(z, gamma)
        try:
            lm, Vm = _eigh(M / scale[0][..., None, None], self._pool, self.workers)
            lp, Vp = _eigh(Pn / scale[1][:, None, None], self._pool, self.workers)
            ld, Vd = _eigh(D / scale[2][:, None, None], self._pool, self.workers) if D is not None else (None, None)
        except np.linalg.LinAlgError:                   # a line-search trial far out: rejected
            return np.inf, np.zeros_like(z)
        top = max(lm[..., -1].max(), lp[:, -1].max(), -np.inf if ld is None else ld[:, -1].max())
        if margin is not None and top < -margin:
            found.append(z.copy())
            raise _Stop("feasible")
        if deadline is not None and time.perf_counter() > deadline:
            raise _Stop("time")
        wm, wp = np.exp((lm - top) / t), np.exp((lp - top) / t)
        wd = None if ld is None else np.exp((ld - top) / t)
        tot = wm.sum() + wp.sum() + (0.0 if wd is None else wd.sum())
        Zm, Zp = _weighted(Vm, wm / tot) / scale[0][..., None, None], _weighted(Vp, wp / tot) / scale[1][:, None, None]
        n, nw = self.n, self.B1.shape[-1]
        Z11, Z31 = Zm[..., :n, :n], Zm[..., n + nw:, :n]
        S11, S31 = Z11.sum(axis=1), Z31.sum(axis=1)                  # over the rate vertices
        AT = self.A.transpose(0, 2, 1)
        gP = (np.einsum("ik,iab->kab", self.c, 2 * AT @ S11 + 2 * self.C1.transpose(0, 2, 1) @ S31 - Zp)
              - np.einsum("jk,jab->kab", self.dvs, Z11.sum(axis=0)))
        gQ = np.einsum("ik,iab->kab", self.c, 2 * self.B2.transpose(0, 2, 1) @ S11
                       + 2 * self.D12.transpose(0, 2, 1) @ S31)
        if wd is not None:        # <Z, dD> = <-r (Z11 + Z22) + 2 A_d^T Z12, dP> + <2 B_d^T Z12, dQ>
            Zd = _weighted(Vd, wd / tot) / scale[2][:, None, None]
            Z12 = Zd[:, :n, n:]
            gP += np.einsum("ik,iab->kab", self.c, -self.radius * (Zd[:, :n, :n] + Zd[:, n:, n:])
                            + 2 * self.Ad.transpose(0, 2, 1) @ Z12)
            gQ += np.einsum("ik,iab->kab", self.c, 2 * self.Bd.transpose(0, 2, 1) @ Z12)
        g = np.concatenate([((gP + gP.transpose(0, 2, 1)) / 2).ravel(), gQ.ravel()])
        return top + t * np.log(tot), g * self.sig

    def solve(self, gamma, z, *, t_schedule=(1e-3, 1e-4, 3e-5), max_iter: int = 150,
              margin: float | None = None, deadline: float | None = None):
        """Minimise the largest scaled eigenvalue at ``gamma`` from ``z``.

        Returns (z, largest scaled eigenvalue, reason): reason "feasible" (below -margin),
        "time" (``deadline``, a ``time.perf_counter`` value, passed) or "done" (the schedule
        ran out; the eigenvalue says whether the point is feasible)."""
        t0 = time.perf_counter()
        scale = self.scales(z, gamma)
        worst = self.largest(z, gamma, scale)
        log.info("LPV eigenvalue optimisation at gamma = %.5g: start, largest scaled eigenvalue %.3e",
                 gamma, worst)
        reason = "done"
        with ExitStack() as threads:
            if self.workers > 1:
                self._pool = threads.enter_context(ThreadPoolExecutor(self.workers))
                threads.enter_context(threadpool_limits(limits=1, user_api="blas"))
                threads.callback(setattr, self, "_pool", None)
            for t in t_schedule:
                if worst < (-margin if margin is not None else 0.0):
                    reason = "feasible"
                    break
                found = []
                try:
                    z = so.minimize(self._fg, z, args=(t, gamma, scale, margin, deadline, found), jac=True,
                                    method="L-BFGS-B",
                                    options=dict(maxiter=max_iter, maxcor=30, gtol=1e-14, ftol=1e-14)).x
                except _Stop as stop:
                    reason = str(stop)
                    z = found[0] if found else z
                worst = self.largest(z, gamma, scale)
                log.info("LPV eigenvalue optimisation: t = %g, largest scaled eigenvalue %.3e (%d evaluations, "
                         "%.1f s)", t, worst, self.evaluations, time.perf_counter() - t0)
                if reason != "done":
                    break
        return z, float(worst), reason

    def coefficients(self, z):
        """P_k, Q_k in the coordinates x = T x_s of the synthesis."""
        P, Q = self.unpack(z)
        return [self.L @ Pk @ self.L.T for Pk in P], [Qk @ self.L.T for Qk in Q]


def feasible_point(gp, gamma: float, *, T, c_of, dvs, t_schedule=(1e-3, 1e-4, 3e-5),
                   max_iter: int = 150, eps: float = 1e-4, sample_time: float | None = None):
    """(P_k, Q_k) in the coordinates x = T x_s of the synthesis (diagonal T), the largest
    scaled eigenvalue of the LMIs there and the number of function evaluations, from the
    Riccati start at one fixed ``gamma`` (the full ``t_schedule``, no early stop)."""
    e = EigOpt(gp, T=T, c_of=c_of, dvs=dvs, gamma=gamma, eps=eps, sample_time=sample_time)
    z, worst, _ = e.solve(gamma, e.riccati_start(gamma), t_schedule=t_schedule, max_iter=max_iter)
    P, Q = e.coefficients(z)
    return P, Q, worst, e.evaluations
