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

import sys
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.membrane import point_matrix
from tmfem.models.mtc.post import q_from_positions
from tmfem.models.mtc.topology import to_floating
from tmfem.fem.truss import truss_internal


class MTCDynamics:
    """The MTC equation of motion on the free DOFs, as a residual for ``park_integrate``.

    Parameters
    ----------
    model : MTCModel
    x_eq : ndarray (3, n_nodes)
        The static equilibrium (``model.solve_static().x``); the fixed DOFs stay there.
    alpha, beta : float
        Rayleigh damping C = alpha M + beta K_0 [1/s, s] (default: undamped).
    """

    def __init__(self, model, x_eq, *, alpha: float = 0.0, beta: float = 0.0):
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

    # park_integrate protocol
    def residual(self, x, v, a, t):
        """r = M a + C v + f_int(x) on the free DOFs (module docstring)."""
        r, _ = self.model.residual(self.reduced(x), tangent=False)
        out = r[self.free] + self.M @ a
        if self.C is not None:
            out = out + self.C @ v
        return out

    def _tangent(self, x):
        """Tangent K_T (eqs. 4.4-4.6) on the free DOFs at the free-DOF state x."""
        _, K = self.model.residual(self.reduced(x))
        return K[self.free][:, self.free]

    def jacobians(self, x, v, a, t):
        """(dr/dx, dr/dv, dr/da) = (K_T, C, M)."""
        K = self._tangent(x)
        C = self.C if self.C is not None else sp.csc_matrix(K.shape)
        return K, C, self.M

    def newton_matrix(self, x, v, a, t, cv, ca):
        """K_T + cv C + ca M, the Newton matrix of Park's method (eq. 5.34)."""
        S = self._tangent(x) + ca * self.M
        if self.C is not None:
            S = S + cv * self.C
        return S.tocsc()

    def factorize(self, S):
        """Solver of the Newton matrix: the default backend's symmetric-mode sparse LU."""
        from tmfem.solvers.backends import get_backend
        return get_backend().factorize(S)

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


def initial_state(dyn: MTCDynamics, perturb: dict | None, *, h: float = 1e-6):
    """Free-DOF positions and velocities (u0, v0) of the perturbed equilibrium (module docstring).

    The labelled-node field dX/dq is the central difference (step h) of ``system.nodes(q)``
    at the q recovered from the equilibrium; the other free DOFs follow by static condensation
    of the equilibrium tangent.
    """
    model = dyn.model
    system, topo = model.system, model.topology
    u0 = dyn.state0()
    if not perturb:
        return u0, np.zeros_like(u0)
    from tmfem.models.com.simulate import split_perturbation
    dq, dqd = split_perturbation(perturb, system.q_names)
    x_eq = model.full(dyn.xr_eq)
    q_e = q_from_positions(system, x_eq[:, topo.system_node])
    X_e = system.nodes(q_e)
    dX_pos = system.nodes(q_e + dq) - X_e if np.any(dq) else np.zeros_like(X_e)
    J = np.zeros_like(X_e)
    for k in np.flatnonzero(dqd):
        e = np.zeros_like(q_e)
        e[k] = h
        J += (system.nodes(q_e + e) - system.nodes(q_e - e)) / (2 * h) * dqd[k]
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
    from tmfem.solvers.backends import get_backend
    solve = get_backend().factorize(Koo)

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


@dataclass
class MTCVibration:
    """Result of :func:`mtc_free_vibration` (histories as arrays, one row per time)."""

    t: np.ndarray
    q: np.ndarray                 # (nt, nq) generalised coordinates recovered from the bars
    w: np.ndarray                 # (nt, n_points) transverse deflections in O_f [m]
    nodes: dict                   # label -> (nt, 3)
    tendon_deflection: np.ndarray  # (nt,) largest tendon transverse deflection [m]
    kinetic: np.ndarray
    strain: np.ndarray
    columns: list
    wall_time: float
    stats: dict = field(default_factory=dict)

    @property
    def energy(self) -> np.ndarray:
        return self.kinetic + self.strain


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


def mtc_free_vibration(model, x_eq, *, t_end: float, dt: float = 0.01, perturb: dict | None = None,
                       csv_path=None, scheme: str = "park", jacobian: str = "step",
                       alpha: float = 0.0, beta: float = 0.0, monitor_nodes=None,
                       output_points=None, progress: bool = False, vtk_dir=None,
                       vtk_every: int = 10, tol: float = 1e-10) -> MTCVibration:
    """Free vibration of an MTC model from its equilibrium ``x_eq`` (6.5, eqs. 5.34-5.35).

    Parameters
    ----------
    model : MTCModel
    x_eq : ndarray (3, n_nodes)
        Static equilibrium of ``model``.
    t_end, dt : float
        Duration and time step (6.5: dt = 0.01 s).
    perturb : dict
        ``{"theta_12_dot": 0.01}`` etc. (see :func:`initial_state`).
    scheme, jacobian, tol :
        Passed to :func:`park_integrate` (default ``"step"``: one factorisation per step,
        modified Newton; measured on 2-3 at n = 10 it needs half the factorisations of
        ``"reuse"``, whose stale matrices diverge at times and restart with full Newton).
    alpha, beta : float
        Rayleigh damping (default none).
    monitor_nodes : list of str, optional
        Labelled nodes recorded (default ``MONITOR_NODES`` of the preset).
    output_points : list of (x_f, y_f), optional
        Membrane points for w (default ``MONITOR_POINTS`` of the preset, eqs. 5.36, 5.38).
    csv_path, vtk_dir, vtk_every :
        Histories written row by row; ParaView frames every ``vtk_every`` steps.
    """
    from tmfem.models.com.model import MONITOR_POINTS
    from tmfem.models.com.simulate import MONITOR_NODES, RunOutputs
    if not (t_end > 0 and dt > 0):
        raise InputError(f"expected t_end > 0 and dt > 0, found t_end={t_end!r}, dt={dt!r}")
    system, topo = model.system, model.topology
    dyn = MTCDynamics(model, x_eq, alpha=alpha, beta=beta)
    u0, v0 = initial_state(dyn, perturb)
    labels = MONITOR_NODES.get(system.name, []) if monitor_nodes is None else list(monitor_nodes)
    lab_nodes = [topo.system_node[system.node_index(n)] for n in labels]
    pts = MONITOR_POINTS.get(system.name, []) if output_points is None else list(output_points)
    P = point_matrix(model.membrane.skmesh, np.reshape(pts, (-1, 2)).T) if pts else None
    nm = topo.n_mesh
    corners = topo.mesh.corners
    x0 = dyn.positions(u0)
    has_int = topo.tendon_internal.size > 0
    td0 = tendon_transverse(model, model.full(dyn.xr_eq)) if has_int else None
    qn = list(system.q_names)
    wn = [f"w_{i + 1}" for i in range(len(pts))]
    columns = (["t"] + qn + wn + [f"{n}_{c}" for n in labels for c in "xyz"]
               + ["tendon_deflection", "kinetic_energy", "strain_energy"])
    n_steps = int(round(t_end / dt))
    T, Q, W, XS, TD, KE, SE = [], [], [], [], [], [], []
    out = RunOutputs(csv_path=csv_path, columns=columns, vtk_dir=vtk_dir, vtk_every=vtk_every,
                     name=f"mtc_{system.name}", label=f"vibrate {system.name} MTC", dt=dt,
                     t_end=t_end, progress=progress)
    element_tendon = [system.tendons[k].name for k in topo.tendon_of_element]
    worst = [0.0, ""]

    def record(t, u, v, a):
        x = dyn.positions(u)
        q = q_from_positions(system, x[:, topo.system_node])
        if P is not None:
            xm = x[:, :nm]
            w = to_floating((P @ xm.T).T, xm[:, corners])[2]
        else:
            w = np.zeros(0)
        if has_int:
            d = np.linalg.norm(tendon_transverse(model, x) - td0, axis=-1)      # (n_t, k-1)
            k = int(np.argmax(d.max(axis=1)))
            td = float(d[k].max())
            if td > worst[0]:
                worst[:] = [td, system.tendons[k].name]
        else:
            td = 0.0
        ke, se = dyn.kinetic_energy(v), dyn.strain_energy(u)
        out.tendon_forces(t, truss_internal(x, model.tendons, tangent=False).N, element_tendon)
        pos = x[:, lab_nodes]
        if out.frame_due():
            from tmfem.models.mtc.post import member_state, membrane_field
            ms = member_state(model, x)
            out.series.append_configuration(t, system, q=q, tendon_forces=ms["tendon_force"],
                                            rest_lengths=model.rest_lengths,
                                            membrane=membrane_field(model, x),
                                            bar_forces=ms["bar_force"])
        T.append(t); Q.append(q); W.append(w); XS.append(pos); TD.append(td); KE.append(ke)
        SE.append(se)
        out.row(t, np.concatenate([q, w, pos.T.ravel(), [td, ke, se]]))

    res, wall = out.integrate(dyn, x0=u0, v0=v0, n_steps=n_steps, scheme=scheme,
                              jacobian=jacobian, callback=record, tol=tol)
    Xa = np.array(XS)
    stats = out.stats(res)
    stats.update({"ndof": int(dyn.free.sum()), "max_tendon_deflection": worst[0],
                  "max_tendon_deflection_tendon": worst[1]})
    if stats["min_tendon_force"] <= 0:
        print(f"warning: tendon {stats['min_tendon_force_tendon']} went slack at t = "
              f"{stats['min_tendon_force_time']:.4g} s (tension-only in the MTC model)",
              file=sys.stderr)
    return MTCVibration(t=np.array(T), q=np.array(Q), w=np.array(W),
                        nodes={n: Xa[:, :, k] for k, n in enumerate(labels)},
                        tendon_deflection=np.array(TD), kinetic=np.array(KE), strain=np.array(SE),
                        columns=columns, wall_time=wall, stats=stats)


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
