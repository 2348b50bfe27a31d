"""Corner constraints Phi(q, zeta) = 0 and the dependent coordinates zeta (eqs. 3.3-3.5, 5.14).

The dependent coordinates (eq. 5.14) are the membrane corner displacements in the floating
frame O_f (3.2: B_M1 free along x_f, B_M,N-1 free in x_f and y_f, B_Mi, i = 2..N-2, free in
x_f, y_f, z_f; B_MN is the origin O_f) followed by the 3-2-1 Euler angles gamma_1..3 of
O_f (eq. 3.3):

    zeta = [Delta_u1, Delta_u2, Delta_v2, Delta_w2, ..., Delta_u,N-1, Delta_v,N-1, g1, g2, g3]

3N - 6 corner displacements + 3 angles = 3N - 3 = number of constraints (eq. 3.5)

    Phi_i(q, zeta) = OB_Mi(q) - OO_f(q) - R^ef(gamma) (c_i + Delta_i),   i = 1..N-1,

with O_f = B_MN and c_i the undeformed corner i in O_f.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.newton import newton
from tmfem.models.com.kinematics import bars_sx, rotation_ef_sx
from tmfem.equilibrium.general import corner_state
from tmfem.system.geometry import free_corner_components


@dataclass(frozen=True)
class ZetaLayout:
    """Which corner displacement components are coordinates (eq. 5.14).

    Attributes
    ----------
    N : int
    corner_components : list of (corner, component)
        0-based corner index (0 = corner 1) and component (0 = u, 1 = v, 2 = w) of each
        Delta entry of zeta, in the order of eq. 5.14.
    """

    N: int
    corner_components: tuple

    @classmethod
    def for_polygon(cls, N: int) -> "ZetaLayout":
        """The layout of eq. 5.14 (:func:`tmfem.system.geometry.free_corner_components`)."""
        return cls(N=N, corner_components=tuple(free_corner_components(N)))

    @property
    def n_delta(self) -> int:
        return len(self.corner_components)

    @property
    def n(self) -> int:
        return self.n_delta + 3

    @property
    def names(self) -> list[str]:
        comp = "uvw"
        return [f"Delta_{comp[c]}{i + 1}" for i, c in self.corner_components] + \
               ["gamma_1", "gamma_2", "gamma_3"]

    def in_plane(self) -> np.ndarray:
        """Indices (into the Delta part) of the in-plane components."""
        return np.array([k for k, (_, c) in enumerate(self.corner_components) if c < 2], dtype=int)

    def transverse(self) -> np.ndarray:
        """Indices (into the Delta part) of the transverse components Delta_w."""
        return np.array([k for k, (_, c) in enumerate(self.corner_components) if c == 2], dtype=int)

    def delta_array(self, zeta) -> np.ndarray:
        """Corner displacements (3, N) from zeta (numeric), zeros where fixed."""
        d = np.zeros((3, self.N))
        for k, (i, c) in enumerate(self.corner_components):
            d[c, i] = zeta[k]
        return d


def phi_sx(system, layout: ZetaLayout, q, zeta):
    """Constraint vector Phi(q, zeta) of eq. 3.5 (SX, length 3N - 3)."""
    N = system.N
    _, _, B = bars_sx(system, q)
    BM = B[(system.M - 1) * N:]
    R = rotation_ef_sx(zeta[layout.n_delta:])
    c = system.membrane_corners
    d = [[0.0, 0.0, 0.0] for _ in range(N)]
    for k, (i, comp) in enumerate(layout.corner_components):
        d[i][comp] = zeta[k]
    out = []
    for i in range(N - 1):
        ci = ca.vertcat(float(c[0, i]) + d[i][0], float(c[1, i]) + d[i][1], d[i][2])
        out.append(BM[i] - BM[N - 1] - ca.mtimes(R, ci))
    return ca.vertcat(*out)


def zeta_closed_form(system, layout: ZetaLayout, q=None) -> np.ndarray:
    """zeta(q) from the geometric definition of O_f (3.2,
    :func:`tmfem.equilibrium.general.corner_state`): x_f along B_MN -> B_M1, z_f normal to the
    plane (B_MN, B_M1, B_M,N-1); corner displacements Delta_i = R^T(B_Mi - B_MN) - c_i. An
    exact solution of Phi = 0, used as the Newton starting point and as a test."""
    st = corner_state(system, q)
    return np.concatenate([[st.delta[c, i] for i, c in layout.corner_components], st.gamma])


def zeta_closed_form_sx(system, layout: ZetaLayout, q):
    """zeta(q) of :func:`zeta_closed_form` as a casadi SX expression: x_f along
    B_MN -> B_M1, z_f normal to (B_MN, B_M1, B_M,N-1), y_f = z_f x x_f (3.2); Delta_i the
    corner positions in O_f minus the undeformed corners, gamma the 3-2-1 Euler angles of
    R = [x_f, y_f, z_f] (eq. 3.3). An exact root of Phi (eq. 3.5): the graphs evaluate zeta(q)
    with it instead of a Newton loop, and the "substituted" formulation substitutes it into
    the Lagrangian."""
    N = system.N
    _, _, B = bars_sx(system, q)
    BM = B[(system.M - 1) * N:]
    ex = BM[0] - BM[N - 1]
    ex = ex / ca.norm_2(ex)
    nz = ca.cross(ex, BM[N - 2] - BM[N - 1])
    ez = nz / ca.norm_2(nz)
    ey = ca.cross(ez, ex)
    R = ca.horzcat(ex, ey, ez)
    c = system.membrane_corners
    out = []
    for (i, comp) in layout.corner_components:
        rel = ca.dot(R[:, comp], BM[i] - BM[N - 1])
        out.append(rel - (float(c[comp, i]) if comp < 2 else 0.0))
    g1 = ca.atan2(R[1, 0], R[0, 0])
    g2 = -ca.asin(R[2, 0])
    g3 = ca.atan2(R[2, 1], R[2, 2])
    return ca.vertcat(*out, g1, g2, g3)


class ConstraintSolver:
    """Newton solution of Phi(q, zeta) = 0 for zeta (eq. 3.5) and the Jacobians of eq. 5.23.

    Parameters
    ----------
    system : System
    layout : ZetaLayout
    """

    def __init__(self, system, layout: ZetaLayout):
        self.system, self.layout = system, layout
        nq = len(system.q_names)
        q = ca.SX.sym("q", nq)
        z = ca.SX.sym("zeta", layout.n)
        phi = phi_sx(system, layout, q, z)
        self._f = ca.Function("phi", [q, z], [phi, ca.jacobian(phi, z), ca.jacobian(phi, q)])

    def phi(self, q, zeta):
        """Phi(q, zeta) of eq. 3.5 and its Jacobians d Phi / d zeta, d Phi / d q."""
        p, pz, pq = self._f(q, zeta)
        return np.asarray(p).ravel(), np.asarray(pz), np.asarray(pq)

    def solve(self, q, zeta0=None, *, tol: float = 1e-13, max_iter: int = 30) -> np.ndarray:
        """zeta(q) by Newton's method on Phi (5.3); start at zeta0 or the closed form."""
        q = np.asarray(q, dtype=float)
        z = zeta_closed_form(self.system, self.layout, q) if zeta0 is None else np.array(zeta0, float)
        scale = max(1.0, float(np.max(np.abs(self.system.membrane_corners))))

        def residual(zeta):
            p, pz, _ = self.phi(q, zeta)
            return p, pz
        try:
            return newton(residual, z, tol=tol, scale=scale, max_iter=max_iter,
                          line_search=False).u
        except ConvergenceError as exc:
            raise ConvergenceError(f"corner constraints (eq. 3.5): {exc}") from None

    def dzeta_dq(self, q, zeta) -> np.ndarray:
        """d zeta / d q = -(dPhi/dzeta)^-1 dPhi/dq (eq. 5.23)."""
        _, pz, pq = self.phi(q, zeta)
        c = np.linalg.cond(pz)
        if not np.isfinite(c) or c > 1e12:
            raise InputError(f"corner constraints: dPhi/dzeta is singular (condition number {c:.3e}, "
                             "expected < 1e12); the frame O_f is undefined (corners B_MN, B_M1, "
                             "B_M,N-1 collinear?)")
        return -np.linalg.solve(pz, pq)
