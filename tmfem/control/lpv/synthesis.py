"""Gridded LPV state-feedback H-infinity synthesis with rate bounds (eqs. 5.90-5.99, 8.3).

The generalised plant of Figure 8.1 (built by :func:`interconnection_8_1`)

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
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from tmfem.control.lpv.plant import GriddedLPV
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


@dataclass
class GeneralisedLPV:
    """Generalised LPV plant (eq. 5.90) on a grid: x' = A x + B1 w + B2 u, p = C1 x + D11 w + D12 u.

    Arrays have shape ``grid_shape + (rows, cols)``; ``axes``, ``parameter_names`` and
    ``rate_bounds`` as in :class:`~tmfem.control.lpv.plant.GriddedLPV`.
    """

    axes: list
    parameter_names: list
    rate_bounds: np.ndarray
    A: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    C1: np.ndarray
    D11: np.ndarray
    D12: np.ndarray
    state_names: list = field(default_factory=list)

    @property
    def grid_shape(self) -> tuple:
        return tuple(np.size(a) for a in self.axes)

    @property
    def sizes(self) -> dict:
        return {"n_x": self.A.shape[-1], "n_w": self.B1.shape[-1], "n_u": self.B2.shape[-1],
                "n_p": self.C1.shape[-2]}

    def points(self):
        plant = self._as_lpv()
        return plant.points()

    def _as_lpv(self) -> GriddedLPV:
        n = self.A.shape[-1]
        return GriddedLPV(axes=self.axes, parameter_names=self.parameter_names,
                          A=self.A, B=self.B2, C=self.C1, D=self.D12, rate_bounds=self.rate_bounds,
                          state_names=[f"x{i}" for i in range(n)],
                          input_names=[f"u{i}" for i in range(self.B2.shape[-1])],
                          output_names=[f"p{i}" for i in range(self.C1.shape[-2])])

    def rate_vertices(self) -> np.ndarray:
        return self._as_lpv().rate_vertices()

    @classmethod
    def from_matrices(cls, *, axes, parameter_names, rate_bounds, A, B1, B2, C1, D11, D12):
        """From arrays (validated: finite, consistent sizes)."""
        arrs = {k: np.asarray(v, dtype=float) for k, v in
                dict(A=A, B1=B1, B2=B2, C1=C1, D11=D11, D12=D12).items()}
        shape = tuple(np.size(a) for a in axes)
        n, nw, nu, npp = (arrs["A"].shape[-1], arrs["B1"].shape[-1], arrs["B2"].shape[-1],
                          arrs["C1"].shape[-2])
        want = dict(A=(n, n), B1=(n, nw), B2=(n, nu), C1=(npp, n), D11=(npp, nw), D12=(npp, nu))
        for k, v in arrs.items():
            if v.shape != shape + want[k] or not np.all(np.isfinite(v)):
                raise InputError(f"generalised LPV plant: {k} expected shape {shape + want[k]} with "
                                 f"finite entries, found {v.shape}")
        rb = np.asarray(rate_bounds, dtype=float).reshape(len(shape), 2)
        return cls(axes=[np.atleast_1d(np.asarray(a, dtype=float)) for a in axes],
                   parameter_names=list(parameter_names), rate_bounds=rb, **arrs)


def interconnection_8_1(plant: GriddedLPV, *, tracked, W_e: float = 0.5, W_u: float = 0.05,
                        W_d: float = 0.001) -> GeneralisedLPV:
    """The interconnection of Figure 8.1 with the integral of the tracking error (eq. 5.98).

    Plant x_z' = A x_z + B (u + W_d n_d), q = T_qx x_z (``tracked``: the output names of q;
    their rows of C, eq. 5.18). States x = [x_z; e~_q], e~_q' = e_q = q_d - q (eq. 5.98);
    exogenous w = [q_d; n_d]; regulated p = [e_r; e_u] = [W_e e_q; W_u u]. Weights are
    scalar multiples of I (8.3: W_e = 0.5 I, W_u = 0.05 I, W_d = 0.001 I).
    """
    tracked = list(tracked)
    missing = [t for t in tracked if t not in plant.output_names]
    if missing or not tracked:
        raise InputError(f"interconnection: tracked outputs must be plant outputs, found unknown "
                         f"{missing or 'none given'}")
    for nm, v in (("W_e", W_e), ("W_u", W_u), ("W_d", W_d)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"interconnection: {nm} expected > 0, found {v!r}")
    rows = [plant.output_names.index(t) for t in tracked]
    if np.any(plant.D[..., rows, :] != 0):
        raise InputError("interconnection: tracked outputs must not depend on u directly (D rows nonzero)")
    T = plant.C[..., rows, :]
    shp = plant.grid_shape
    n, m, nq = plant.nx, plant.nu, len(rows)
    Z = lambda r, c: np.zeros(shp + (r, c))            # noqa: E731
    I = lambda k: np.broadcast_to(np.eye(k), shp + (k, k))   # noqa: E731
    A = np.concatenate([np.concatenate([plant.A, Z(n, nq)], -1),
                        np.concatenate([-T, Z(nq, nq)], -1)], -2)
    B1 = np.concatenate([np.concatenate([Z(n, nq), W_d * plant.B], -1),
                         np.concatenate([I(nq), Z(nq, m)], -1)], -2)
    B2 = np.concatenate([plant.B, Z(nq, m)], -2)
    C1 = np.concatenate([np.concatenate([-W_e * T, Z(nq, nq)], -1), Z(m, n + nq)], -2)
    D11 = np.concatenate([np.concatenate([W_e * I(nq), Z(nq, m)], -1), Z(m, nq + m)], -2)
    D12 = np.concatenate([Z(nq, m), W_u * I(m)], -2)
    g = GeneralisedLPV.from_matrices(axes=plant.axes, parameter_names=plant.parameter_names,
                                     rate_bounds=plant.rate_bounds, A=A, B1=B1, B2=B2, C1=C1,
                                     D11=D11, D12=D12)
    g.state_names = list(plant.state_names) + [f"int_e_{t}" for t in tracked]
    return g


@dataclass
class LPVStateFeedback:
    """Result of :func:`synthesize_state_feedback`: K(rho) = Q(rho) P(rho)^-1 (eq. 5.99).

    ``P[k]``, ``Q[k]`` (k = 0..n_p) are the coefficients in the normalised parameters
    rho_n = (rho - centre) / half_width (k = 0 the constant term); :meth:`P_of`, :meth:`Q_of`
    and :meth:`gain` evaluate them at a parameter value in the original units.
    """

    gamma: float
    P: list
    Q: list
    centre: np.ndarray
    half_width: np.ndarray
    varying: list
    axes: list
    parameter_names: list
    rate_bounds: np.ndarray
    state_names: list
    solver: str
    status: str
    solve_time: float
    build_time: float
    sizes: dict
    max_lmi_eig: float
    min_P_eig: float

    def _basis(self, rho) -> np.ndarray:
        rho = np.asarray(rho, dtype=float).reshape(-1)
        if rho.size != len(self.centre):
            raise InputError(f"LPV controller: expected {len(self.centre)} parameter values, found {rho.size}")
        return np.concatenate([[1.0], ((rho - self.centre) / self.half_width)[self.varying]])

    def P_of(self, rho) -> np.ndarray:
        """P(rho) (eq. 5.99)."""
        return sum(c * Pk for c, Pk in zip(self._basis(rho), self.P))

    def Q_of(self, rho) -> np.ndarray:
        """Q(rho) (eq. 5.99)."""
        return sum(c * Qk for c, Qk in zip(self._basis(rho), self.Q))

    def gain(self, rho) -> np.ndarray:
        """K(rho) = Q(rho) P(rho)^-1 (8.3)."""
        return sla.solve(self.P_of(rho), self.Q_of(rho).T, assume_a="pos").T

    def summary(self) -> dict:
        return {"gamma": self.gamma, "solver": self.solver, "status": self.status,
                "solve_time_s": self.solve_time, "build_time_s": self.build_time,
                "sizes": self.sizes, "max_lmi_eig": self.max_lmi_eig, "min_P_eig": self.min_P_eig}

    def arrays(self) -> dict:
        """The coefficients, gamma and grid as arrays (the contents of :meth:`save`)."""
        return dict(gamma=self.gamma, P=np.array(self.P), Q=np.array(self.Q), centre=self.centre,
                    half_width=self.half_width, varying=np.isin(np.arange(len(self.centre)), self.varying),
                    rate_bounds=self.rate_bounds, parameter_names=np.array(self.parameter_names),
                    state_names=np.array(self.state_names),
                    **{f"axis_{k}": a for k, a in enumerate(self.axes)})

    def save(self, path) -> None:
        """Write the coefficients, gamma and grid to an ``.npz`` file."""
        np.savez(path, **self.arrays())

    @classmethod
    def load(cls, path) -> "LPVStateFeedback":
        """The coefficients, gamma and grid written by :meth:`save` (sizes and residuals are
        re-computed by whoever uses it: :func:`tmfem.control.lpv.verify.verify`).

        Raises
        ------
        InputError
            Not a file written by :meth:`save`.
        """
        from tmfem.io.npz import read_npz
        d = read_npz(path, expected="an .npz LPV controller written by `tmfem control lpv "
                                    "--save`")
        try:
            keys = ("gamma", "P", "Q", "centre", "half_width", "varying", "rate_bounds",
                    "parameter_names", "state_names")
            f = {k: d[k] for k in keys}
        except (OSError, KeyError, ValueError) as exc:
            raise InputError(f"LPV controller file {str(path)!r}: expected an .npz written by "
                             f"`tmfem control lpv --save` (keys gamma, P, Q, ...), found {exc}") from None
        axes = [d[f"axis_{k}"] for k in range(len(f["parameter_names"]))]
        P, Q = list(f["P"]), list(f["Q"])
        varying = [k for k, a in enumerate(axes) if a.size > 1]      # as in the synthesis
        if len(P) != 1 + len(varying) or len(Q) != len(P):
            raise InputError(f"LPV controller file {str(path)!r}: expected {1 + len(varying)} coefficients "
                             f"P_k, Q_k (eq. 5.99 on its grid), found {len(P)} and {len(Q)}")
        return cls(gamma=float(f["gamma"]), P=P, Q=Q, centre=f["centre"], half_width=f["half_width"],
                   varying=varying, axes=axes,
                   parameter_names=[str(v) for v in f["parameter_names"]], rate_bounds=f["rate_bounds"],
                   state_names=[str(v) for v in f["state_names"]], solver="loaded", status=f"from {path}",
                   solve_time=0.0, build_time=0.0, sizes={"n_x": P[0].shape[0], "coefficients": len(P)},
                   max_lmi_eig=float("nan"), min_P_eig=float("nan"))


def lmi_matrix(*, A, B1, B2, C1, D11, D12, P, Q, dP, gamma) -> np.ndarray:
    """The (symmetric) matrix of eq. 5.95 with H1, F of eq. 5.96 for numeric P, Q, dP, gamma."""
    nw, npp = B1.shape[1], C1.shape[0]
    APBQ = A @ P + B2 @ Q
    H1 = APBQ + APBQ.T - dP
    F = C1 @ P + D12 @ Q
    return np.block([[H1, B1, F.T], [B1.T, -gamma * np.eye(nw), D11.T], [F, D11, -gamma * np.eye(npp)]])


def _state_scaling(A: np.ndarray) -> np.ndarray:
    """Diagonal T (x = T x_s) balancing A (LAPACK gebal, scaling only)."""
    _, (sca, _) = sla.matrix_balance(A, permute=False, separate=True)
    return sca


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


def synthesize_state_feedback(gp: GeneralisedLPV, *, solver: str = "CLARABEL", margin: float = 1e-6,
                              scale: bool = True, accuracy: float = 1e-5,
                              max_iter: int | None = None, gamma: float | None = None,
                              sample_time: float | None = None) -> LPVStateFeedback:
    """Minimise gamma subject to eqs. 5.95-5.96 at every grid point and rate vertex (8.3).

    The LMIs are written directly as a sparse conic program (vec(M) = vec(M_0) + G x with
    Kronecker products: vec(A P) = (I kron A) vec(P)) and handed to Clarabel or SCS through
    their own interfaces: cvxpy's canonicalisation of the products A P ran out of memory on
    the 2-3 plant (71 states, 2 x 2 grid; docs/lpv.md).

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

    Raises
    ------
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
    shp, T, centre, half, varying, verts, sizes = (co.grid_shape, co.T, co.centre, co.half, co.varying,
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
    if solver == "EIGOPT":
        from tmfem.control.lpv.eigopt import feasible_point
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
        c = np.concatenate([[1.0], ((rho - centre) / half)[varying]])
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
        M0[:n, n:n + nw] = B1; M0[n:n + nw, :n] = B1.T
        M0[n + nw:, n:n + nw] = D11; M0[n:n + nw, n + nw:] = D11.T
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
    qobj = np.zeros(nvar); qobj[-1] = 1.0
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
        As.append(sp.csr_matrix(([-1.0], ([0], [nvar - 1])), shape=(1, nvar))); bs.append(np.zeros(1))
        Acon = sp.vstack(As, format="csc"); bcon = np.concatenate(bs)
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
            return _accepted(gp, Pv, Qv, g, T, verts, centre, half, varying, solver=s, status=status,
                             solve=solve, build=build, sizes=sizes, tol=accuracy * scale_data)
        except InfeasibleController as exc:
            last = f"{s}: status {status} but {exc}"
            log.warning("LPV synthesis: %s", last)
    raise InfeasibleController(f"LPV state-feedback synthesis (eqs. 5.95-5.96) on a {shp} grid with "
                               f"{len(verts)} rate vertices failed: {last}; expected an optimal, "
                               "accurate solution")


@dataclass
class Coordinates:
    """The synthesis coordinates of a generalised plant (module docstring): parameters
    normalised to [-1, 1] over the grid (``centre``, ``half``; ``varying``: the parameters
    with more than one grid value), states x = T x_s, the rate vertices and the LMI sizes."""

    grid_shape: tuple
    T: np.ndarray
    centre: np.ndarray
    half: np.ndarray
    varying: list
    verts: np.ndarray
    sizes: dict

    @classmethod
    def of(cls, gp: GeneralisedLPV, *, scale: bool = True) -> "Coordinates":
        shp = gp.grid_shape
        n, nw, nu, npp = (gp.sizes[k] for k in ("n_x", "n_w", "n_u", "n_p"))
        lo = np.array([a[0] for a in gp.axes]); hi = np.array([a[-1] for a in gp.axes])
        varying = [k for k in range(len(shp)) if shp[k] > 1]
        verts = gp.rate_vertices()
        nvar = (1 + len(varying)) * (n * (n + 1) // 2 + nu * n) + 1
        sizes = {"grid_points": int(np.prod(shp)), "rate_vertices": len(verts),
                 "lmis": int(np.prod(shp)) * len(verts), "lmi_size": n + nw + npp, "n_x": n, "n_w": nw,
                 "n_u": nu, "n_p": npp, "decision_variables": nvar}
        return cls(grid_shape=shp, T=_state_scaling(gp.A[tuple(s // 2 for s in shp)]) if scale else np.ones(n),
                   centre=(lo + hi) / 2, half=np.where(hi > lo, (hi - lo) / 2, 1.0), varying=varying,
                   verts=verts, sizes=sizes)

    def c_of(self, rho) -> np.ndarray:
        """The coefficients [1, rho_n...] of P_k in P(rho) (eq. 5.99, normalised rho)."""
        return np.concatenate([[1.0], ((np.asarray(rho) - self.centre) / self.half)[self.varying]])

    @property
    def dvs(self) -> list:
        """The coefficients of P_k in dP/dt at each rate vertex."""
        return [np.concatenate([[0.0], (v / self.half)[self.varying]]) for v in self.verts]

    def accepted(self, gp, Ps, Qs, gamma, *, solver, status, solve, build,
                 sample_time: float | None = None) -> "LPVStateFeedback":
        """:func:`_accepted` (strictly negative LMIs) of P_k, Q_k given in the scaled coordinates;
        with ``sample_time`` also every frozen sampled loop of the grid stable
        (:func:`tmfem.control.lpv.verify.verify`)."""
        T = self.T
        ctrl = _accepted(gp, [Tm_back(P, T) for P in Ps], [Q * T[None, :] for Q in Qs], gamma, T, self.verts,
                         self.centre, self.half, self.varying, solver=solver, status=status, solve=solve,
                         build=build, sizes=self.sizes, tol=-1e-300)
        if sample_time is not None:
            from tmfem.control.lpv.verify import verify
            r = verify(ctrl, gp, sample_time=sample_time, allow_failure=True).max_sampled_radius
            if not r < 1:
                raise InfeasibleController(f"the frozen loops sampled at {sample_time} s have spectral radius "
                                           f"{r:.6f} (expected < 1)")
        return ctrl


def _accepted(gp, Pv, Qv, g, T, verts, centre, half, varying, *, solver, status, solve, build, sizes,
              tol) -> LPVStateFeedback:
    """The result, after re-computing every LMI (eq. 5.95) and P(rho_i) from P_k, Q_k in
    floating point (largest eigenvalue in the scaled coordinates <= ``tol``, P > 0).

    Raises
    ------
    InfeasibleController
        When an LMI or P fails.
    """
    Ti = 1.0 / T
    n, nw, npp = gp.sizes["n_x"], gp.sizes["n_w"], gp.sizes["n_p"]
    worst, minP = -np.inf, np.inf
    for idx in np.ndindex(*gp.grid_shape):
        rho = np.array([a[i] for a, i in zip(gp.axes, idx)])
        c = np.concatenate([[1.0], ((rho - centre) / half)[varying]])
        P = sum(ck * Pk for ck, Pk in zip(c, Pv)); Q = sum(ck * Qk for ck, Qk in zip(c, Qv))
        minP = min(minP, np.linalg.eigvalsh((P * Ti[:, None] * Ti[None, :])).min())
        for v in verts:
            dP = sum((v[k] / half[k]) * Pv[1 + j] for j, k in enumerate(varying)) if varying \
                else np.zeros((n, n))
            M = lmi_matrix(A=gp.A[idx], B1=gp.B1[idx], B2=gp.B2[idx], C1=gp.C1[idx],
                           D11=gp.D11[idx], D12=gp.D12[idx], P=P, Q=Q, dP=dP, gamma=g)
            worst = max(worst, _max_eig_congruent(M, T, nw + npp))
    if not (worst <= tol and minP > 0):
        raise InfeasibleController(f"the LMI re-computed from the solution has largest eigenvalue "
                                   f"{worst:.3e} (expected <= {tol:.3e}) and min eig P {minP:.3e} "
                                   "(expected > 0)")
    log.info("LPV synthesis: gamma = %.6g (%s, %s, %.1f s)", g, solver, status, solve)
    return LPVStateFeedback(gamma=g, P=Pv, Q=Qv, centre=centre, half_width=half, varying=varying,
                            axes=[a.copy() for a in gp.axes], parameter_names=list(gp.parameter_names),
                            rate_bounds=gp.rate_bounds.copy(), state_names=list(gp.state_names),
                            solver=solver, status=status, solve_time=solve, build_time=build,
                            sizes=sizes, max_lmi_eig=float(worst), min_P_eig=float(minP))


def _unsym(p: np.ndarray, n: int) -> np.ndarray:
    a, b = np.triu_indices(n)
    P = np.zeros((n, n)); P[a, b] = p; P[b, a] = p
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
def Tm_back(Ps: np.ndarray, T: np.ndarray) -> np.ndarray:
    """P in original coordinates from the scaled one: x = T x_s  ->  P = T P_s T."""
    return T[:, None] * Ps * T[None, :]


def _max_eig_congruent(M: np.ndarray, T: np.ndarray, n_extra: int) -> float:
    """Largest eigenvalue of diag(T^-1, I) M diag(T^-1, I) (the LMI in the scaled
    coordinates, where the margin is imposed; the sign is that of M)."""
    d = np.concatenate([1.0 / T, np.ones(n_extra)])
    S = d[:, None] * M * d[None, :]
    return float(np.linalg.eigvalsh((S + S.T) / 2).max())
