"""Gridded LPV state-feedback H-infinity synthesis with rate bounds (eqs. 5.90-5.99, 8.3).

The generalized plant of Figure 8.1 (built by
:func:`~tmfem.control.lpv.generalized_plant.interconnection_8_1`)

    x' = A x + B1 w + B2 u,   p = C1 x + D11 w + D12 u          (eq. 5.90)

is stabilised by u = K(rho) x with ||G_pw|| < gamma when the parameter-dependent
bounded-real LMI of eqs. 5.95-5.96 holds for all rho and rates:

    [[H1, B1, F^T], [B1^T, -gamma I, D11^T], [F, D11, -gamma I]] < 0,
    H1 = A P + B2 Q + (A P + B2 Q)^T - dP/dt,   F = C1 P + D12 Q,   P(rho) > 0,

with P(rho) = P_0 + rho_1 P_1 + rho_2 P_2, Q likewise (eq. 5.99) and K = Q P^-1. It is
imposed at every grid point (the gridding of 8.3) and, since dP/dt = sum_k rho_k' P_k is
affine in the rates, at every vertex of the rate box. gamma is minimised with cvxpy
(Clarabel, SCS as fallback) on a sparse conic program built here.

Scaling: each parameter enters normalised, rho_n = (rho - c) / h with c the centre and h the
half-width of its grid (the same affine span as eq. 5.99, so the same optimum), and the
states are scaled by a diagonal T (x = T x_s, the balancing of A at the grid centre) so that
angles, positions and membrane deflections have comparable magnitudes; P, Q are returned
in the original coordinates.
"""
from __future__ import annotations

import logging
import time

import numpy as np
import scipy.sparse as sp

from tmfem.control.lpv.coordinates import Coordinates, Tm_back, accepted_design
from tmfem.control.lpv.cost import check_lpvsyn_cost, conic_cost
from tmfem.control.lpv.eigopt import feasible_point
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.errors import InfeasibleController, InputError
from tmfem.resources import MAX_SYNTHESIS_S

log = logging.getLogger(__name__)


def _triangle(N: int, solver: str):
    """Row indices (column-major vec of an N x N matrix) and scale of the svec of the PSD
    cone: Clarabel's upper triangle by columns, SCS's lower triangle by columns; off-diagonal
    entries times sqrt(2)."""
    jj, ii = np.meshgrid(np.arange(N), np.arange(N), indexing="ij")   # column j, row i
    keep = (ii >= jj) if solver == "SCS" else (ii <= jj)
    i, j = ii[keep], jj[keep]                                          # column-major order
    return i + j * N, np.where(i == j, 1.0, np.sqrt(2.0))


def _embed(G: sp.coo_matrix, r0: int, c0: int, rows: int, N: int, transpose: bool = False):
    """Move the vec rows of a (rows x cols) block (entry (i, j) at i + j rows) to the vec of
    an N x N matrix at offset (r0, c0), or of its transpose at (c0, r0)."""
    G = G.tocoo()
    i, j = G.row % rows, G.row // rows
    r, c = (c0 + j, r0 + i) if transpose else (r0 + i, c0 + j)
    return sp.coo_matrix((G.data, (r + c * N, G.col)), shape=(N * N, G.shape[1]))


def _sym_basis(n: int) -> sp.csr_matrix:
    """S with vec(P) = S p for the upper-triangle entries p of a symmetric n x n P."""
    a, b = np.triu_indices(n)
    t = np.arange(a.size)
    rows = np.concatenate([a + b * n, (b + a * n)[a != b]])
    cols = np.concatenate([t, t[a != b]])
    return sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(n * n, a.size))


def synthesize_state_feedback(gp: GeneralizedLPV, *, solver: str = "CLARABEL", margin: float = 1e-6,
                              scale: bool = True, accuracy: float = 1e-5,
                              max_iter: int | None = None, gamma: float | None = None,
                              sample_time: float | None = None,
                              time_budget: float = MAX_SYNTHESIS_S) -> LPVStateFeedback:
    """Minimise gamma subject to eqs. 5.95-5.96 at every grid point and rate vertex (8.3).

    The LMIs are written directly as a sparse conic program (vec(M) = vec(M_0) + G x with
    Kronecker products: vec(A P) = (I kron A) vec(P)) and handed to Clarabel or SCS through
    their own interfaces: cvxpy's canonicalisation of the products A P ran out of memory on
    the 2-3 plant (71 states, 2 x 2 grid; docs/guides/lpv.md).

    Parameters
    ----------
    solver : {"CLARABEL", "SCS", "EIGOPT"}
        Interior-point Clarabel (accurate, memory grows with the square of each LMI's svec
        size) or first-order SCS; when Clarabel fails or is inaccurate, SCS is tried.
        "EIGOPT": a feasible point at the given ``gamma`` by eigenvalue optimisation
        (:mod:`tmfem.control.lpv.eigopt`; for plants too large for the conic solvers),
        accepted only when every re-computed LMI is negative.
    gamma : float, optional
        The fixed level of "EIGOPT" (required there, refused by the other solvers).
    sample_time : float, optional
        "EIGOPT" only: also the stability of the frozen loops sampled at this zero-order-hold
        step (:class:`tmfem.control.lpv.eigopt.EigOpt`).
    margin : float
        Strictness: LMI <= -margin I and P >= margin I (in the scaled coordinates).
    scale : bool
        Diagonal state scaling (module docstring).
    accuracy : float
        Largest accepted LMI eigenvalue re-computed from the solution (scaled coordinates);
        above it the solve is "inaccurate".
    time_budget : float
        "CLARABEL", "SCS": the longest solve started [CPU s]: the program's estimate
        (:func:`~tmfem.control.lpv.cost.conic_cost`, logged before the build) must stay below it
        and below this machine's memory limit.

    Raises
    ------
    ResourceLimit
        The estimate over ``time_budget`` or the memory limit, before anything is built.
    InfeasibleController
        Infeasible, unbounded or inaccurate solve (status and residuals in the message).
    """
    if solver not in ("CLARABEL", "SCS", "EIGOPT"):
        raise InputError(f"solver: expected 'CLARABEL', 'SCS' or 'EIGOPT', found {solver!r}")
    if (gamma is None) == (solver == "EIGOPT"):
        raise InputError(f"gamma: expected a fixed level with solver EIGOPT only, found gamma = {gamma!r} "
                         f"with solver {solver}")
    if sample_time is not None and (solver != "EIGOPT" or not (np.isfinite(sample_time) and sample_time > 0)):
        raise InputError(f"sample_time: expected a step > 0 with solver EIGOPT only, found {sample_time!r} "
                         f"with solver {solver}")
    t0 = time.perf_counter()
    co = Coordinates.of(gp, scale=scale)
    shp, T, center, half, varying, verts, sizes = (co.grid_shape, co.T, co.center, co.half, co.varying,
                                                    co.verts, co.sizes)
    n, nw, nu, npp = (gp.sizes[k] for k in ("n_x", "n_w", "n_u", "n_p"))
    N = n + nw + npp
    Ti = 1.0 / T
    nb = 1 + len(varying)
    S = _sym_basis(n)
    ms, mq = S.shape[1], nu * n
    nvar = sizes["decision_variables"]
    In = sp.identity(n, format="csr")
    log.info("LPV synthesis: %s", sizes)
    if solver != "EIGOPT":
        cost = conic_cost(sizes, solver=solver)
        log.info("LPV synthesis: estimate of the %s solve: %s", solver, cost.text)
        check_lpvsyn_cost(cost, what=f"LPV state-feedback synthesis ({solver}): {n} states, {sizes['grid_points']} "
                                     f"grid points x {len(verts)} rate vertices",
                          time_limit=time_budget, lifted_by="time_budget, `tmfem control lpv --time-budget`")
    if solver == "EIGOPT":
        t1 = time.perf_counter()
        Ps, Qs, _, nev = feasible_point(gp, gamma, T=T, c_of=co.c_of, dvs=co.dvs, max_iter=max_iter or 150,
                                        sample_time=sample_time)
        return co.accepted(gp, Ps, Qs, gamma, solver="EIGOPT", status=f"feasible point ({nev} evaluations)",
                           solve=time.perf_counter() - t1, build=t1 - t0, sample_time=sample_time)

    def pcol(k):
        return k * (ms + mq)

    def place(block: sp.spmatrix, col0: int):
        B = block.tocoo()
        return sp.coo_matrix((B.data, (B.row, B.col + col0)), shape=(B.shape[0], nvar))

    lmi_parts = []          # (G, m0) per LMI, solver independent
    psd_parts = []
    for idx in np.ndindex(*shp):
        rho = np.array([a[i] for a, i in zip(gp.axes, idx)])
        c = np.concatenate([[1.0], ((rho - center) / half)[varying]])
        A = Ti[:, None] * gp.A[idx] * T[None, :]
        B1 = Ti[:, None] * gp.B1[idx]
        B2 = Ti[:, None] * gp.B2[idx]
        C1 = gp.C1[idx] * T[None, :]
        D11, D12 = gp.D11[idx], gp.D12[idx]
        LA = (sp.kron(In, sp.csr_matrix(A)) + sp.kron(sp.csr_matrix(A), In)) @ S     # A P + P A^T
        LB = sp.kron(In, sp.csr_matrix(B2))                                           # B2 Q
        LC = sp.kron(In, sp.csr_matrix(C1)) @ S                                       # C1 P
        LD = sp.kron(In, sp.csr_matrix(D12))                                          # D12 Q
        fixed = []
        for k in range(nb):
            fixed += [_embed(place(c[k] * LA, pcol(k)), 0, 0, n, N),
                      _embed(place(c[k] * LB, pcol(k) + ms), 0, 0, n, N),
                      _embed(place(c[k] * LB, pcol(k) + ms), 0, 0, n, N, transpose=True),
                      _embed(place(c[k] * LC, pcol(k)), n + nw, 0, npp, N),
                      _embed(place(c[k] * LC, pcol(k)), n + nw, 0, npp, N, transpose=True),
                      _embed(place(c[k] * LD, pcol(k) + ms), n + nw, 0, npp, N),
                      _embed(place(c[k] * LD, pcol(k) + ms), n + nw, 0, npp, N, transpose=True)]
        d = np.arange(n, N)
        fixed.append(sp.coo_matrix((-np.ones(d.size), (d + d * N, np.full(d.size, nvar - 1))),
                                   shape=(N * N, nvar)))
        Gfix = sp.csr_matrix(sum(f.tocsr() for f in fixed))
        M0 = np.zeros((N, N))
        M0[:n, n:n + nw] = B1
        M0[n:n + nw, :n] = B1.T
        M0[n + nw:, n:n + nw] = D11
        M0[n:n + nw, n + nw:] = D11.T
        for v in verts:
            G = Gfix
            for j, k in enumerate(varying):
                if v[k] != 0:
                    G = G - _embed(place((v[k] / half[k]) * S, pcol(1 + j)), 0, 0, n, N).tocsr()
            lmi_parts.append((G, M0))
        Pmap = sum(place(c[k] * S, pcol(k)).tocsr() for k in range(nb))
        psd_parts.append(Pmap)
    build = time.perf_counter() - t0
    scale_data = 1.0
    tries = [solver] + (["SCS"] if solver == "CLARABEL" else [])
    last = None
    qobj = np.zeros(nvar)
    qobj[-1] = 1.0
    for s in tries:
        rows_tri, sc = _triangle(N, s)
        rows_p, scp = _triangle(n, s)
        As, bs = [], []
        for G, M0 in lmi_parts:            # -M(x) - margin I in the PSD cone: s = b - A x
            As.append(sp.diags(sc) @ G[rows_tri])
            bs.append(sc * (-M0 - margin * np.eye(N)).ravel(order="F")[rows_tri])
        for Pm in psd_parts:               # P(x) - margin I in the PSD cone
            As.append(-(sp.diags(scp) @ Pm[rows_p]))
            bs.append(-scp * (margin * np.eye(n)).ravel(order="F")[rows_p])
        # gamma >= 0
        As.append(sp.csr_matrix(([-1.0], ([0], [nvar - 1])), shape=(1, nvar)))
        bs.append(np.zeros(1))
        Acon = sp.vstack(As, format="csc")
        bcon = np.concatenate(bs)
        t1 = time.perf_counter()
        x, status = _solve_conic(s, qobj, Acon, bcon, cones=(len(lmi_parts), N, len(psd_parts), n),
                                 max_iter=max_iter)
        solve = time.perf_counter() - t1
        if x is None:
            last = f"{s}: status {status}"
            log.warning("LPV synthesis: %s", last)
            continue
        g = float(x[-1])
        Pv = [Tm_back(_unsym(x[pcol(k):pcol(k) + ms], n), T) for k in range(nb)]
        Qv = [x[pcol(k) + ms:pcol(k) + ms + mq].reshape(nu, n, order="F") * T[None, :] for k in range(nb)]
        try:
            return accepted_design(gp, Pv, Qv, g, T, verts, center, half, varying, solver=s, status=status,
                                   solve=solve, build=build, sizes=sizes, tol=accuracy * scale_data)
        except InfeasibleController as exc:
            last = f"{s}: status {status} but {exc}"
            log.warning("LPV synthesis: %s", last)
    raise InfeasibleController(f"LPV state-feedback synthesis (eqs. 5.95-5.96) on a {shp} grid with "
                               f"{len(verts)} rate vertices failed: {last}; expected an optimal, "
                               "accurate solution")


def _unsym(p: np.ndarray, n: int) -> np.ndarray:
    a, b = np.triu_indices(n)
    P = np.zeros((n, n))
    P[a, b] = p
    P[b, a] = p
    return P


def _solve_conic(solver, q, A, b, *, cones, max_iter):
    """min q^T x s.t. b - A x in (n_lmi PSD cones of size N) x (n_p PSD cones of size n) x R+."""
    n_lmi, N, n_p, n = cones
    if solver == "CLARABEL":
        import clarabel
        st = clarabel.DefaultSettings()
        st.verbose = False
        if max_iter:
            st.max_iter = max_iter
        cl = ([clarabel.PSDTriangleConeT(N)] * n_lmi + [clarabel.PSDTriangleConeT(n)] * n_p
              + [clarabel.NonnegativeConeT(1)])
        # the nonnegative row is last: Clarabel takes cones in row order, so put it there
        sol = clarabel.DefaultSolver(sp.csc_matrix((A.shape[1], A.shape[1])), q, A, b, cl, st).solve()
        status = str(sol.status)
        ok = status in ("Solved", "AlmostSolved", "SolverStatus.Solved", "SolverStatus.AlmostSolved")
        return (np.array(sol.x) if ok else None), status
    import scs
    # SCS wants cones in the order: zero, nonnegative, ..., PSD: move the last row first
    m = A.shape[0]
    perm = np.concatenate([[m - 1], np.arange(m - 1)])
    data = {"A": sp.csc_matrix(A[perm]), "b": b[perm], "c": q}
    cone = {"l": 1, "s": [N] * n_lmi + [n] * n_p}
    res = scs.SCS(data, cone, verbose=False, eps_abs=1e-7, eps_rel=1e-7,
                  max_iters=max_iter or 100000).solve()
    status = res["info"]["status"]
    return (res["x"] if status in ("solved", "solved (inaccurate - reached max_iters)") else None), status
