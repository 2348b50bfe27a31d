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

**Outputs per step** (:class:`tmfem.simulation.vibration.FEVibration`, CSV row by row): theta and psi of every bar
(recovered from the bar vectors, :func:`tmfem.models.mtc.post.q_from_positions`), the monitored bar
ends (``MONITOR_NODES``: B_12, B_14 for 1-4; A_21, B_11, B_21 for 2-3; Figs. 6.21-6.22,
6.25-6.27), the membrane transverse deflections w_1..w_3 at the material points of eqs.
5.36 / 5.38 (the ``MONITOR_POINTS`` of the COM, reference coordinates in O_f) measured along z_f
of the floating frame of the current corners (eq. 3.3, :func:`tmfem.models.fe.topology.to_floating`),
and the largest tendon transverse deflection: the internal nodes' offset from the chord in the
local frame e_t1 (chord), e_t2 = e_t1 x e_z / |.|, e_t3 = e_t1 x e_t2 (eq. 5.37; Figs. 6.24,
6.29), relative to its value at the equilibrium.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError
from tmfem.models.fe.plant import FEPlant


class MTCDynamics(FEPlant):
    """The MTC equation of motion on the free DOFs as a :class:`tmfem.models.base.Plant`
    (:class:`tmfem.models.fe.plant.FEPlant`: inputs, outputs, initial state).

    Inputs u: the tendon rest lengths ``r_<tendon>`` (each tendon's k elements get u / k);
    outputs y: the bar coordinates q recovered from the bar nodes (eqs. 3.1-3.2) and the
    transverse deflections w_k in the floating frame at ``output_points`` (eqs. 5.36-5.38),
    as a sensor would measure them. The state is the free independent node positions; the
    start state ``x0, v0`` is the equilibrium with the perturbation of
    :func:`tmfem.models.fe.plant.initial_state`.

    Parameters
    ----------
    model : MTCModel
    x_eq : ndarray (3, n_nodes)
        The static equilibrium (``model.equilibrium().x``); the fixed DOFs stay there.
    alpha, beta : float
        Rayleigh damping C = alpha M + beta K_0 [1/s, s] (default: undamped).
    damping_tangent : {"initial", "current"}, optional
        The tangent of beta K: K_0 at x_eq (default) or K_T at every sampled state
        (:meth:`tmfem.models.fe.plant.FEPlant.sample`); only with beta > 0.
    perturb : dict, optional
        Initial perturbation by coordinate name (``theta_12_dot=0.01``).
    output_points : array (2, n) or list of (x_f, y_f), optional
        Default ``system.monitor_points``.
    """

    name = "mtc"

    def __init__(self, model, x_eq, *, alpha: float = 0.0, beta: float = 0.0,
                 perturb: dict | None = None, output_points=None,
                 damping_tangent: str | None = None):
        self.model = model
        self.dofmap, self.constraints = model.topology.dofmap, model.topology.constraints
        self.free = model.free
        self.xr_eq = model.reduce(np.asarray(x_eq, dtype=float))
        self._setup(model.mass(), alpha=alpha, beta=beta, perturb=perturb,
                    output_points=output_points, damping_tangent=damping_tangent)

    def state0(self) -> np.ndarray:
        """The equilibrium as a free-DOF state."""
        return self.xr_eq[self.free].copy()

    def reduced(self, u) -> np.ndarray:
        """Independent positions (flat, 3 n_red) of the free-DOF state u (fixed DOFs at x_eq)."""
        xr = self.xr_eq.copy()
        xr[self.free] = u
        return xr

    configuration = reduced

    def positions(self, u) -> np.ndarray:
        """Full node positions (3, n_nodes) of the free-DOF state u."""
        return self.model.full(self.reduced(u))

    def strain_energy(self, x) -> float:
        """Strain energy [J] of membrane, bars and tendons (:meth:`MTCModel.energy`)."""
        return self.model.energy(self.reduced(x))

    def member_forces(self, x) -> dict:
        """Tendon element forces, tendon forces and bar forces [N] at the free-DOF state x
        (:func:`tmfem.models.mtc.post.member_state`)."""
        from tmfem.models.mtc.post import member_state
        return member_state(self.model, self.positions(x))

    def state_of(self, xf: np.ndarray) -> np.ndarray:
        """The free-DOF state of full node positions xf (3, n_nodes)."""
        return self.model.reduce(xf)[self.free]

    def membrane_stress(self, x) -> dict:
        """Peak membrane stresses [Pa] (``max_von_mises``, ``max_sigma_p1``) at the Gauss
        points of the free-DOF state x (:func:`tmfem.models.mtc.post.membrane_stress_summary`)."""
        from tmfem.models.mtc.post import membrane_stress_summary
        m = membrane_stress_summary(self.model, self.positions(x))
        return {"max_von_mises": m["max_von_mises"], "max_sigma_p1": m["max_sigma_p1"]}


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
