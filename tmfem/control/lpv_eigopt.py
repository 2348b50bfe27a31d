"""A feasible point of the gridded LPV LMIs (eqs. 5.95-5.96) at a fixed gamma by eigenvalue
optimisation, for problems too large for the interior-point solvers (the 2-3 system: 72 LMIs of
size 155, 12142 variables; docs/lpv.md).

With P(rho) = P_0 + rho_1 P_1 + rho_2 P_2 and Q(rho) likewise (eq. 5.99, normalised
parameters), the LMIs M_iv(P, Q) < 0 (grid point i, rate vertex v) and P(rho_i) > 0 hold iff
the largest eigenvalue over all of them is negative. Its smooth upper bound

    f_t = t log sum_{i,v,j} exp(lambda_j(M_iv / s_iv) / t) >= max lambda

(s_iv: each matrix's scale at the start; t -> 0 along ``t_schedule``) is convex in (P, Q) and
minimised by L-BFGS (scipy), with the gradient <Z, dM> in closed form (Z = V diag(w) V^T from
the eigenvectors; d/dP of tr(Z11 (A P + P A^T)) = 2 A^T Z11, and so on). Starting point: the
pointwise state-feedback solutions (Riccati, :mod:`tmfem.control.hinf_are`) P_i = gamma
X_i^-1, Q_i = K_i P_i, fitted affine in rho by least squares; coordinates: the diagonal
balancing of the synthesis, then x = L x_b with L L^T the centre point's P_i (so P_b ~ I).
This is a feasibility method, not a gamma minimisation: the result is accepted only when every
LMI re-computed in floating point is negative (the caller verifies off the grid as for any
other solver).
"""
from __future__ import annotations

import logging
import time

import numpy as np
import scipy.optimize as so

from tmfem.control.hinf_are import game_riccati, state_feedback_gain
from tmfem.errors import InfeasibleController

log = logging.getLogger(__name__)


def _points(gp, T, c_of):
    Ti = 1.0 / T
    out = []
    for idx in np.ndindex(*gp.grid_shape):
        rho = np.array([a[i] for a, i in zip(gp.axes, idx)])
        out.append(dict(c=c_of(rho), A=Ti[:, None] * gp.A[idx] * T[None, :], B1=Ti[:, None] * gp.B1[idx],
                        B2=Ti[:, None] * gp.B2[idx], C1=gp.C1[idx] * T[None, :], D11=gp.D11[idx],
                        D12=gp.D12[idx]))
    return out


def _start(pts, gamma, eps, centre: int):
    """Pointwise Riccati solutions at gamma, the balancing L and the affine fit (balanced)."""
    Pi, Qi = [], []
    for p in pts:
        args = (p["A"], p["B1"], p["B2"], p["C1"], p["D11"], p["D12"])
        X = game_riccati(*args, gamma, eps=eps)
        if X is None or gamma <= np.linalg.norm(p["D11"], 2):
            raise InfeasibleController(f"LPV eigenvalue optimisation: expected gamma = {gamma:.4g} above "
                                       "every grid point's state-feedback optimum, found a point below "
                                       "(see the pointwise bound, tmfem.control.lpv_bounds)")
        Y = gamma * np.linalg.inv(X)
        Y = (Y + Y.T) / 2
        Pi.append(Y)
        Qi.append(state_feedback_gain(*args, gamma, eps=eps) @ Y)
    L = np.linalg.cholesky(Pi[centre])
    Li = np.linalg.inv(L)
    for p in pts:
        p["A"], p["B1"], p["B2"], p["C1"] = Li @ p["A"] @ L, Li @ p["B1"], Li @ p["B2"], p["C1"] @ L
    C = np.array([p["c"] for p in pts])
    n, nu = Pi[0].shape[0], Qi[0].shape[0]
    P0 = np.linalg.lstsq(C, np.array([Li @ P @ Li.T for P in Pi]).reshape(len(pts), -1), rcond=None)[0]
    Q0 = np.linalg.lstsq(C, np.array([Q @ Li.T for Q in Qi]).reshape(len(pts), -1), rcond=None)[0]
    return L, P0.reshape(-1, n, n), Q0.reshape(-1, nu, n)


def _matrices(pts, dvs, P, Q, gamma):
    """(kind, point, vertex, matrix): the LMIs of eq. 5.95 at every point and vertex, and -P_i."""
    nw, npp = pts[0]["B1"].shape[1], pts[0]["C1"].shape[0]
    n = P.shape[1]
    out = []
    for i, p in enumerate(pts):
        Pr, Qr = np.tensordot(p["c"], P, 1), np.tensordot(p["c"], Q, 1)
        APBQ = p["A"] @ Pr + p["B2"] @ Qr
        F = p["C1"] @ Pr + p["D12"] @ Qr
        base = np.block([[APBQ + APBQ.T, p["B1"], F.T], [p["B1"].T, -gamma * np.eye(nw), p["D11"].T],
                         [F, p["D11"], -gamma * np.eye(npp)]])
        for j, d in enumerate(dvs):
            M = base.copy()
            M[:n, :n] -= np.tensordot(d, P, 1)
            out.append(("lmi", i, j, M))
        out.append(("pos", i, None, -Pr))
    return out


def feasible_point(gp, gamma: float, *, T, c_of, dvs, t_schedule=(1e-3, 1e-4, 3e-5),
                   max_iter: int = 150, eps: float = 1e-4):
    """(P_k, Q_k) in the coordinates x = T x_s of the synthesis (diagonal T), the largest
    scaled eigenvalue of the LMIs there and the number of function evaluations.

    ``c_of(rho)`` gives the coefficients [1, rho_n...] of P_k at a grid point, ``dvs`` the
    coefficients of P_k in dP/dt at each rate vertex.
    """
    t0 = time.perf_counter()
    pts = _points(gp, T, c_of)
    shp = gp.grid_shape
    L, P0, Q0 = _start(pts, gamma, eps, int(np.ravel_multi_index(tuple(k // 2 for k in shp), shp)))
    nb, n, nu = P0.shape[0], P0.shape[1], Q0.shape[1]
    nP = nb * n * n
    ms = _matrices(pts, dvs, P0, Q0, gamma)
    scale = np.array([max(np.abs(M).max(), 1e-300) for *_, M in ms])
    sig = np.concatenate([np.full(nP, max(np.abs(P0).max(), 1e-300)),
                          np.full(Q0.size, max(np.abs(Q0).max(), 1e-300))])
    nev = [0]

    def unpack(z):
        x = z * sig
        S = x[:nP].reshape(nb, n, n)
        return (S + S.transpose(0, 2, 1)) / 2, x[nP:].reshape(nb, nu, n)

    def largest(z):
        return max(np.linalg.eigvalsh(M / s)[-1] for (*_, M), s in zip(_matrices(pts, dvs, *unpack(z), gamma), scale))

    def fg(z, t):
        nev[0] += 1
        P, Q = unpack(z)
        ms = _matrices(pts, dvs, P, Q, gamma)
        try:
            eig = [np.linalg.eigh(M / s) for (*_, M), s in zip(ms, scale)]
        except np.linalg.LinAlgError:                   # a line-search trial far out: rejected
            return np.inf, np.zeros_like(z)
        top = max(e[0][-1] for e in eig)
        tot = sum(np.exp((e[0] - top) / t).sum() for e in eig)
        gP, gQ = np.zeros_like(P), np.zeros_like(Q)
        for (kind, i, j, _), s, (lam, V) in zip(ms, scale, eig):
            w = np.exp((lam - top) / t) / tot
            k = w > 1e-14
            if not k.any():
                continue
            Z = (V[:, k] * w[k]) @ V[:, k].T / s
            p = pts[i]
            if kind == "pos":
                gP -= p["c"][:, None, None] * Z[None]
                continue
            nw = p["B1"].shape[1]
            Z11, Z31 = Z[:n, :n], Z[n + nw:, :n]
            gP += (p["c"][:, None, None] * (2 * p["A"].T @ Z11 + 2 * p["C1"].T @ Z31)[None]
                   - dvs[j][:, None, None] * Z11[None])
            gQ += p["c"][:, None, None] * (2 * p["B2"].T @ Z11 + 2 * p["D12"].T @ Z31)[None]
        g = np.concatenate([((gP + gP.transpose(0, 2, 1)) / 2).ravel(), gQ.ravel()])
        return top + t * np.log(tot), g * sig

    z = np.concatenate([P0.ravel(), Q0.ravel()]) / sig
    worst = largest(z)
    log.info("LPV eigenvalue optimisation at gamma = %.4g: start, largest scaled eigenvalue %.3e", gamma, worst)
    for t in t_schedule:
        if worst < 0:
            break
        r = so.minimize(fg, z, args=(t,), jac=True, method="L-BFGS-B",
                        options=dict(maxiter=max_iter, maxcor=30, gtol=1e-14, ftol=1e-14))
        z = r.x
        worst = largest(z)
        log.info("LPV eigenvalue optimisation: t = %g, largest scaled eigenvalue %.3e (%d evaluations, "
                 "%.1f s)", t, worst, nev[0], time.perf_counter() - t0)
    P, Q = unpack(z)
    P = np.array([L @ Pk @ L.T for Pk in P])
    Q = np.array([Qk @ L.T for Qk in Q])
    return list(P), list(Q), float(worst), nev[0]
