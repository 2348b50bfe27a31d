"""Free vibration of the membrane-truss-cable model about its equilibrium (dissertation 6.5).

The MTC model of :mod:`tmfem.models.mtc.model` is integrated in time with Park's method started by the
trapezoidal rule (eqs. 5.34-5.35, :func:`tmfem.solvers.park.park_integrate`). The equation of
motion on the free reduced DOFs is

    M a + C v + f_int(x) = 0,        C = alpha M + beta K_0  (Rayleigh, default 0),

with the constant mass ``MTCModel.mass()`` (membrane, bars and tendons consistent), the internal
force and tangent of ``MTCModel.residual`` (total-Lagrangian membrane, trusses; tendons
tension-only) and K_0 the tangent at the equilibrium.

**Initial state.** The static equilibrium x_e plus the perturbation of the control-oriented
model (``theta_12_dot=0.01`` as in 6.5.1, ``theta_11_dot=0.01`` as in 6.5.2; any coordinate of
``system.q_names`` with or without ``_dot``). A generalised coordinate q_k of 3.2 moves the
labelled nodes rigidly: the initial velocity of the labelled nodes (A_ij, B_ij) is
dX/dq_k * rate, i.e. the top of bar b_ij rotating about its base gets l_ij de/dtheta rate
(e = bar direction, eq. 3.1), and a displacement ``theta_12=0.001`` moves them by
X(q_e + dq) - X(q_e) with q_e recovered from the equilibrium bar vectors. The remaining nodes
(membrane nodes other than the corners, tendon internal nodes) get the quasi-static field that
follows the labelled nodes: v_o = -K_oo^-1 K_op v_p with the tangent at the equilibrium (static
condensation). For a straight prestressed tendon this is exactly the linear interpolation of its
end velocities; for the membrane it is the smooth deformation its prestress imposes when a
corner moves -- the counterpart of the COM, where the membrane follows the bars through its
floating frame and corner-deformation fields (eqs. 5.1-5.3) and the membrane modal rates start
at zero. Giving the corner alone a velocity would instead excite the mesh-scale modes around it.

**Outputs per step** (:class:`MTCVibration`, CSV row by row): theta and psi of every bar
(recovered from the bar vectors, :func:`tmfem.models.mtc.post.q_from_positions`), the monitored bar
ends (``MONITOR_NODES``: B_12, B_14 for 1-4; A_21, B_11, B_21 for 2-3; Figs. 6.21-6.22,
6.25-6.27), the membrane transverse deflections w_1..w_3 at the material points of eqs.
5.36 / 5.38 (the ``MONITOR_POINTS`` of the COM, reference coordinates in O_f) measured along z_f
of the floating frame of the current corners (eq. 3.3, :func:`tmfem.models.mtc.topology.to_floating`),
and the largest tendon transverse deflection: the internal nodes' offset from the chord in the
local frame e_t1 (chord), e_t2 = e_t1 x e_z / |.|, e_t3 = e_t1 x e_t2 (eq. 5.37; Figs. 6.24,
6.29), relative to its value at the equilibrium.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from tmfem.equilibrium.general import node_jacobian
from tmfem.errors import InputError
from tmfem.fem.membrane import point_matrix
from tmfem.models.base import split_perturbation
from tmfem.models.mtc.post import q_from_positions
from tmfem.models.mtc.topology import to_floating


class MTCDynamics:
    """The MTC equation of motion on the free DOFs as a :class:`tmfem.models.base.Plant`.

    Inputs u: the tendon rest lengths ``r_<tendon>`` (each tendon's k elements get u / k);
    outputs y: the bar coordinates q recovered from the bar nodes (eqs. 3.1-3.2) and the
    transverse deflections w_k in the floating frame at ``output_points`` (eqs. 5.36-5.38),
    as a sensor would measure them. The start state ``x0, v0`` is the equilibrium with the
    perturbation of :func:`initial_state`.

    Parameters
    ----------
    model : MTCModel
    x_eq : ndarray (3, n_nodes)
        The static equilibrium (``model.solve_static().x``); the fixed DOFs stay there.
    alpha, beta : float
        Rayleigh damping C = alpha M + beta K_0 [1/s, s] (default: undamped).
    perturb : dict, optional
        Initial perturbation by coordinate name (``theta_12_dot=0.01``).
    output_points : array (2, n) or list of (x_f, y_f), optional
        Default ``system.monitor_points``.
    """

    def __init__(self, model, x_eq, *, alpha: float = 0.0, beta: float = 0.0,
                 perturb: dict | None = None, output_points=None):
        if not (np.isfinite(alpha) and np.isfinite(beta) and alpha >= 0 and beta >= 0):
            raise InputError(f"Rayleigh damping: expected alpha, beta >= 0, found {alpha}, {beta}")
        self.model = model
        self.free = model.free
        self.xr_eq = model.reduce(np.asarray(x_eq, dtype=float))
        f = self.free
        self.M = model.mass()[f][:, f].tocsc()
        _, K0 = model.residual(self.xr_eq)
        self.K0 = K0[f][:, f].tocsc()
        self.alpha, self.beta = float(alpha), float(beta)
        self.C = (self.alpha * self.M + self.beta * self.K0).tocsc() if (alpha or beta) else None
        system = model.system
        pts = system.monitor_points.T if output_points is None else np.reshape(output_points, (-1, 2))
        self.output_points = [tuple(map(float, p)) for p in pts]
        self._P = point_matrix(model.membrane.skmesh, np.asarray(self.output_points).T) \
            if self.output_points else None
        self.u0 = np.asarray(model.rest_lengths, dtype=float)
        self.input_names = [f"r_{t.name}" for t in system.tendons]
        self.output_names = list(system.q_names) + [f"w_{i + 1}" for i in range(len(self.output_points))]
        self.x0, self.v0 = initial_state(self, perturb)

    # state <-> positions
    def state0(self) -> np.ndarray:
        """The equilibrium as a free-DOF state."""
        return self.xr_eq[self.free].copy()

    def reduced(self, u) -> np.ndarray:
        """Independent positions (flat, 3 n_red) of the free-DOF state u (fixed DOFs at x_eq)."""
        xr = self.xr_eq.copy()
        xr[self.free] = u
        return xr

    def positions(self, u) -> np.ndarray:
        """Full node positions (3, n_nodes) of the free-DOF state u."""
        return self.model.full(self.reduced(u))

    # Plant protocol (tmfem.models.base)
    def _inputs(self, u) -> None:
        # the plant drives its model: the tendon rest lengths are the inputs of this call
        # (the nominal u0 when none are given), so the model is left at the last u
        self.model.set_tendon_lengths(self.u0 if u is None else u)

    def residual(self, x, v, a, t, u=None):
        """r = M a + C v + f_int(x; u) on the free DOFs (module docstring)."""
        self._inputs(u)
        r, _ = self.model.residual(self.reduced(x), tangent=False)
        out = r[self.free] + self.M @ a
        if self.C is not None:
            out = out + self.C @ v
        return out

    def _tangent(self, x):
        """Tangent K_T (eqs. 4.4-4.6) on the free DOFs at the free-DOF state x."""
        _, K = self.model.residual(self.reduced(x))
        return K[self.free][:, self.free]

    def jacobians(self, x, v, a, t, u=None):
        """(dr/dx, dr/dv, dr/da) = (K_T, C, M)."""
        self._inputs(u)
        K = self._tangent(x)
        C = self.C if self.C is not None else sp.csc_matrix(K.shape)
        return K, C, self.M

    def newton_matrix(self, x, v, a, t, cv, ca, u=None):
        """K_T + cv C + ca M, the Newton matrix of Park's method (eq. 5.34)."""
        self._inputs(u)
        S = self._tangent(x) + ca * self.M
        if self.C is not None:
            S = S + cv * self.C
        return S.tocsc()

    def factorize(self, S):
        """Solver of the Newton matrix: the model's backend (symmetric-mode sparse LU)."""
        return self.model.backend.factorize(S)

    def outputs(self, x, v=None, u=None) -> np.ndarray:
        """y = [q, w_k]: bar coordinates from the bar nodes (eqs. 3.1-3.2) and membrane
        deflections along z_f of the floating frame at the output points (eqs. 5.36-5.38)."""
        xf = self.positions(x)
        topo = self.model.topology
        q = q_from_positions(self.model.system, xf[:, topo.system_node])
        if self._P is None:
            return q
        xm = xf[:, :topo.n_mesh]
        w = to_floating((self._P @ xm.T).T, xm[:, topo.mesh.corners])[2]
        return np.concatenate([q, w])

    # energies
    def kinetic_energy(self, v) -> float:
        """v^T M v / 2 [J] of the free-DOF velocities v."""
        return 0.5 * float(v @ (self.M @ v))

    def strain_energy(self, x) -> float:
        """Strain energy [J] of membrane, bars and tendons (:meth:`MTCModel.energy`)."""
        return self.model.energy(self.reduced(x))


def perturbation_names(system) -> list:
    """Accepted perturbation names: the q of 3.2 and their rates (``theta_12_dot``)."""
    return list(system.q_names) + [n + "_dot" for n in system.q_names]


def initial_state(dyn: MTCDynamics, perturb: dict | None):
    """Free-DOF positions and velocities (u0, v0) of the perturbed equilibrium (module docstring).

    The labelled-node field dX/dq (exact, :func:`tmfem.equilibrium.general.node_jacobian`) is
    taken at the q recovered from the equilibrium; the other free DOFs follow by static
    condensation of the equilibrium tangent.
    """
    model = dyn.model
    system, topo = model.system, model.topology
    u0 = dyn.state0()
    if not perturb:
        return u0, np.zeros_like(u0)
    dq, dqd = split_perturbation(perturb, system.q_names)
    x_eq = model.full(dyn.xr_eq)
    q_e = q_from_positions(system, x_eq[:, topo.system_node])
    X_e = system.nodes(q_e)
    dX_pos = system.nodes(q_e + dq) - X_e if np.any(dq) else np.zeros_like(X_e)
    J = node_jacobian(system, q_e) @ dqd                       # dX/dq q' (eqs. 3.1-3.2)
    # reduced node carrying each labelled node (point attachment: B_Mj is the corner node)
    red_of = np.full(len(system.node_labels), -1)
    for i, n in enumerate(topo.system_node):
        if topo.red_node[n] >= 0:
            red_of[i] = topo.red_node[n]
        else:
            row = topo.T[3 * n]
            if topo.attachment != "point" or row.nnz != 1:
                if np.any(J[:, i]) or np.any(dX_pos[:, i]):
                    raise InputError(f"perturbation of {system.node_labels[i]}: needs "
                                     f"attachment='point' (the bar top is a weighted patch "
                                     f"point here)")
                continue
            red_of[i] = row.indices[0] // 3
    # prescribed reduced DOFs (labelled nodes) among the free ones
    n_red3 = dyn.xr_eq.size
    pres = np.zeros(n_red3, dtype=bool)
    vp = np.zeros(n_red3)
    dp = np.zeros(n_red3)
    for i, r in enumerate(red_of):
        if r >= 0:
            pres[3 * r:3 * r + 3] = True
            vp[3 * r:3 * r + 3] = J[:, i]
            dp[3 * r:3 * r + 3] = dX_pos[:, i]
    free = dyn.free
    pf, vpf, dpf = pres[free], vp[free], dp[free]
    K = dyn.K0
    o = ~pf
    Koo = K[o][:, o].tocsc()
    Kop = K[o][:, pf]
    solve = model.backend.factorize(Koo)

    def condense(p):
        out = np.zeros(free.sum())
        out[pf] = p[pf]
        if np.any(p[pf]):
            out[o] = -solve(Kop @ p[pf])
        return out

    v0 = condense(vpf)
    if np.any(dpf):
        u0 = u0 + condense(dpf)
    return u0, v0


def tendon_transverse(model, x) -> np.ndarray:
    """Transverse offsets (n_t, k - 1, 2) of every tendon's internal nodes from its chord, in
    the tendon frame e_t2, e_t3 of eq. 5.37."""
    topo = model.topology
    c = model.system.tendon_connectivity
    a = x[:, topo.system_node[c[0]]]
    b = x[:, topo.system_node[c[1]]]
    e1 = (b - a) / np.linalg.norm(b - a, axis=0)
    e2 = np.cross(e1.T, [0.0, 0.0, 1.0]).T
    e2 /= np.linalg.norm(e2, axis=0)        # tendons are never vertical in these designs
    e3 = np.cross(e1.T, e2.T).T
    d = x[:, topo.tendon_internal] - a[:, :, None]           # (3, n_t, k-1)
    return np.stack([np.einsum("it,itk->tk", e2, d), np.einsum("it,itk->tk", e3, d)], axis=-1)


def fit_frequency(t, y, *, f_min: float, f_max: float, n_grid: int = 2000) -> float:
    """Frequency [Hz] of the single sinusoid a cos(2 pi f t) + b sin(2 pi f t) + c that fits the
    samples y(t) best in least squares, searched in [f_min, f_max] (grid, then refined).

    Unlike an FFT peak this is accurate on records of one or two periods when one frequency
    dominates (e.g. a modal coordinate of the response).
    """
    from scipy.optimize import minimize_scalar
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.shape != y.shape or t.size < 8 or not np.all(np.isfinite(y)):
        raise InputError(f"fit_frequency: expected >= 8 finite samples matching t, found "
                         f"{y.shape} for t {t.shape}")
    if not (0 < f_min < f_max):
        raise InputError(f"fit_frequency: expected 0 < f_min < f_max, found {f_min}, {f_max}")

    def misfit(f):
        A = np.column_stack([np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t), np.ones_like(t)])
        c, *_ = np.linalg.lstsq(A, y, rcond=None)
        return float(np.sum((A @ c - y) ** 2))

    grid = np.linspace(f_min, f_max, n_grid)
    k = int(np.argmin([misfit(f) for f in grid]))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, n_grid - 1)]
    return float(minimize_scalar(misfit, bounds=(lo, hi), method="bounded",
                                 options={"xatol": 1e-10 * f_max}).x)
