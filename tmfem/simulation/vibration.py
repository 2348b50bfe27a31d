"""Free vibration of the control-oriented and the finite-element (MTC, SBC) models (6.5).

Each model's plant starts at its static equilibrium with an initial perturbation (the rate
theta_12' = 0.01 rad/s of 6.5.1, theta_11' = 0.01 rad/s of 6.5.2) and is integrated by the
simulation driver (:func:`tmfem.simulation.simulate`, Park's method, eqs. 5.34-5.35) with
the nominal rest lengths held, or a prescribed schedule u(t). The histories of the
coordinates, the monitored membrane deflections w_k (eqs. 5.36, 5.38) and the monitored bar
ends (``system.monitor_nodes``; Figs. 6.21-6.22, 6.25-6.27) are written row by row
(:class:`tmfem.io.run.RunOutputs`).
"""
from __future__ import annotations

import logging
import sys
from dataclasses import dataclass, field

import numpy as np

from tmfem.io.fields import DISPLACEMENT_FIELD, MembraneField
from tmfem.io.run import RunOutputs
from tmfem.models.com.plant import COMPlant
from tmfem.models.mtc.dynamics import MTCDynamics, tendon_transverse
from tmfem.models.sbc.dynamics import SBCDynamics
from tmfem.post.mtc import membrane_field
from tmfem.post.sbc import shell_field
from tmfem.simulation.controllers import OpenLoop
from tmfem.simulation.driver import check_time_grid, simulate

log = logging.getLogger(__name__)


@dataclass
class FreeVibration:
    """Result of :func:`free_vibration` (control-oriented model)."""

    def __repr__(self) -> str:
        return (f"FreeVibration({self.t.size} times to t = {self.t[-1]:.4g} s, "
                f"{self.z.shape[1]} coordinates, {self.wall_time:.2f} s wall)")


    t: np.ndarray
    z: np.ndarray
    zd: np.ndarray
    w: np.ndarray
    nodes: dict
    columns: list
    wall_time: float
    stats: dict = field(default_factory=dict)

    def summary(self) -> dict:
        """What this run adds to the common report: the final state by name."""
        n = 2 * self.z.shape[1]
        return {"final": dict(zip(self.columns[1:1 + n],
                                  np.concatenate([self.z[-1], self.zd[-1]]).tolist()))}


def free_vibration(model, *, t_end: float, dt: float = 0.01, perturb: dict | None = None,
                   csv_path=None, scheme: str = "park", jacobian: str = "step",
                   monitor_nodes=None, progress=None, vtk_dir=None,
                   vtk_every: int = 10, u=None, plant=None) -> FreeVibration:
    """Free vibration of a :class:`~tmfem.models.com.model.ControlOrientedModel` from its
    equilibrium with an initial perturbation (6.5).

    Parameters
    ----------
    model : ControlOrientedModel
    t_end, dt : float
        Duration and time step (6.5: dt = 0.01 s).
    perturb : dict
        Initial perturbations by state name (``theta_11_dot``: rate, ``theta_11``: offset).
    csv_path : path, optional
        Write t, z, z', w_k and monitored node coordinates row by row.
    scheme, jacobian :
        Passed to the integrator (``jacobian="step"``: modified Newton).
    monitor_nodes : list of str, optional
        Node labels whose positions are recorded (default ``system.monitor_nodes``).
    progress : callable, optional
        ``progress(step, n_steps)`` (the CLI's progress bar).
    u : array or callable, optional
        Tendon rest lengths during the run: an array, or ``u(t) -> array`` sampled every step
        (zero-order hold); default the model's nominal ``u0`` (free vibration). The run always
        starts from the equilibrium for ``u0``.
    plant : COMPlant, optional
        The plant to integrate (default ``model.plant(perturb=perturb)``).
    vtk_dir : path, optional
        Write every ``vtk_every``-th step as a ParaView frame (bars, tendons with forces,
        deformed membrane with its deflection in O_f) and a ``.pvd`` collection, as the run goes.
    """
    check_time_grid(t_end, dt)
    system = model.system
    plant = COMPlant(model, perturb=perturb) if plant is None else plant
    labels = list(system.monitor_nodes) if monitor_nodes is None else list(monitor_nodes)
    idx = [system.node_index(n) for n in labels]
    wnames = [f"w_{i + 1}" for i in range(len(model.output_points))]
    columns = (["t"] + model.z_names + [n + "_dot" for n in model.z_names] + wnames
               + [f"{n}_{c}" for n in labels for c in "xyz"])
    T, Z, ZD, W, XS = [], [], [], [], []
    out = RunOutputs(csv_path=csv_path, columns=columns, vtk_dir=vtk_dir, vtk_every=vtk_every,
                     name=f"com_{system.name}")
    tendon_names = [t.name for t in system.tendons]

    def record(t, z, zd, a, rest, y):
        w, X, L = model.fast_outputs(z, with_lengths=True)
        force = model.k * (L - rest)                                   # eq. 3.8
        out.tendon_forces(t, force, tendon_names)
        pos = X[:, idx]
        if out.frame_due():
            xm, defl = model.membrane_positions(z)
            out.series.append_configuration(
                t, system, q=(model.P @ z)[: model.nq], tendon_forces=force, rest_lengths=rest,
                membrane=MembraneField(mesh=model.membrane.mesh, x=xm,
                                       point_data={DISPLACEMENT_FIELD: defl}))
        T.append(t)
        Z.append(z.copy())
        ZD.append(zd.copy())
        W.append(w)
        XS.append(pos)
        out.row(t, np.concatenate([z, zd, w, pos.T.ravel()]))

    try:
        sim = simulate(plant, t_end=t_end, dt=dt, controller=None if u is None else OpenLoop(u),
                       scheme=scheme, jacobian=jacobian, record=record, progress=progress,
                       outputs=False)
    finally:
        out.close(complete=sys.exc_info()[0] is None)     # else the files stay partial
    Xa = np.array(XS)
    stats = out.stats(sim)
    if stats["min_tendon_force"] <= 0:
        # the COM's tendons are bilateral springs (docs/guides/com.md): a compressed tendon means the
        # motion left the model's range of validity
        log.warning("tendon %s goes slack (force %.4g N at t = %.4g s); the COM treats tendons "
                    "as two-sided springs", stats["min_tendon_force_tendon"],
                    stats["min_tendon_force"], stats["min_tendon_force_time"])
    return FreeVibration(t=np.array(T), z=np.array(Z), zd=np.array(ZD), w=np.array(W),
                         nodes={n: Xa[:, :, k] for k, n in enumerate(labels)}, columns=columns,
                         wall_time=sim.wall_time, stats=stats)


@dataclass
class FEVibration:
    """Result of :func:`fe_free_vibration` (histories as arrays, one row per time)."""

    def __repr__(self) -> str:
        return (f"FEVibration({self.model}, {self.t.size} times to t = {self.t[-1]:.4g} s, "
                f"{self.q.shape[1]} coordinates, {self.wall_time:.2f} s wall)")


    model: str
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

    def summary(self) -> dict:
        """What this run adds to the common report: the largest tendon deflection, the energy
        drift and the range of every coordinate q."""
        return {"max_tendon_deflection_m": self.stats["max_tendon_deflection"],
                "max_tendon_deflection_tendon": self.stats["max_tendon_deflection_tendon"],
                "energy_drift_J": float(np.max(np.abs(self.energy - self.energy[0]))),
                "initial_kinetic_energy_J": float(self.kinetic[0]),
                "q_range": dict(zip(self.columns[1:1 + self.q.shape[1]],
                                    np.ptp(self.q, axis=0).tolist()))}


#: the ParaView membrane of a finite-element plant's free-dof state u, by plant type
FRAME_FIELDS = {
    MTCDynamics: lambda dyn: (lambda u: membrane_field(dyn.model, dyn.positions(u))),
    SBCDynamics: lambda dyn: (lambda u: shell_field(dyn.model, dyn.configuration(u))),
}


def model_free_vibration(model, *, at=None, perturb: dict | None = None, dynamics=None,
                         jacobian: str | None = None, **run):
    """Free vibration of any model (:mod:`tmfem.models.base`) from its equilibrium ``at``
    (default ``model.equilibrium()``) with an initial ``perturb``: the plant
    ``model.plant(at=at, perturb=perturb, **dynamics)`` integrated by :func:`free_vibration`
    (control-oriented model; ``jacobian`` default ``"reuse"``, its matrices change little) or
    :func:`fe_free_vibration` (finite-element plants; default ``"step"``). ``run``: the
    keyword arguments both take (``t_end``, ``dt``, ``csv_path``, ``scheme``, ``progress``,
    ``vtk_dir``, ``vtk_every``, ``monitor_nodes``)."""
    plant = model.plant(at=at, perturb=perturb, **(dynamics or {}))
    if isinstance(plant, COMPlant):
        return free_vibration(model, plant=plant, jacobian=jacobian or "reuse", **run)
    frames = FRAME_FIELDS[type(plant)](plant)
    return fe_free_vibration(plant, name=model.name, membrane=frames,
                             jacobian=jacobian or "step", **run)


def fe_free_vibration(dyn, *, name: str, t_end: float, dt: float = 0.01, csv_path=None,
                      scheme: str = "park", jacobian: str = "step", monitor_nodes=None,
                      progress=None, vtk_dir=None, vtk_every: int = 10, tol: float = 1e-10,
                      membrane=None, line_search: bool = True) -> FEVibration:
    """Free vibration of a finite-element plant ``dyn`` (:class:`tmfem.models.fe.plant.FEPlant`)
    from its perturbed equilibrium (6.5, eqs. 5.34-5.35).

    Parameters
    ----------
    dyn : MTCDynamics or SBCDynamics
        The plant, built with its perturbation (``{"theta_12_dot": 0.01}`` etc.,
        :func:`tmfem.models.fe.plant.initial_state`), damping and output points.
    name : str
        Model name of the result and the ParaView series.
    t_end, dt : float
        Duration and time step (6.5: dt = 0.01 s).
    scheme, jacobian, tol :
        Passed to the integrator (default ``"step"``: one factorisation per step, modified
        Newton; measured on 2-3 at n = 10 it needs half the factorisations of ``"reuse"``,
        whose stale matrices diverge at times and restart with full Newton).
    monitor_nodes : list of str, optional
        Labelled nodes recorded (default ``system.monitor_nodes``).
    csv_path, vtk_dir, vtk_every :
        Histories written row by row; ParaView frames every ``vtk_every`` steps.
    membrane : callable, optional
        ``membrane(u) -> MembraneField`` of a free-dof state, for the ParaView frames.
    progress : callable, optional
        ``progress(step, n_steps)``.
    line_search : bool
        Backtracking on the Newton corrections (:func:`tmfem.solvers.park.park_integrate`;
        default on: a correction that reduces the residual is taken whole, so it changes
        nothing where plain Newton converges; the SBC shell's soft rotations on fine meshes
        need it, docs/guides/sbc.md "Free vibration on the fine mesh").

    Outputs per step: q, w_k (eqs. 5.36, 5.38), the monitored bar ends, the largest tendon
    transverse deflection (eq. 5.37, relative to the equilibrium), kinetic and strain energy.
    """
    check_time_grid(t_end, dt)
    mtc = dyn.model
    system, topo = mtc.system, mtc.topology
    labels = list(system.monitor_nodes) if monitor_nodes is None else list(monitor_nodes)
    lab_nodes = [topo.system_node[system.node_index(n)] for n in labels]
    has_int = topo.tendon_internal.size > 0
    td0 = tendon_transverse(mtc, dyn.positions(dyn.state0())) if has_int else None
    nq = len(system.q_names)
    wn = [f"w_{i + 1}" for i in range(len(dyn.output_points))]
    columns = (["t"] + list(system.q_names) + wn + [f"{n}_{c}" for n in labels for c in "xyz"]
               + ["tendon_deflection", "kinetic_energy", "strain_energy"])
    T, Q, W, XS, TD, KE, SE = [], [], [], [], [], [], []
    out = RunOutputs(csv_path=csv_path, columns=columns, vtk_dir=vtk_dir, vtk_every=vtk_every,
                     name=f"{name}_{system.name}")
    element_tendon = [system.tendons[k].name for k in topo.tendon_of_element]
    worst = [0.0, ""]

    def record(t, u, v, a, rest, y):
        x = dyn.positions(u)
        q, w = y[:nq], y[nq:]
        if has_int:
            d = np.linalg.norm(tendon_transverse(mtc, x) - td0, axis=-1)      # (n_t, k-1)
            k = int(np.argmax(d.max(axis=1)))
            td = float(d[k].max())
            if td > worst[0]:
                worst[:] = [td, system.tendons[k].name]
        else:
            td = 0.0
        ke, se = dyn.kinetic_energy(v), dyn.strain_energy(u)
        ms = dyn.member_forces(u)
        out.tendon_forces(t, ms["element_force"], element_tendon)
        pos = x[:, lab_nodes]
        if out.frame_due():
            out.series.append_configuration(t, system, q=q, tendon_forces=ms["tendon_force"],
                                            rest_lengths=dyn.model.rest_lengths,
                                            membrane=None if membrane is None else membrane(u),
                                            bar_forces=ms["bar_force"])
        T.append(t)
        Q.append(q)
        W.append(w)
        XS.append(pos)
        TD.append(td)
        KE.append(ke)
        SE.append(se)
        out.row(t, np.concatenate([q, w, pos.T.ravel(), [td, ke, se]]))

    try:
        sim = simulate(dyn, t_end=t_end, dt=dt, scheme=scheme, jacobian=jacobian, tol=tol,
                       record=record, progress=progress, line_search=line_search)
    finally:
        out.close(complete=sys.exc_info()[0] is None)     # else the files stay partial
    Xa = np.array(XS)
    stats = out.stats(sim)
    stats.update({"ndof": int(dyn.free.sum()), "max_tendon_deflection": worst[0],
                  "max_tendon_deflection_tendon": worst[1]})
    if stats["min_tendon_force"] <= 0:
        log.warning("tendon %s went slack at t = %.4g s (tension-only in the %s model)",
                    stats["min_tendon_force_tendon"], stats["min_tendon_force_time"], name.upper())
    return FEVibration(model=name, t=np.array(T), q=np.array(Q), w=np.array(W),
                       nodes={n: Xa[:, :, k] for k, n in enumerate(labels)},
                       tendon_deflection=np.array(TD), kinetic=np.array(KE), strain=np.array(SE),
                       columns=columns, wall_time=sim.wall_time, stats=stats)
