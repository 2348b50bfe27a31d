"""Closed-loop deployment runs (dissertation 7.4): reference, adaptive PFL, switch to a linear
controller, rest-length limits, stress recovery and the zero dynamics.

Measurement. The deployment controller is a full-state feedback (7.2): the plant is
:class:`StatePlant`, the control-oriented model (eq. 5.27) whose outputs are the full state
y = [z, z'] (modal membrane coordinates). A linear controller on the measured outputs
[q, w] of eq. 5.62 reads them through ``measure`` (:func:`output_measure`).

Rest-length limits (7.4): :class:`tmfem.control.deployment.limits.RestLengthLimits` saturates the
commanded inputs to [r_min, |tendon|(q)]; the adaptive PFL may already honour them in its
inversion (``allocation="bounded"``, :mod:`tmfem.control.deployment.adaptive`).

Stress recovery after the run (:mod:`tmfem.control.deployment.recovery`): tendon stress T / A with
T = k (|d| - r) (eq. 3.8) at every sample; every ``stress_every`` samples the bar
compression from the equilibrium of each bar under the tendon and membrane-corner forces (as
in the design checks, eq. 5.31 against the Euler load) and the maximum von Mises stress of
the in-plane membrane solution for the current corner displacements (eq. 5.30, the linear
plane-stress FE of the equilibrium design). Zero
dynamics (7.6): the energy of the membrane coordinates, E_eta = 1/2 |eta'|^2 +
1/2 sum omega_i^2 eta_i^2 (mass-normalised modes).
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np
from threadpoolctl import threadpool_limits

from tmfem.control.deployment.adaptive import ALLOCATION, AdaptivePFL, reference_centers
from tmfem.control.deployment.limits import RestLengthLimits
from tmfem.control.deployment.rbf import GaussianRBF
from tmfem.control.deployment.recovery import StressRecovery
from tmfem.control.deployment.reference_trajectory import DeploymentReference, angle_mask
from tmfem.control.deployment.switching import SwitchingController, relative_error
from tmfem.control.linear.deployed_design import deployed_hinf, mode_frequencies_hz
from tmfem.equilibrium.deployment_path import path_feasibility
from tmfem.equilibrium.symmetric import check_1ND
from tmfem.equilibrium.symmetric_map import with_configuration
from tmfem.errors import ConvergenceError, InputError, SlackMembrane, SlackTendon
from tmfem.system.problem import TENSION_FLOOR
from tmfem.models.com.linearize import linearize
from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes
from tmfem.models.com.plant import COMPlant
from tmfem.simulation.controllers import LinearController
from tmfem.simulation.driver import simulate

log = logging.getLogger(__name__)


class StatePlant(COMPlant):
    """The COM plant (eq. 5.27) with outputs y = [z, z'] (full-state measurement), started at
    (z0, 0)."""

    def __init__(self, model, *, z0):
        super().__init__(model)
        self.x0 = np.asarray(z0, dtype=float)
        self.v0 = np.zeros(model.nz)
        self.output_names = model.state_names

    def outputs(self, x, v, u):
        return np.concatenate([x, v])


def output_measure(model):
    """y = [z, z'] -> [q, w] of the model (the measured outputs of eq. 5.62)."""
    nz = model.nz
    return lambda y: model.outputs(np.asarray(y)[:nz])


def lqr_state_feedback(model, *, u_e, z_e=None, u_m: float = 0.01, q_weight: float = 1.0):
    """A linear state-feedback controller about the final equilibrium: the LQR gain of the
    linearisation (eq. 5.33) with Q = q_weight I and R = I / u_m^2 (the W_u = I / u_m of
    7.4), python-control ``lqr``, as a :class:`LinearController` on y = [z, z'].

    This is a stand-in for the H-infinity output-feedback controller of 7.3 (any
    LinearController about the same point plugs into :class:`SwitchingController`)."""
    import control
    lin = linearize(model, z_e=z_e, u_e=u_e)
    n = lin.A.shape[0]
    K, _, _ = control.lqr(lin.A, lin.B, q_weight * np.eye(n), np.eye(lin.B.shape[1]) / u_m**2)
    y_e = np.concatenate([lin.z_e, np.zeros(model.nz)])
    return LinearController(-np.asarray(K), u_e=lin.u_e, y_e=y_e, name="lqr"), lin


def hinf_output_feedback(model, *, u_e, z_e=None, w_e: float = 0.5, w_n: float = 1e-3,
                         u_m: float = 0.01):
    """A Riccati H-infinity output-feedback controller (python-control ``hinfsyn``) on the
    measured outputs [q, w] about the final equilibrium, with the weights of 7.4
    (W_e = 0.5 I on the state error, measurement noise 0.001 I, W_u = I / u_m). A stand-in
    for the LMI synthesis of 7.3 (eq. 5.65: alpha-stability not imposed here)."""
    import control
    lin = linearize(model, z_e=z_e, u_e=u_e)
    A, B2 = lin.A, lin.B
    n, nu = A.shape[0], B2.shape[1]
    C2 = lin.Cy
    ny = C2.shape[0]
    B1 = np.hstack([np.vstack([np.zeros((n // 2, n // 2)), np.eye(n // 2)]) * 1e-2,
                    np.zeros((n, ny))])
    C1 = np.vstack([w_e * np.eye(n), np.zeros((nu, n))])
    D12 = np.vstack([np.zeros((n, nu)), np.eye(nu) / u_m])
    D21 = np.hstack([np.zeros((ny, n // 2)), w_n * np.eye(ny)])
    P = control.ss(A, np.hstack([B1, B2]), np.vstack([C1, C2]),
                   np.block([[np.zeros((C1.shape[0], B1.shape[1])), D12],
                             [D21, np.zeros((ny, nu))]]))
    Kc, _, gam, _ = control.hinfsyn(P, ny, nu)
    return LinearController(Kc, u_e=lin.u_e, y_e=lin.y_e, name="hinf-riccati"), lin, float(gam)


#: names of the H-infinity controllers of 7.3 by synthesis method
HINF_NAMES = {"central": "hinf-central", "lmi": "hinf-lmi", "riccati": "hinf-shifted-riccati"}
#: the linear controller's state at the switch (:class:`SwitchingController`) by method:
#: the central controller is an observer of the measured state (its state starts at it)
HINF_STARTS = {"central": "estimate", "lmi": "bumpless", "riccati": "bumpless"}


def lmi_hinf_controller(system, *, membrane_modes: int, method: str = "central", z_e=None):
    """The H-infinity controller of 7.3 (eqs. 5.62-5.67, :func:`tmfem.control.linear.deployed_design.
    deployed_hinf` with the 7.4 weights and alpha_1: the central controller at 1.01
    gamma_opt (default, solver-independent, :mod:`tmfem.control.linear.hinf_central`), the
    eliminated LMIs (``"lmi"``, one solver-dependent member of the degenerate optimum's
    family) or ``method="riccati"``, python-control ``hinfsyn`` on the alpha-shifted
    plant) as a :class:`LinearController`, with ``measure`` mapping the
    modal state y = [z, z'] of :class:`StatePlant` onto the design's measured signals
    [q, v, q', v'] (membrane point coordinates of eq. 5.18: z_points = P^-1 z_modal, the
    same linear map for the rates). ``z_e``: the run's equilibrium state, whose angles
    (theta, psi) may lie on another 2 pi branch than the design's (a path continued through
    psi = 180 deg); the controller's set point is then moved onto that branch.

    Returns
    -------
    controller, measure, design
        ``design``: the :class:`~tmfem.control.linear.deployed_design.DeployedDesign`.
    """
    if method not in HINF_NAMES:
        raise InputError(f"H-infinity method: expected one of {sorted(HINF_NAMES)}, found {method!r}")
    d = deployed_hinf(system, membrane_modes=membrane_modes, method=method)
    pl = d.plant
    P = pl.model.P
    z_set = pl.z_e
    if z_e is not None:
        nq = len(system.q_names)
        turns = np.zeros(z_set.size)
        turns[:nq] = np.where(angle_mask(system.q_names), np.round((z_e[:nq] - z_set[:nq]) / (2 * np.pi)), 0)
        z_set = z_set + 2 * np.pi * turns if turns.any() else z_set
    y_e = np.concatenate([z_set, np.zeros(pl.z_e.size)])
    ctrl = LinearController(d.design.controller, u_e=pl.u_e, y_e=y_e, name=HINF_NAMES[method])
    nz = P.shape[0]

    def measure(y):
        y = np.asarray(y)
        return np.linalg.solve(P, np.column_stack([y[:nz], y[nz:2 * nz]])).T.ravel()
    return ctrl, measure, d


@dataclass
class DeploymentResult:
    """Signals and figures of a deployment run (see :func:`run_deployment`)."""

    t: np.ndarray
    z: np.ndarray
    zd: np.ndarray
    u: np.ndarray
    u_commanded: np.ndarray
    lengths: np.ndarray
    w: np.ndarray
    q_d: np.ndarray
    controller: list
    eta_energy: np.ndarray
    relative_error: np.ndarray
    switch_time: float | None
    limits_active: np.ndarray
    min_margin: float
    stress: dict
    condition_numbers: np.ndarray
    wall_time: float
    allocation_active: np.ndarray = field(default_factory=lambda: np.zeros(0))
    plant_report: dict | None = None
    names: dict = field(default_factory=dict)
    failure: str | None = None
    tendon_force: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    actuator: dict = field(default_factory=dict)

    def summary(self) -> dict:
        """The figures of the run for its JSON summary."""
        dt = float(self.t[1] - self.t[0]) if self.t.size > 1 else 0.0
        return {"switch_time_s": self.switch_time, "t_end_s": float(self.t[-1]),
                "max_membrane_deflection_m": float(np.max(np.abs(self.w))) if self.w.size else None,
                "peak_bar_compression_N": self.stress["peak_bar_compression_N"],
                "bar_critical_load_N": self.stress["bar_critical_load_N"],
                "max_von_mises_Pa": self.stress["max_von_mises_Pa"],
                "max_tendon_stress_Pa": self.stress["max_tendon_stress_Pa"],
                "strength_checks_failed": self.stress.get("failed_checks", []),
                "min_rest_length_margin_m": self.min_margin,
                "final_tracking_error": float(self.relative_error[-1]),
                "limits_active_s": float(np.sum(self.limits_active > 0) * dt),
                "allocation_active_s": float(self.allocation_active.size * dt),
                "last_limit_active_s": float(self.t[np.flatnonzero(self.limits_active > 0)[-1]])
                if np.any(self.limits_active > 0) else None,
                "max_eta_energy_J": float(np.max(self.eta_energy)),
                "B_q_condition_max": float(np.max(self.condition_numbers))
                if self.condition_numbers.size else None,
                "wall_time_s": self.wall_time, "failure": self.failure,
                **{f"plant_{k}": v for k, v in (self.plant_report or {}).items()}}


def run_deployment(*, model, reference, controller, z0, t_end: float, dt: float = 0.01,
                   r_min: float = 1e-3, stress_every: int = 10, progress=None,
                   mesh_n: int = 10, jacobian: str = "reuse", plant=None,
                   partial: bool = False) -> DeploymentResult:
    """Deploy: the COM plant (:class:`StatePlant`) from z0 under ``controller`` (reading
    y = [z, z']) saturated by :class:`RestLengthLimits`, integrated by Park's method
    (eqs. 5.34-5.35) at step dt. The run records the state and the inputs only; outputs,
    reference, energies and stresses are recovered after it (:mod:`tmfem.control.deployment.recovery`:
    tendon stresses at every sample, bars and membrane every ``stress_every`` samples).
    ``jacobian``: the Newton-matrix policy of :func:`tmfem.solvers.park.park_integrate`
    (``"reuse"`` keeps the matrix over steps while Newton converges within a few iterations).

    ``plant``: the plant the controller drives; default the COM plant from z0. Any plant whose
    outputs are the COM state y = [z, z'] serves (a finite-element plant through its state
    estimate, :class:`tmfem.control.fe_plant.state_estimate.FEStatePlant`): the run records that y as
    z, z', and a plant with a ``recover(states)`` method adds what only it knows (the FE
    tendon forces and slack, the membrane deflections its sensors measure) as ``plant_report``;
    the plant's own tendon forces over time are ``tendon_force`` (the COM's k (|d| - u), or
    the FE tendons' from ``recover``) and a force-actuated FE plant's tension demand and FE rest
    lengths ``actuator`` (:class:`tmfem.control.fe_plant.state_estimate.FEStatePlant`).

    ``partial``: a run whose integration fails (:class:`ConvergenceError`, a diverging closed
    loop) returns what it recorded up to the failure, with the message in ``failure``,
    instead of raising (the record of a failing FE-plant run, docs/guides/fe-plant.md).

    The loop runs with one BLAS thread: its dense algebra is small (the LPV gain's 71 x 71
    solve, the COM's Newton matrices), where OpenBLAS threads cost more than they give (a
    71 x 71 solve: 0.16 ms on one thread, 1.2-9 ms on two threads of a loaded 2-core
    machine)."""
    if stress_every < 1:
        raise InputError(f"stress_every: expected >= 1, found {stress_every}")
    plant = StatePlant(model, z0=z0) if plant is None else plant
    lim = RestLengthLimits(controller, model=model, r_min=r_min)
    nq, nz = model.nq, model.nz
    T, C, X, V, U, S = [], [], [], [], [], []
    recover = getattr(plant, "recover", None)

    def record(t, x, v, a, u, y):
        y = plant.outputs(x, v, u) if y is None else y
        T.append(t)
        C.append(lim.name)
        X.append(y[:nz].copy())
        V.append(y[nz:].copy())
        U.append(u.copy())
        if recover is not None:
            S.append(x.copy())
        return False

    t0 = time.perf_counter()
    failure = None
    try:
        with threadpool_limits(limits=1, user_api="blas"):
            simulate(plant, t_end=t_end, dt=dt, controller=lim, record=record,
                     progress=progress, outputs=False, jacobian=jacobian)
    except ConvergenceError as exc:
        if not partial or len(T) < 2:
            raise
        failure = str(exc)
        log.warning("deployment stopped at t = %.4g s: %s", T[-1], exc)
    wall = time.perf_counter() - t0
    t_rec = np.array(T)
    z, zd, u = np.array(X), np.array(V), np.array(U)
    out = [model.fast_outputs(zk, with_lengths=True) for zk in z]
    w = np.array([o[0] for o in out])
    L = np.array([o[2] for o in out])
    report = recover(np.array(S), u) if recover is not None else None
    tendon_force = model.k * (L - u)               # the COM's tendons (eq. 3.8, fixed k)
    actuator = {}
    if report is not None:
        w = report.pop("w")
        tendon_force = report.pop("tendon_force")
        actuator = {k: report.pop(k) for k in ("tension_demand", "fe_rest_lengths") if k in report}
        slack = report.pop("slack", None)
        if slack is not None:
            report["first_slack_s"] = float(t_rec[np.argmax(slack > 0)]) if np.any(slack) else None
    q_d = np.array([reference(tk)[0] for tk in t_rec])
    eta, etad = z[:, nq:], zd[:, nq:]
    E = 0.5 * np.sum(etad**2, axis=1) + 0.5 * np.sum(model.membrane.omega**2 * eta**2, axis=1)
    q_e = getattr(reference, "q_e", None)
    rel = relative_error(z[:, :nq], q_e) if q_e is not None else np.full(t_rec.size, np.nan)
    rc = StressRecovery(model.system, mesh_n=mesh_n)
    sigma_t = rc.tendon_stress(model.k, L, u)
    idx = np.arange(0, t_rec.size, stress_every)
    bar, vm = rc.bars_and_membrane(z[idx, :nq], model.k * (L[idx] - u[idx]))
    act = np.array([a for _, a in lim.active])[:t_rec.size]
    cond, alloc = [], []
    for c in (controller, getattr(controller, "first", None)):
        if c is not None and hasattr(c, "condition_numbers"):
            cond, alloc = c.condition_numbers, getattr(c, "allocation_active", [])
        elif c is not None and hasattr(c, "allocation_active"):     # an LPV deployment's allocation
            alloc = c.allocation_active
    return DeploymentResult(
        t=t_rec, z=z, zd=zd, u=u, u_commanded=u, lengths=L, w=w, q_d=q_d,
        controller=C, eta_energy=E, relative_error=rel,
        switch_time=getattr(controller, "switch_time", None), limits_active=act,
        min_margin=float(np.min(lim.margins)),
        stress={"peak_bar_compression_N": float(np.max(bar)),
                "bar_critical_load_N": rc.critical_load,
                "max_von_mises_Pa": float(np.max(vm)),
                "max_tendon_stress_Pa": float(np.max(sigma_t)),
                "bar_t": t_rec[idx], "bar": bar, "von_mises": vm, "tendon": sigma_t,
                "failed_checks": rc.failed_checks(t=t_rec, tendon_stress=sigma_t, bar_t=t_rec[idx],
                                                  bar_compression=bar, von_mises=vm)},
        condition_numbers=np.asarray(cond, dtype=float), wall_time=wall,
        allocation_active=np.asarray(alloc, dtype=float), plant_report=report, failure=failure,
        tendon_force=tendon_force, actuator=actuator,
        names={"q": list(model.system.q_names), "u": model.input_names,
               "tendons": [t.name for t in model.system.tendons],
               "w": [f"w_{i + 1}" for i in range(len(model.output_points))]})


@dataclass
class DeploymentSetup:
    """Everything a deployment run needs (built by :func:`build_deployment`)."""

    model: object
    reference: object
    adaptive: object
    controller: object
    linear: object
    z0: np.ndarray
    z_e: np.ndarray
    info: dict


def build_deployment(*, final, initial, omega_r: float, gains, uncertainty: str,
                     output_points=None, linear: str = "lqr", R_c: float = 0.01,
                     n_centers: int = 10, w_bar: float = 100.0, gamma: float = 0.01,
                     u_m: float = 0.01, membrane_modes: int | None = None,
                     check_path: bool = True, bases=None, allocation: str = "bounded",
                     hinf_method: str = "central", r_min: float = 1e-3,
                     delta_path: bool = False, evaluation: str = "state",
                     tendon_law: str = "fixed-rate", path=None, info=None,
                     tension_floor: float = TENSION_FLOOR) -> DeploymentSetup:
    """The model (built at the final configuration with its printed rest lengths), the
    reference from ``initial`` to ``final`` (:class:`DeploymentReference`, stage bases from
    ``bases`` when given, psi_r from eq. 3.22 with Delta linear in s when ``delta_path``,
    one-stage systems, the configurations ``path(s)`` when given: the automatic path of
    :mod:`tmfem.equilibrium.deployment_path`), the adaptive PFL (eq. 5.58, limits treated by ``allocation``) and,
    unless ``linear="none"``, the switch (eq. 5.70) to a linear controller about the final
    equilibrium: ``"lmi"`` (the H-infinity output feedback of 7.3 with alpha-stability,
    :func:`lmi_hinf_controller`, synthesised by ``hinf_method``, its state at the switch by
    :data:`HINF_STARTS`), ``"lqr"``
    (:func:`lqr_state_feedback`) or ``"hinf"`` (:func:`hinf_output_feedback`, python-control
    Riccati on [q, w]). ``evaluation``: where the PFL evaluates its model terms, at the
    measured state (eq. 5.58) or at the reference; ``tendon_law``: the PFL's tendon model,
    the rates of eq. 5.19 or k = EA / u (:mod:`tmfem.control.deployment.adaptive`); ``info``: entries
    added to the set-up's ``info`` (the JSON of a run); ``tension_floor``: the fraction of its
    path elongation an over-actuated system's tendon keeps (:class:`AdaptivePFL`)."""
    if allocation not in ALLOCATION:
        raise InputError(f"allocation: expected one of {ALLOCATION}, found {allocation!r}")
    if linear not in ("lmi", "lqr", "hinf", "none"):
        raise InputError(f"linear controller: expected 'lmi', 'lqr', 'hinf' or 'none', found "
                         f"{linear!r}")
    K = default_membrane_modes(final) if membrane_modes is None else membrane_modes
    model = ControlOrientedModel(final, membrane_modes=K, rest_lengths="system",
                                 output_points=output_points)
    ref = DeploymentReference(initial=initial.symmetric, final=final.symmetric, N=final.N,
                              q_names=list(final.q_names), omega_r=omega_r, bases=bases,
                              r_mb=final.r_mb if delta_path else None, path=path)
    if check_path:
        ref.check_equilibria(checker=equilibrium_checker(final))
    t_settle = 8.0 / omega_r
    C, sig = reference_centers(ref, t_end=t_settle, m=n_centers)
    ad = AdaptivePFL(model=model, reference=ref, gains=gains, rbf=GaussianRBF(centers=C, sigma=sig),
                     w_bar=w_bar, gamma=gamma, uncertainty=uncertainty, allocation=allocation,
                     r_min=r_min, evaluation=evaluation, tendon_law=tendon_law,
                     u_initial=initial.rest_lengths,
                     rest_length_reference=path_rest_length_reference(final, ref),
                     tension_floor=tension_floor)
    z0 = np.concatenate([ref.q_0, np.zeros(model.K)])
    z_e = model.equilibrium(model.u0, z0=np.concatenate([ref.q_e, np.zeros(model.K)])).state
    info = {"rbf_centres": n_centers, "rbf_sigma": sig, "w_bar": w_bar, "K": K, **(info or {})}
    lin_ctrl = None
    ctrl = ad
    start = "bumpless"
    estimate = None
    if linear != "none":
        if linear == "lmi":
            lin_ctrl, measure, d = lmi_hinf_controller(final, membrane_modes=K, method=hinf_method,
                                                       z_e=z_e)
            info["hinf_gamma"] = float(d.design.gamma)
            if d.excluded_modes:
                info["excluded_modes_hz"] = mode_frequencies_hz(d.excluded_modes)
                # the design's states are Z_r^T x (C2 = Z_r of the measured y = x, Fig. 7.1)
                estimate = np.linalg.pinv(d.generalized.C2)
            start = HINF_STARTS[hinf_method]
        elif linear == "lqr":
            lin_ctrl, _ = lqr_state_feedback(model, u_e=model.u0, z_e=z_e, u_m=u_m)
            measure = lambda y: np.asarray(y)                               # noqa: E731
        else:
            lin_ctrl, _, g = hinf_output_feedback(model, u_e=model.u0, z_e=z_e, u_m=u_m)
            measure = output_measure(model)
            info["hinf_gamma"] = g
        ctrl = SwitchingController(first=ad, second=lin_ctrl, q_of_y=lambda y: y[: model.nq],
                                   q_e=ref.q_e, measure=measure, R_c=R_c, start=start,
                                   estimate=estimate)
    return DeploymentSetup(model=model, reference=ref, adaptive=ad, controller=ctrl,
                           linear=lin_ctrl, z0=z0, z_e=z_e, info=info)


def path_rest_length_reference(final, ref, *, n: int = 101):
    """u_d(t) [m] of an over-actuated M >= 2 system (more tendons than bar coordinates): the
    rest lengths of the reference's equilibria (:func:`tmfem.equilibrium.deployment_path.
    path_rest_lengths`, forces scaled with the membrane stiffness of the deployed design) at
    n evenly spaced progress values, linear in s between them, at the progress s(t) of the
    reference ``ref``; None for any other system (its B_q is square)."""
    from tmfem.equilibrium.deployment_path import membrane_stiffness, path_rest_lengths
    from tmfem.equilibrium.design import design_equilibrium
    if final.M < 2 or len(final.tendons) <= len(final.q_names):
        return None
    kappa = membrane_stiffness(design_equilibrium(final.replace(rest_lengths=None), strict=False))
    ss = np.linspace(0.0, 1.0, n)
    U = np.array([path_rest_lengths(final, ref.config(s), kappa=kappa) for s in ss])

    def u_d(t):
        s = float(np.clip(ref.progress(t)[0], 0.0, 1.0)) * (n - 1)
        i = min(int(s), n - 2)
        return U[i] + (s - i) * (U[i + 1] - U[i])
    return u_d


def equilibrium_checker(system):
    """The equilibrium test ``check(cfg)`` of a symmetric configuration of ``system`` (for
    :meth:`~tmfem.control.deployment.reference_trajectory.DeploymentReference.check_equilibria`):
    eqs. 3.40-3.41 for a 1-N(D) system (:func:`tmfem.equilibrium.symmetric.check_1ND`), the
    positive null vector of the reduced symmetric matrix otherwise (3.3.2)."""
    if system.deployable:
        return lambda cfg: check_1ND(with_configuration(system, cfg))

    def check(cfg):
        p = path_feasibility(system, cfg)
        if p.reason:
            raise (SlackMembrane if p.Delta <= 0 and p.margin > 0 else SlackTendon)(p.reason)
    return check
