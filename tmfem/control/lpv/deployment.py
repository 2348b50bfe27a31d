"""The LPV deployment of dissertation 8.4 (the 2-3 system; any symmetric M >= 2 system on
its grid's stage-base rule): reference of eq. 5.100, the COM plant, the measurement of the
LPV states and scheduling parameters, and any controller on them.

Reference (eq. 5.100): theta_r'' + 2 xi_r omega_r theta_r' + omega_r^2 theta_r =
omega_r^2 theta_e with theta_r(0) = theta_0, theta_r'(0) = 0 and psi_r = psi_0 (xi_r = 1,
omega_r = 0.3 rad/s, theta 77.32 -> 63 deg, psi_0 = 8.36 deg); q_d follows from eq. 5.97 with
the stage bases of the design grid (:func:`tmfem.reference.deployments.lpv_bases`), the
closed form and path of :class:`tmfem.control.deployment.reference_trajectory.DeploymentReference`
(eq. 5.100 is eq. 5.68 with a constant psi).

Plant: the control-oriented model (eq. 5.27) built at the final configuration with its
designed rest lengths, in modal membrane coordinates, started at rest in the initial
configuration (as the 7.4 deployments, :func:`tmfem.control.deployment.run.run_deployment`: Park's
method, rest-length limits), or an FE plant through its COM-state estimate started in its own
equilibrium of :meth:`LPVDeployment.packaged` (docs/guides/fe-plant.md).

Over-actuated systems (more tendons than bar coordinates, M >= 3): the scheduled feedback
commands every rest length; where its command leaves the rest-length limits, the limits are
met as in the 7.4 deployment (:class:`MinimumChangeAllocation`: the admissible rest lengths
whose bar acceleration is closest to the commanded one, the bounded inversion of
:func:`tmfem.control.deployment.pfl.bounded_inversion` regularised toward the command, with the
tension floor of :mod:`tmfem.control.deployment.adaptive` about u_e(rho_r(t))), not by
clipping each rest length on its own (a square system keeps the clipping of 8.4: its inversion
has no freedom, and the limits change the acceleration either way).

Measurement (:meth:`LPVDeployment.measure`): the plant's y = [z, z'] (modal) mapped onto the
signals of the LPV design, y_lpv = [x_z, rho] with x_z = [q, v, q', v'] (v = T_v_eta eta, the
membrane point coordinates of eq. 5.17 at the design plant's points) and rho = [theta_1N,
psi_1N] (theta_13, psi_13 for N = 3) read from q (8.4 schedules on the measured angles). Any controller with the
reset/output/update/name protocol of :mod:`tmfem.simulation.controllers` on y_lpv deploys
through :meth:`LPVDeployment.setup` (the state feedback: :func:`state_feedback_controller`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.control.deployment.limits import tendon_lengths
from tmfem.control.deployment.pfl import bounded_inversion, partition
from tmfem.control.deployment.reference_trajectory import DeploymentReference, angle_mask
from tmfem.control.deployment.run import DeploymentSetup
from tmfem.control.lpv.controller import LPVController
from tmfem.control.lpv.output_feedback import LPVOutputController, design_output_feedback
from tmfem.control.lpv.plant import scheduling_parameters
from tmfem.equilibrium.symmetric_map import configuration_5_97, with_configuration
from tmfem.errors import InputError
from tmfem.models.com.coordinates import point_coordinates
from tmfem.models.com.model import ControlOrientedModel
from tmfem.system.geometry import wrap_angle
from tmfem.system.problem import TENSION_FLOOR

class Measured:
    """A controller on y_lpv = measure(y): the protocol of :mod:`tmfem.simulation.controllers`
    with the plant outputs mapped first (the name is the inner controller's)."""

    def __init__(self, inner, measure):
        if not all(hasattr(inner, m) for m in ("reset", "output", "update", "name")):
            raise InputError(f"LPV deployment: expected a controller with reset/output/update/name "
                             f"(tmfem.simulation.controllers), found {type(inner).__name__}")
        self.inner, self.measure = inner, measure

    @property
    def name(self) -> str:
        return self.inner.name

    def reset(self, t0, y0, dt):
        return self.inner.reset(t0, self.measure(y0), dt)

    def output(self, t, y, xc):
        return self.inner.output(t, self.measure(y), xc)

    def update(self, t, y, xc):
        return self.inner.update(t, self.measure(y), xc)


class MinimumChangeAllocation:
    """The rest-length limits of an over-actuated LPV deployment met by the 7.4 inversion.

    With the command u_c of ``inner`` (reading the plant outputs y = [z, z'], modal), the PFL
    terms of eq. 5.41 at the measured state (M_q, B_q: the bar accelerations q'' = -F_q* -
    B_q u) and the limits r_min <= u <= |tendon|(q) - f (L_d - u_d) (L_d the tendon lengths at
    q_d(t), u_d = ``u_d(t)``, f the tension floor), u_c itself when it lies inside, else

        min_u |R B_q (u - u_c)|^2 + eps^2 |u - u_c|^2   subject to the limits,

    M_q = R^T R, eps = 1e-6 s_1 (:func:`tmfem.control.deployment.pfl.bounded_inversion` with
    v = B_q u_c and u_ref = u_c): the admissible rest lengths whose acceleration is closest
    to the commanded one, the smallest change of u among them. ``allocation_active``: the
    times the limits changed the command.
    """

    def __init__(self, inner, *, model, reference, u_d, r_min: float = 1e-3, floor: float = TENSION_FLOOR):
        if not (np.isfinite(floor) and 0 <= floor < 1):
            raise InputError(f"tension floor: expected a number in [0, 1), found {floor!r}")
        self.inner, self.model, self.reference, self.u_d = inner, model, reference, u_d
        self.r_min, self.floor = float(r_min), float(floor)
        self.allocation_active: list = []

    @property
    def name(self) -> str:
        return self.inner.name

    def reset(self, t0, y0, dt):
        self.allocation_active = []
        return self.inner.reset(t0, y0, dt)

    def update(self, t, y, xc):
        return self.inner.update(t, y, xc)

    def output(self, t, y, xc):
        u = np.asarray(self.inner.output(t, y, xc), dtype=float)
        m, y = self.model, np.asarray(y, dtype=float)
        ud = self.u_d(t)
        L_d = tendon_lengths(m.system, np.asarray(self.reference(t)[0], dtype=float)).copy()
        upper = tendon_lengths(m.system, y[:m.nq]) - self.floor * np.maximum(L_d - ud, 0.0)
        if np.all(u >= self.r_min) and np.all(u <= upper):
            return u
        terms = partition(*m.matrices(y[:m.nz], y[m.nz:2 * m.nz]), nq=m.nq)
        self.allocation_active.append(float(t))
        return bounded_inversion(terms, terms.B_q @ u, lower=self.r_min, upper=upper, u_ref=u)[0]


@dataclass
class LPVDeployment:
    """Model, reference and measurement of the 8.4 deployment (module docstring); ``plant``
    is the design :class:`~tmfem.control.lpv.plant.GriddedLPV` (grid, equilibria, points)."""

    model: object
    reference: object
    plant: object
    T_veta: np.ndarray
    z0: np.ndarray
    z_e: np.ndarray
    rho_q: list
    info: dict
    initial: object = None
    floor: float = TENSION_FLOOR
    r_min: float = 1e-3

    def on_turn(self, plant):
        """``plant`` (a gridded plant of this deployment's system) with the bar angles of its
        equilibria on the turn of the reference's start q_d(0) (:meth:`GriddedLPV.on_turn`):
        the measured angles of the plant (a COM state, integrated; an FE plant's estimate,
        counted continuously) stay on that turn, so x_z - x_e(rho_r) holds no whole turn."""
        names = list(self.model.system.q_names)
        q0 = np.asarray(self.reference(0.0)[0], dtype=float)
        angles = {n: float(v) for n, v, a in zip(names, q0, angle_mask(names)) if a}
        return plant.on_turn(self.reference_rho(0.0), angles)

    def packaged(self):
        """The initial (packaged) configuration as a designed System: its rest lengths those
        the run starts with, u_e of the design grid at rho_r(0) (the controller's first
        output at rest on the reference) -- the start of an FE plant
        (:func:`tmfem.control.fe_plant.state_estimate.deployment_plant`)."""
        return self.initial.replace(rest_lengths=self.plant.interpolate("u_e", self.reference_rho(0.0)))

    @property
    def signal_names(self) -> list:
        """Names of y_lpv: the design plant's states, then its parameters."""
        return list(self.plant.state_names) + list(self.plant.parameter_names)

    def reference_rho(self, t) -> np.ndarray:
        """rho_r(t) = [theta_1N, psi_1N] of the reference q_d(t) (eq. 5.100: theta_r, psi_0)."""
        r = np.asarray(self.reference(t)[0], dtype=float)[self.rho_q].copy()
        r[1] = wrap_angle(r[1])
        return r

    def measure(self, y) -> np.ndarray:
        """y_lpv = [q, v, q', v', rho] from the plant outputs y = [z, z'] (modal)."""
        y = np.asarray(y, dtype=float)
        m = self.model
        nq, nz = m.nq, m.nz
        q, eta, qd, etad = y[:nq], y[nq:nz], y[nz:nz + nq], y[nz + nq:2 * nz]
        rho = q[self.rho_q].copy()
        rho[1] = wrap_angle(rho[1])
        return np.concatenate([q, self.T_veta @ eta, qd, self.T_veta @ etad, rho])

    def setup(self, controller):
        """The :class:`tmfem.control.deployment.run.DeploymentSetup` of ``controller`` (any object with
        the reset/output/update/name protocol on y_lpv) for :func:`~tmfem.control.deployment.run.
        run_deployment` and :func:`tmfem.reference.deployments.write_outputs`."""
        c = Measured(controller, self.measure)
        info = dict(self.info)
        if self.model.n_t > self.model.nq:              # over-actuated: the 7.4 inversion
            c = MinimumChangeAllocation(c, model=self.model, reference=self.reference, r_min=self.r_min,
                                        floor=self.floor,
                                        u_d=lambda t: self.plant.interpolate("u_e", self.reference_rho(t)))
            info.update(allocation="minimum-change", tension_floor=self.floor)
        return DeploymentSetup(model=self.model, reference=self.reference, adaptive=None,
                               controller=c, linear=None, z0=self.z0, z_e=self.z_e, info=info)


def lpv_deployment(system, plant, *, theta_0: float, theta_e: float, psi_0: float, omega_r: float,
                   bases, output_points, membrane_modes: int = 4, model_at: str = "final",
                   floor: float = TENSION_FLOOR, r_min: float = 1e-3) -> LPVDeployment:
    """The deployment of 8.4 of ``system`` from theta_0 to theta_e at psi_0 [rad] (eq. 5.100,
    xi_r = 1, ``omega_r`` [rad/s]) for the design plant ``plant``
    (:func:`~tmfem.control.lpv.plant.com_lpv_plant` of the same system with the same
    ``bases`` rule; its membrane points define v); ``output_points``: the monitored membrane
    points (eq. 5.101); ``floor`` and ``r_min``: the tension floor and the smallest rest
    length of an over-actuated system's allocation (:class:`MinimumChangeAllocation`).

    Raises
    ------
    InputError
        The reference leaves the design grid, or the plant has no membrane points.
    """
    for nm, v in zip(scheduling_parameters(system.N), ((theta_0, theta_e), (psi_0, psi_0))):
        a = plant.axes[plant.parameter_names.index(nm)]
        if min(v) < a[0] - 1e-9 or max(v) > a[-1] + 1e-9:
            raise InputError(f"LPV deployment: expected the reference {nm} in "
                             f"[{np.degrees(min(v)):.4g}, {np.degrees(max(v)):.4g}] deg inside the design "
                             f"grid, found the grid [{np.degrees(a[0]):.4g}, {np.degrees(a[-1]):.4g}] deg")
    if not plant.membrane_points:
        raise InputError("LPV deployment: expected a design plant with membrane point coordinates "
                         "(eq. 5.17, com_lpv_plant), found none")
    final = with_configuration(system, configuration_5_97(system, theta_e, psi_0, **bases(theta_e, psi_0)))
    initial = with_configuration(system, configuration_5_97(system, theta_0, psi_0, **bases(theta_0, psi_0)))
    if model_at not in ("final", "initial"):
        raise InputError(f"LPV deployment: model_at expected 'final' or 'initial', found {model_at!r}")
    model = ControlOrientedModel(final if model_at == "final" else initial, membrane_modes=membrane_modes,
                                 output_points=output_points)
    _, T_veta, _ = point_coordinates(model.membrane, plant.membrane_points)
    ref = DeploymentReference(initial=initial.symmetric, final=final.symmetric, N=final.N,
                              q_names=list(final.q_names), omega_r=omega_r, bases=bases)
    z0 = np.concatenate([ref.q_0, np.zeros(model.K)])
    z_e = model.equilibrium(model.u0, z0=np.concatenate([ref.q_e, np.zeros(model.K)])).state
    info = {"omega_r": omega_r, "xi_r": 1.0, "theta_0_deg": float(np.degrees(theta_0)),
            "theta_e_deg": float(np.degrees(theta_e)), "psi_0_deg": float(np.degrees(psi_0)), "K": model.K,
            "lpv_grid": list(plant.grid_shape)}
    dep = LPVDeployment(model=model, reference=ref, plant=plant, T_veta=T_veta, z0=z0, z_e=z_e,
                        rho_q=[list(final.q_names).index(n) for n in plant.parameter_names], info=info,
                        initial=initial, floor=floor, r_min=r_min)
    dep.plant = dep.on_turn(plant)
    return dep


def state_feedback_controller(dep: LPVDeployment, design):
    """The scheduled state feedback of 8.3 (:class:`tmfem.control.lpv.controller.LPVController`)
    of ``design`` on y_lpv, tracking q_d of eq. 5.100, gains at the measured rho, equilibria
    x_e, u_e at the reference's rho_r(t).

    Raises
    ------
    InputError
        ``design`` is not over the states of the deployment's design plant.
    """
    pl = dep.plant
    nq = dep.model.nq
    want = list(pl.state_names) + [f"int_e_{n}" for n in dep.model.system.q_names]
    if list(design.state_names) != want:
        raise InputError(f"LPV controller: expected a design over the {len(want)} states of the "
                         f"{pl.grid_shape} design plant ([x_z, integrals of e_q], eq. 5.98), found "
                         f"{len(design.state_names)} states"
                         + ("" if len(design.state_names) != len(want) else " with other names"))
    for a, b in zip(design.axes, pl.axes):
        if a.shape != b.shape or not np.allclose(a, b, rtol=0, atol=1e-9):
            want = [np.degrees(x).round(2).tolist() for x in pl.axes]
            got = [np.degrees(x).round(2).tolist() for x in design.axes]
            raise InputError(f"LPV controller: expected the design grid {want} deg, found {got} deg")
    n = pl.nx
    return LPVController(design, pl, state_index=np.arange(n), q_index=np.arange(nq),
                         rho_index=[n, n + 1], reference=lambda t: dep.reference(t)[0],
                         reference_rho=dep.reference_rho)


def output_feedback_controller(dep: LPVDeployment, design, *, interpolation: str = "multilinear",
                               estimator_plant=None):
    """The observer-based output feedback of :mod:`tmfem.control.lpv.output_feedback` with
    ``design``'s K(rho) and a gridded Kalman estimator (W_d = W_n = 0.001) on the design plant,
    reading the positions of y_lpv (q and the membrane point coordinates of eq. 5.17), scheduled on
    the estimated theta_13, psi_13 (the measured ones at the start: noise in the measured rho
    enters x_e(rho), u_e(rho) and K(rho) unfiltered, docs/guides/lpv.md); the control law about rho_r(t)
    as the state feedback's; the estimator is driven by the input saturated to the rest-length
    limits [1 mm, |tendon|(q_m)] of the run at the measured q.

    Parameters
    ----------
    interpolation : {"multilinear", "spline"}
        The estimator's between grid points (:class:`~tmfem.control.lpv.plant.GriddedLPV`).
    estimator_plant : GriddedLPV, optional
        The estimator's plant on a finer grid than the design's (default the design plant).
    """
    pl, system = dep.plant, dep.model.system
    nz, n, nq = pl.nx // 2, pl.nx, dep.model.nq
    of = design_output_feedback(design, pl if estimator_plant is None else estimator_plant,
                                tracked=system.q_names, measured=pl.state_names[:nz],
                                interpolation=interpolation)
    return LPVOutputController(of, measured_index=np.arange(nz), rho_index=[n, n + 1],
                               reference=lambda t: dep.reference(t)[0], reference_rho=dep.reference_rho,
                               schedule="estimate",
                               input_limits=lambda u, ym: np.clip(u, 1e-3, tendon_lengths(system, ym[:nq])))
