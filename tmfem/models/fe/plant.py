"""The equation of motion of a finite-element model of a tensegrity-membrane system (6.5).

Both finite-element models (MTC, :mod:`tmfem.models.mtc`; SBC, :mod:`tmfem.models.sbc`) are
integrated in time with Park's method (eqs. 5.34-5.35) as the plant

    r(u, v, a; rest) = M a + C v + f_int(u; rest) = 0,      C = alpha M + beta K_0,

on their free reduced dofs u, with the tendon rest lengths as inputs (eq. 5.19), the constant
mass at the equilibrium, K_0 the tangent there and f_int the model's internal force. With
``damping_tangent="current"`` the stiffness-proportional part takes the tangent of the
sampled state instead, C_n = alpha M + beta K_T(x_n), held over the step from t_n
(:meth:`FEPlant.sample`; tangent-stiffness-proportional Rayleigh damping): K_0's axial bar
stiffness along the equilibrium's bar axes damps a bar's rigid rotation away from them, K_T's
does not (docs/guides/fe-plant.md, "Plant damping"). What a
state u *is* differs -- the MTC model's independent node positions, the SBC model's
translations and rotation vectors counted from the equilibrium -- and each model's plant says
so through three hooks (:meth:`FEPlant.configuration`, :meth:`FEPlant.positions`,
:attr:`FEPlant.T`); the rest is shared here:

* **outputs** y (eqs. 3.1-3.2, 5.36-5.38): the bar coordinates q recovered from the bar end
  positions (:func:`tmfem.models.fe.outputs.q_from_positions`) and the membrane transverse
  deflections w_k at the monitored material points (``system.monitor_points``), measured along
  z_f of the floating frame of the current corners (eq. 3.3,
  :func:`tmfem.models.fe.outputs.to_floating`), both from positions in the MTC numbering
  (which the SBC model extends);
* **initial state** (:func:`initial_state`): the equilibrium plus the perturbation of the
  control-oriented model, with the labelled nodes moved rigidly with their bars and the other
  free dofs following by static condensation of K_0.
"""
from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np
import scipy.sparse as sp

from tmfem.equilibrium.general import node_jacobian
from tmfem.errors import InputError
from tmfem.models.base import split_perturbation
from tmfem.models.fe.outputs import MeasuredOutputs, q_from_positions


#: where the stiffness-proportional damping beta K takes its tangent (module docstring)
DAMPING_TANGENTS = ("initial", "current")


def check_damping_tangent(damping_tangent, beta: float) -> str:
    """The damping tangent of an FE plant of stiffness-proportional damping ``beta``: the
    given one of :data:`DAMPING_TANGENTS` (refused without that damping, beta = 0, where the
    tangent does not enter C), default ``"initial"`` (C = alpha M + beta K_0)."""
    if damping_tangent is None:
        return "initial"
    if damping_tangent not in DAMPING_TANGENTS:
        raise InputError(f"damping tangent: expected one of {DAMPING_TANGENTS}, found "
                         f"{damping_tangent!r}")
    if not beta:
        raise InputError(f"damping tangent {damping_tangent!r}: expected stiffness-proportional "
                         f"damping beta > 0 (the tangent enters C through beta K only), found "
                         f"beta = {beta}")
    return damping_tangent


class FEPlant(ABC):
    """Shared part of the finite-element plants (module docstring); a
    :class:`tmfem.models.base.Plant`.

    Subclasses set ``model`` (an FE model, :mod:`tmfem.models.fe.model`: ``residual``,
    ``backend``, ``rest_lengths``, ``set_tendon_lengths`` and the placement ``topology`` the
    positions are numbered on), ``dofmap`` and ``constraints`` (the model's
    :class:`tmfem.fem.constraints.ConstraintMap`) and ``free``, then call :meth:`_setup`; they
    implement :meth:`state0`, :meth:`configuration`, :meth:`positions`,
    :meth:`strain_energy`, :meth:`state_of`, :meth:`member_forces` and
    :meth:`membrane_stress`, and name themselves (``name``: ``"mtc"``, ``"sbc"``).
    """

    name = None
    model = None
    dofmap = None
    constraints = None
    free = None

    def _setup(self, M, *, alpha: float, beta: float, perturb, output_points,
               damping_tangent: str | None = None) -> None:
        """Mass ``M`` (reduced), K_0, damping (``damping_tangent``:
        :func:`check_damping_tangent`), monitored points, names and the start state."""
        if not (np.isfinite(alpha) and np.isfinite(beta) and alpha >= 0 and beta >= 0):
            raise InputError(f"Rayleigh damping: expected alpha, beta >= 0, found {alpha}, {beta}")
        self.damping_tangent = check_damping_tangent(damping_tangent, beta)
        f = self.free
        self.M = M[f][:, f].tocsc()
        self.K0 = self._tangent(self.state0())
        self.alpha, self.beta = float(alpha), float(beta)
        self.C = self.damping_matrix(self.K0) if (alpha or beta) else None
        system = self.model.system
        self.measured = MeasuredOutputs(system, self.model.topology, output_points)
        self.output_points = self.measured.points
        self.u0 = np.asarray(self.model.rest_lengths, dtype=float).copy()
        self.input_names = [f"r_{t.name}" for t in system.tendons]
        self.output_names = self.measured.names
        self.x0, self.v0 = initial_state(self, perturb)

    # hooks -------------------------------------------------------------------------------
    @abstractmethod
    def state0(self) -> np.ndarray:
        """The equilibrium as a free-dof state."""

    @abstractmethod
    def configuration(self, u):
        """The argument of ``model.residual`` for the free-dof state u."""

    @abstractmethod
    def positions(self, u) -> np.ndarray:
        """Node positions (3, n) in the MTC numbering of the free-dof state u."""

    @abstractmethod
    def strain_energy(self, u) -> float:
        """Strain energy [J] of the free-dof state u."""

    @abstractmethod
    def state_of(self, xf: np.ndarray) -> np.ndarray:
        """The free-dof state whose node positions (MTC numbering) are xf (3, n)."""

    @abstractmethod
    def member_forces(self, u) -> dict:
        """Tendon element forces ``element_force``, tendon forces ``tendon_force`` and bar
        axial forces ``bar_force`` [N] at the free-dof state u, and per tendon whether one of
        its elements is slack (``tendon_slack``)."""

    @abstractmethod
    def membrane_stress(self, u) -> dict:
        """Peak membrane stresses [Pa] ``max_von_mises``, ``max_sigma_p1`` at u."""

    def translation_rows(self, nodes) -> np.ndarray:
        """Rows (len(nodes), 3) of the constraint matrix T (all dofs x reduced dofs) that
        carry the translations of ``nodes``."""
        return self.dofmap.translation_dofs(np.asarray(nodes))

    # Plant protocol (tmfem.models.base) ---------------------------------------------------
    def _inputs(self, u) -> None:
        # the plant drives its model: the tendon rest lengths are the inputs of this call
        # (the nominal u0 when none are given), so the model is left at the last u
        self.model.set_tendon_lengths(self.u0 if u is None else u)

    def residual(self, x, v, a, t, u=None):
        """r = M a + C v + f_int(x; u) on the free dofs (module docstring)."""
        self._inputs(u)
        r, _ = self.model.residual(self.configuration(x), tangent=False)
        out = r[self.free] + self.M @ a
        if self.C is not None:
            out = out + self.C @ v
        return out

    def _tangent(self, x):
        """Tangent K_T (eqs. 4.4-4.6) on the free dofs at the free-dof state x."""
        _, K = self.model.residual(self.configuration(x))
        return K[self.free][:, self.free].tocsc()

    def damping_matrix(self, K):
        """Rayleigh damping C = alpha M + beta K of the tangent K (K_0, or K_T(x_n))."""
        return (self.alpha * self.M + self.beta * K).tocsc()

    def sample(self, x, u=None) -> None:
        """The driver's hook at every sample (:func:`tmfem.simulation.driver.simulate`): with
        ``damping_tangent="current"`` C_n = alpha M + beta K_T(x_n; u) at the sampled state
        x_n under the input u held over the step, kept until the next sample (dr/dv = C_n
        stays exact in Park's Newton); with ``"initial"`` nothing (C = alpha M + beta K_0)."""
        if self.damping_tangent == "current":
            self._inputs(u)
            self.C = self.damping_matrix(self._tangent(x))

    def jacobians(self, x, v, a, t, u=None):
        """(dr/dx, dr/dv, dr/da) = (K_T, C, M)."""
        self._inputs(u)
        K = self._tangent(x)
        C = self.C if self.C is not None else sp.csc_matrix(K.shape)
        return K, C, self.M

    def mass_matrix(self, x, v, t):
        """dr/da = M, the reduced mass matrix (constant)."""
        return self.M

    def newton_matrix(self, x, v, a, t, cv, ca, u=None):
        """K_T + cv C + ca M, the Newton matrix of Park's method (eq. 5.34)."""
        self._inputs(u)
        S = self._tangent(x) + ca * self.M
        if self.C is not None:
            S = S + cv * self.C
        return S.tocsc()

    def factorize(self, S):
        """Solver of the Newton matrix: the model's backend."""
        return self.model.backend.factorize(S)

    def outputs(self, x, v=None, u=None) -> np.ndarray:
        """y = [q, w_k]: bar coordinates from the bar nodes (eqs. 3.1-3.2) and membrane
        deflections along z_f of the floating frame at the output points (eqs. 5.36-5.38)."""
        return self.outputs_of(self.positions(x))

    def outputs_of(self, xf: np.ndarray) -> np.ndarray:
        """:meth:`outputs` of positions xf (3, n) in the MTC numbering."""
        return self.measured.of(xf)

    def kinetic_energy(self, v) -> float:
        """v^T M v / 2 [J] of the free-dof velocities v."""
        return 0.5 * float(v @ (self.M @ v))


def perturbation_names(system) -> list:
    """Accepted perturbation names: the q of 3.2 and their rates (``theta_12_dot``)."""
    return list(system.q_names) + [n + "_dot" for n in system.q_names]


def initial_state(dyn: FEPlant, perturb: dict | None):
    """Free-dof state and velocity (u0, v0) of the perturbed equilibrium.

    A generalised coordinate q_k of 3.2 moves the labelled nodes rigidly: their velocity is
    dX/dq q' (exact, :func:`tmfem.equilibrium.general.node_jacobian`, at the q recovered from
    the equilibrium) and a displacement moves them by X(q_e + dq) - X(q_e). The remaining free
    dofs (membrane, tendon internal nodes, and in the SBC model the rotations and bar interior
    nodes) get the quasi-static field that follows them, v_o = -K_oo^-1 K_op v_p with K_0
    (static condensation): for a straight prestressed tendon the linear interpolation of its
    end velocities, for a bar the rigid rotation, for the membrane the smooth deformation its
    prestress imposes -- the counterpart of the COM, whose membrane follows the bars through
    its floating frame (eqs. 5.1-5.3) with the membrane modal rates at zero.
    """
    model, system = dyn.model, dyn.model.system
    u0 = dyn.state0()
    if not perturb:
        return u0, np.zeros_like(u0)
    dq, dqd = split_perturbation(perturb, system.q_names)
    x_eq = dyn.positions(u0)
    q_e = q_from_positions(system, x_eq[:, dyn.model.topology.system_node])
    X_e = system.nodes(q_e)
    dX_pos = system.nodes(q_e + dq) - X_e if np.any(dq) else np.zeros_like(X_e)
    J = node_jacobian(system, q_e) @ dqd                       # dX/dq q' (eqs. 3.1-3.2)
    T = sp.csr_matrix(dyn.constraints.T)
    rows = dyn.translation_rows(dyn.model.topology.system_node)  # (n_labels, 3)
    n_red = T.shape[1]
    pres = np.zeros(n_red, dtype=bool)
    vp = np.zeros(n_red)
    dp = np.zeros(n_red)
    for i, rr in enumerate(rows):
        moved = np.any(J[:, i]) or np.any(dX_pos[:, i])
        nnz = T.indptr[rr + 1] - T.indptr[rr]
        if np.all(nnz == 0):                  # eliminated (fixed) node
            continue
        start = T.indptr[rr]
        if not (np.all(nnz == 1) and np.all(T.data[start] == 1.0)):
            if moved:
                raise InputError(f"perturbation of {system.node_labels[i]}: needs "
                                 f"attachment='point' (the bar top is a weighted patch "
                                 f"point here)")
            continue
        cols = T.indices[start]
        pres[cols] = True
        vp[cols] = J[:, i]
        dp[cols] = dX_pos[:, i]
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
