"""Equilibrium conditions of general systems (dissertation 3.2) and their symmetric reduction (3.3.2).

The membrane corner constraints (eq. 3.5) tie the upper bar ends B_Mi to the floating frame
O_f (3-2-1 Euler angles gamma, eq. 3.3) and the free corner displacements Delta of eq. 3.4:

    B_Mi(q) - B_MN(q) = R^ef(gamma) (P_i + Delta_i),   i = 1, ..., N-1,

with P_i the undeformed corner in O_f and the free components Delta_u1; Delta_ui, Delta_vi,
Delta_wi (2 <= i <= N-2); Delta_u,N-1, Delta_v,N-1 (3N-6 in all). The virtual work of the
tendon forces and the membrane corner forces (eqs. 3.6-3.15) gives the matrix A(q) of eq.
3.16 whose columns are d|d_k|/dq (tendons) and dDelta_c/dq (membrane corner forces, from
implicit differentiation of eq. 3.5, eq. 3.11); rows are the generalised coordinates q of
eqs. 3.1-3.2. All derivatives are analytic.

For symmetric systems the rows of bar b_iN and the column sums over the tendons of each
family and stage, with the membrane column F_Delta (cos beta_i, sin beta_i) of eq. 3.21,
give the (5M-3) x (6M-4) matrix of 3.3.2 acting on the force vector of eq. 3.26.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.newton import newton
from tmfem.system.geometry import (beta, euler_angles_321, free_corner_components,
                                  rotation_ef)
from tmfem.system.coordinates import q_index, q_size
from tmfem.system.topology import FAMILIES_MN


# ---------------------------------------------------------------------------- kinematics
@lru_cache(maxsize=None)
def _lower_end_jacobian(M: int, N: int) -> np.ndarray:
    """dA_ij/dq of the lower bar ends, shape (3, M N, n_q), made once per (M, N) (read-only):
    1 at the coordinates x_ij, y_ij, z_ij of the stages i >= 2 (eq. 3.2), 0 elsewhere."""
    xyz = q_index(M, N)[0].reshape(3, M * N)
    J = np.zeros((3, M * N, q_size(M, N)))
    c, n = np.nonzero(xyz >= 0)
    J[c, n, xyz[c, n]] = 1.0
    J.flags.writeable = False
    return J


def node_jacobian(system, q=None) -> np.ndarray:
    """Derivatives dX/dq of all node coordinates, shape (3, n_nodes, n_q) (eqs. 3.1-3.2).

    dA_ij/dq is 1 at the coordinates of A_ij; B_ij = A_ij + l_ij e(theta_ij, psi_ij) with
    e = (sin theta cos psi, sin theta sin psi, cos theta) gives dB_ij/dq = dA_ij/dq plus
    l_ij de/dtheta_ij and l_ij de/dpsi_ij in the columns of theta_ij and psi_ij; the points
    H_1j of a 1-N(D) system, H = A + k_H (B - A), give dH/dq = dA/dq + k_H (dB/dq - dA/dq).
    """
    q = system.q if q is None else np.asarray(q, dtype=float)
    M, N = system.M, system.N
    _, th, ps = q_index(M, N)
    th, ps = th.ravel(), ps.ravel()
    st, ct, sp, cp = np.sin(q[th]), np.cos(q[th]), np.sin(q[ps]), np.cos(q[ps])
    l = system.l.ravel()
    JA = _lower_end_jacobian(M, N)
    JB = JA.copy()
    bars = np.arange(M * N)
    JB[:, bars, th] += l * np.array([ct * cp, ct * sp, -st])
    JB[:, bars, ps] += l * np.array([-st * sp, st * cp, np.zeros_like(st)])
    parts = [JA, JB]
    if system.deployable:
        parts.append(JA[:, :N] + system.k_H * (JB[:, :N] - JA[:, :N]))
    return np.concatenate(parts, axis=1)


def tendon_length_gradient(system, q=None, J=None) -> np.ndarray:
    """d|d_k|/dq of every tendon, shape (n_q, n_tendons) (the tendon columns of eq. 3.16):
    n_k . (dX_end/dq - dX_start/dq) with n_k = d_k / |d_k|. ``J``: the node Jacobian of
    :func:`node_jacobian` at q when the caller has it."""
    J = node_jacobian(system, q) if J is None else J
    d = system.tendon_vectors(q)
    L = np.linalg.norm(d, axis=0)
    if np.any(L <= 0):
        raise InputError("expected tendons of positive length, found zero length for "
                         f"{[system.tendons[k].name for k in np.flatnonzero(L <= 0)]}")
    n = d / L
    c = system.tendon_connectivity
    dJ = J[:, c[1], :] - J[:, c[0], :]                   # (3, n_t, n_q)
    return np.einsum("ck,ckq->qk", n, dJ)


# ---------------------------------------------------------------------------- corner constraints
def euler_R_derivatives(gamma) -> np.ndarray:
    """dR^ef/dgamma_k of :func:`tmfem.system.geometry.rotation_ef` (eq. 3.3), shape (3, 3, 3)
    with k last."""
    g1, g2, g3 = gamma
    c1, s1, c2, s2, c3, s3 = np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2), np.cos(g3), np.sin(g3)
    Rz = np.array([[c1, -s1, 0], [s1, c1, 0], [0, 0, 1]])
    Ry = np.array([[c2, 0, s2], [0, 1, 0], [-s2, 0, c2]])
    Rx = np.array([[1, 0, 0], [0, c3, -s3], [0, s3, c3]])
    dRz = np.array([[-s1, -c1, 0], [c1, -s1, 0], [0, 0, 0]])
    dRy = np.array([[-s2, 0, c2], [0, 0, 0], [-c2, 0, -s2]])
    dRx = np.array([[0, 0, 0], [0, -s3, -c3], [0, c3, -s3]])
    return np.stack([dRz @ Ry @ Rx, Rz @ dRy @ Rx, Rz @ Ry @ dRx], axis=-1)


def corner_force_names(N: int) -> list[str]:
    """Names of the membrane corner forces of T_q (eqs. 3.16-3.17): F_u1, F_u2, F_v2, ..."""
    return [f"F_{'uvw'[c]}{i + 1}" for i, c in free_corner_components(N)]


@lru_cache(maxsize=None)
def _free_index(N: int) -> tuple[np.ndarray, np.ndarray]:
    """Corner and component indices of the 3N-6 free corner displacements
    (:func:`tmfem.system.geometry.free_corner_components`), made once per N (read-only)."""
    corner, comp = np.array(free_corner_components(N), dtype=int).reshape(-1, 2).T
    corner.flags.writeable = comp.flags.writeable = False
    return corner, comp


def free_components(X) -> np.ndarray:
    """The 3N-6 free entries of a corner array X (2 or 3, N), in the order of eq. 3.4
    (:func:`tmfem.system.geometry.free_corner_components`); a missing w row counts as 0."""
    X = np.asarray(X, dtype=float)
    if X.shape[0] == 2:
        X = np.vstack([X, np.zeros((1, X.shape[1]))])
    corner, comp = _free_index(X.shape[1])
    return X[comp, corner]


def corner_array(free, N: int) -> np.ndarray:
    """The corner array (3, N) of eq. 3.4 with the 3N-6 free entries ``free`` and zeros
    elsewhere (the inverse of :func:`free_components`)."""
    D = np.zeros((3, N))
    corner, comp = _free_index(N)
    D[comp, corner] = free
    return D


@dataclass(frozen=True)
class CornerState:
    """Solution of the corner constraints (eq. 3.5) for one q.

    ``R`` is R^ef, ``gamma`` its 3-2-1 Euler angles, ``delta`` (3, N) the corner
    displacements in O_f (corner N is the origin, its displacement is zero), ``free`` the
    3N-6 free components in the order of :func:`free_corner_components`.
    """

    R: np.ndarray
    gamma: np.ndarray
    delta: np.ndarray
    free: np.ndarray
    iterations: int = 0


def _undeformed_corners(system) -> np.ndarray:
    """The undeformed corners P_i (3, N) in O_f (eq. 3.5; w = 0)."""
    return np.vstack([system.membrane_corners, np.zeros((1, system.N))])


def _corner_data(system, q):
    B = system.membrane_corners_inertial(q)
    N = system.N
    X = B[:, :N - 1] - B[:, [N - 1]]
    return X, _undeformed_corners(system)


def corner_state(system, q=None) -> CornerState:
    """Solve eq. 3.5 in closed form with the floating frame of 3.2
    (:func:`tmfem.system.geometry.floating_frame`: x_f along B_MN -> B_M1, z_f normal to the
    plane of B_MN, B_M1, B_M,N-1); the corner displacements are then
    R^fe (B_Mi - B_MN) - P_i.

    Raises
    ------
    InputError
        if B_MN, B_M1, B_M,N-1 are collinear.
    """
    delta, _, R = system.corner_displacements(q)
    delta[:, -1] = 0.0                  # corner N is the origin O_f (eq. 3.4)
    return CornerState(R=R, gamma=euler_angles_321(R), delta=delta, free=free_components(delta))


def _G(gamma, free, P, N):
    """Right-hand side R(gamma) (P_i + Delta_i) of eq. 3.5, shape (3, N-1)."""
    return rotation_ef(gamma) @ (P + corner_array(free, N))[:, :N - 1]


def corner_constraint_jacobian(gamma, free, P, N) -> np.ndarray:
    """Jacobian d vec(G)/d(gamma, free) of the corner constraints of eq. 3.5 (G of :func:`_G`),
    shape (3(N-1), 3N-3); vec is column-major over corners."""
    corner, comp = _free_index(N)
    R = rotation_ef(gamma)
    dR = euler_R_derivatives(gamma)
    Y = (P + corner_array(free, N))[:, :N - 1]
    J = np.zeros((3, N - 1, 3 + corner.size))
    J[:, :, :3] = np.einsum("abk,bi->aik", dR, Y)
    J[:, corner, 3 + np.arange(corner.size)] = R[:, comp]
    return J.transpose(1, 0, 2).reshape(3 * (N - 1), -1)


def solve_corner_constraints(system, q=None, *, gamma0=None, free0=None, tol: float = 1e-12,
                             maxiter: int = 50) -> CornerState:
    """Solve eq. 3.5 for (gamma, Delta) by Newton's method (independent of :func:`corner_state`).

    Raises
    ------
    ConvergenceError
        if the residual |B_Mi - B_MN - R (P_i + Delta_i)| does not fall below
        ``tol`` times the membrane size within ``maxiter`` iterations.
    """
    q = system.q if q is None else np.asarray(q, dtype=float)
    X, P = _corner_data(system, q)
    N = system.N
    nfree = 3 * N - 6
    y = np.zeros(3 + nfree)
    # default start: x_f along the horizontal projection of B_MN -> B_M1, no tilt
    y[0] = np.arctan2(X[1, 0], X[0, 0])
    if gamma0 is not None:
        y[:3] = gamma0
    if free0 is not None:
        y[3:] = free0
    scale = max(np.abs(P).max(), 1.0)
    x = X.T.ravel()

    def residual(yy):
        return _G(yy[:3], yy[3:], P, N).T.ravel() - x, corner_constraint_jacobian(yy[:3], yy[3:], P, N)
    try:
        res = newton(residual, y, tol=tol, scale=scale, max_iter=maxiter, line_search=False)
    except ConvergenceError as exc:
        raise ConvergenceError(f"corner constraints (eq. 3.5): expected residual < "
                               f"{tol * scale:.3g} m within {maxiter} Newton iterations: {exc}") from None
    y = res.u
    return CornerState(R=rotation_ef(y[:3]), gamma=y[:3].copy(), delta=corner_array(y[3:], N),
                       free=y[3:].copy(), iterations=res.iterations)


def delta_gradient(system, q=None, state: CornerState | None = None, J=None) -> np.ndarray:
    """dDelta_c/dq of the 3N-6 free corner displacements, shape (n_q, 3N-6) (eq. 3.11).

    Implicit differentiation of eq. 3.5: dX(q) = dG(gamma, Delta), so
    d(gamma, Delta)/dq = G_(gamma,Delta)^-1 X_q. ``state`` and ``J`` (the node Jacobian of
    :func:`node_jacobian`): those at q when the caller has them.
    """
    q = system.q if q is None else np.asarray(q, dtype=float)
    st = corner_state(system, q) if state is None else state
    N = system.N
    P = _undeformed_corners(system)
    J = node_jacobian(system, q) if J is None else J
    M = system.M
    b = system.M * system.N + (M - 1) * N        # index of B_M1 in the node order
    JB = J[:, b:b + N, :]
    Xq = (JB[:, :N - 1, :] - JB[:, [N - 1], :]).transpose(1, 0, 2).reshape(3 * (N - 1), -1)
    Gy = corner_constraint_jacobian(st.gamma, st.free, P, N)
    dy = np.linalg.solve(Gy, Xq)
    return dy[3:].T


# ---------------------------------------------------------------------------- A(q)
@dataclass(frozen=True)
class EquilibriumMatrix:
    """A(q) of eq. 3.16 with row and column names.

    Columns: the 3N-6 membrane corner forces, then the tendon forces (T_q of eq. 3.16);
    rows: the generalised coordinates q. ``n_F`` is the number of corner-force columns.
    """

    A: np.ndarray
    rows: list
    cols: list
    n_F: int
    state: CornerState = field(repr=False, default=None)

    @property
    def A_F(self) -> np.ndarray:
        return self.A[:, :self.n_F]

    @property
    def A_T(self) -> np.ndarray:
        return self.A[:, self.n_F:]


def equilibrium_matrix(system, q=None) -> EquilibriumMatrix:
    """The matrix A(q) of eq. 3.16 from the virtual work of tendon and corner forces.

    delta U = sum_c F_c dDelta_c/dq dq + sum_k T_k d|d_k|/dq dq = 0 for every dq, so the
    column of force c is its generalised-force contribution (eqs. 3.7, 3.10-3.15).
    """
    q = system.q if q is None else np.asarray(q, dtype=float)
    st = corner_state(system, q)
    J = node_jacobian(system, q)
    AF = delta_gradient(system, q, st, J)
    AT = tendon_length_gradient(system, q, J)
    return EquilibriumMatrix(A=np.hstack([AF, AT]), rows=list(system.q_names),
                             cols=corner_force_names(system.N) + system.tendon_names(),
                             n_F=AF.shape[1], state=st)


def symmetric_corner_direction(N: int) -> np.ndarray:
    """Free corner-force components for F_Delta = 1 (eq. 3.21: F_ui = cos beta_i, F_vi = sin beta_i)."""
    b = beta(N)
    return free_components(np.vstack([np.cos(b), np.sin(b)]))


def symmetric_groups(system) -> list[str]:
    """Tendon groups in the order of the force vector of eq. 3.26 (S1, then S V D C P R of
    each stage i >= 2), or SL, SU for a 1-N(D) system."""
    if system.deployable:
        return ["SL", "SU"]
    return ["S1"] + [f"{f}{i}" for i in range(2, system.M + 1) for f in FAMILIES_MN]


@dataclass(frozen=True)
class SymmetricMatrix:
    """The (5M-3) x (6M-4) matrix of 3.3.2 acting on T_MN (eq. 3.26); last column F_Delta."""

    A: np.ndarray
    rows: list
    cols: list


def symmetric_matrix(system, q=None) -> SymmetricMatrix:
    """Reduce A(q) by symmetry (3.3.2): rows of bar b_iN (eq. 3.24), columns summed per
    tendon group (eq. 3.23) and the membrane column for F_Delta (eq. 3.21)."""
    if system.symmetric is None:
        raise InputError(f"system {system.name!r}: expected a symmetric system (3.3.1), found "
                         "no symmetric parametrisation")
    E = equilibrium_matrix(system, q)
    rows = _bar_N_rows(system.M, system.N)
    groups = symmetric_groups(system)
    cols = [E.A_T[:, k].sum(axis=1) for k in _group_members(system.tendons, tuple(groups))]
    cols.append(E.A_F @ symmetric_corner_direction(system.N))
    A = np.column_stack(cols)[rows]
    names = system.q_names
    return SymmetricMatrix(A=A, rows=[names[r] for r in rows], cols=groups + ["F_Delta"])


@lru_cache(maxsize=None)
def _bar_N_rows(M: int, N: int) -> np.ndarray:
    """Indices into q of the coordinates of the bars b_iN (eq. 3.24): theta_1N, psi_1N, then
    x_iN, y_iN, z_iN, theta_iN, psi_iN of each stage i >= 2 (read-only)."""
    xyz, th, ps = q_index(M, N)
    rows = np.concatenate([[th[0, -1], ps[0, -1]], np.column_stack(
        [xyz[0, 1:, -1], xyz[1, 1:, -1], xyz[2, 1:, -1], th[1:, -1], ps[1:, -1]]).ravel()])
    rows.flags.writeable = False
    return rows


@lru_cache(maxsize=256)
def _group_members(tendons: tuple, groups: tuple) -> tuple[np.ndarray, ...]:
    """Indices of the tendons of each group of ``groups``, in the order of ``tendons``."""
    gid = np.array([t.group for t in tendons])
    return tuple(np.flatnonzero(gid == g) for g in groups)


def expand_symmetric_forces(system, T_groups: np.ndarray, F_delta: float) -> np.ndarray:
    """The full T_q of eq. 3.16 from group forces (eq. 3.23) and F_Delta (eq. 3.21)."""
    groups = symmetric_groups(system)
    g = {k: v for k, v in zip(groups, T_groups)}
    T = np.array([g[t.group] for t in system.tendons])
    return np.concatenate([F_delta * symmetric_corner_direction(system.N), T])


# ---------------------------------------------------------------------------- null space
@dataclass(frozen=True)
class NullVector:
    """Result of the positive null-space search.

    ``x`` maximises min_i x_i over ``positive`` entries subject to A x = 0 and
    sum of the positive entries = 1; ``margin`` is that minimum (> 0 when a vector with all
    required entries positive exists); ``dim`` the dimension of the numerical null space;
    ``sv`` the singular values of A (relative to the largest).
    """

    x: np.ndarray
    margin: float
    dim: int
    sv: np.ndarray

    @property
    def exists(self) -> bool:
        return self.dim > 0 and self.margin > 0


def null_space(A: np.ndarray, rtol: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal basis Z (n, k) of the numerical null space of A and its relative singular values."""
    A = np.atleast_2d(A)
    n = A.shape[1]
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    As = A / scale                                         # column scaling: forces of any unit
    U, s, Vt = np.linalg.svd(As)
    sfull = np.zeros(n)
    sfull[:s.size] = s
    rel = sfull / max(sfull.max(), 1e-300)
    k = int(np.sum(rel <= rtol))
    Z = Vt[n - k:].T / scale[:, None]
    if k:
        Z /= np.linalg.norm(Z, axis=0)
    return Z, rel


def positive_null_vector(A: np.ndarray, positive=None, *, rtol: float = 1e-9) -> NullVector:
    """Search the null space of A for a vector whose ``positive`` entries are all > 0.

    A linear programme (scipy HiGHS) over the null-space coordinates c, x = Z c, maximises
    t subject to x_i >= t (i in ``positive``) and sum_i x_i = 1; ``margin`` = t. This is
    the search of 3.2 / 3.3.2 (tendons taut, membrane tensioned).
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    n = A.shape[1]
    pos = np.ones(n, dtype=bool) if positive is None else np.asarray(positive, dtype=bool)
    Z, rel = null_space(A, rtol)
    k = Z.shape[1]
    if k == 0:
        return NullVector(x=np.zeros(n), margin=-np.inf, dim=0, sv=rel)
    Zp = Z[pos]
    if k == 1:                  # one null vector: the normalisation fixes c, no LP to solve
        s = Zp.sum()
        if abs(s) <= rtol * np.abs(Zp).sum():
            return NullVector(x=np.zeros(n), margin=-np.inf, dim=k, sv=rel)
        x = Z[:, 0] / s
        return NullVector(x=x, margin=float(min(x[pos].min(), 1.0)), dim=k, sv=rel)
    # variables (c_1..c_k, t); maximise t
    c = np.zeros(k + 1)
    c[-1] = -1.0
    A_ub = np.hstack([-Zp, np.ones((Zp.shape[0], 1))])     # t - Zp c <= 0
    b_ub = np.zeros(Zp.shape[0])
    A_eq = np.hstack([Zp.sum(axis=0)[None, :], [[0.0]]])
    from scipy.optimize import linprog     # 16 MB resident: only where used
    res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=[1.0],
                  bounds=[(None, None)] * k + [(None, 1.0)], method="highs")
    if res.status != 0:
        # the normalisation is infeasible only when every null vector sums to zero on `pos`
        return NullVector(x=np.zeros(n), margin=-np.inf, dim=k, sv=rel)
    x = Z @ res.x[:k]
    return NullVector(x=x, margin=float(res.x[-1]), dim=k, sv=rel)
