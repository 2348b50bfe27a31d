"""Free vibration of the control-oriented model (6.5) with Park's method (eqs. 5.34-5.35).

The model starts at its static equilibrium with an initial perturbation (e.g. the rate
theta_12' = 0.01 rad/s of 6.5.1 or theta_11' = 0.01 rad/s of 6.5.2) and is integrated by
:func:`tmfem.solvers.park.park_integrate`. Histories of the coordinates, the monitored
membrane deflections w_1..w_3 (eqs. 5.36, 5.38) and the monitored bar ends (Figs.
6.21-6.22, 6.25-6.27) are written row by row to a CSV file when asked.
"""
from __future__ import annotations

import csv
import sys
import time
from dataclasses import dataclass, field

import numpy as np

from tmfem.errors import InputError
from tmfem.solvers.park import park_integrate

# Bar ends whose positions 6.5 plots (Figs. 6.21-6.22, 6.25-6.27).
MONITOR_NODES = {"1-4": ["B_12", "B_14"], "2-3": ["A_21", "B_11", "B_21"]}


def parse_perturbation(items, names) -> dict:
    """``["theta_11_dot=0.01", ...]`` -> {name: value}; names must be states of the model."""
    out = {}
    for it in items or []:
        if "=" not in it:
            raise InputError(f"perturbation: expected NAME=VALUE, found {it!r}")
        k, v = it.split("=", 1)
        k = k.strip()
        if k not in names:
            raise InputError(f"perturbation: unknown state {k!r}; expected one of {names}")
        try:
            out[k] = float(v)
        except ValueError:
            raise InputError(f"perturbation {k}: expected a number, found {v!r}") from None
    return out


def split_perturbation(perturb: dict | None, names) -> tuple[np.ndarray, np.ndarray]:
    """Initial offsets and rates of the coordinates ``names`` from a perturbation by name.

    Parameters
    ----------
    perturb : dict or None
        ``{"theta_11_dot": 0.01, "theta_12": 0.001}``: a coordinate name adds to its value,
        ``<name>_dot`` to its rate (6.5.1-6.5.2).
    names : list of str
        The coordinates (``system.q_names`` for the MTC model, ``model.z_names`` for the COM).

    Returns
    -------
    d, d_dot : ndarray (len(names),)
    """
    names = list(names)
    accepted = names + [n + "_dot" for n in names]
    d = np.zeros(len(names))
    d_dot = np.zeros(len(names))
    for k, val in (perturb or {}).items():
        if k not in accepted:
            raise InputError(f"perturbation: unknown state {k!r}; expected one of {accepted}")
        i = accepted.index(k)
        if i < len(names):
            d[i] += val
        else:
            d_dot[i - len(names)] += val
    return d, d_dot


class RunOutputs:
    """Per-step outputs of a free-vibration run, shared by the COM and MTC drivers (6.5).

    The CSV history (header ``columns``, one row per recorded step, flushed), the ParaView
    series (a frame every ``vtk_every`` steps, :class:`tmfem.io.vtk.SeriesWriter`), the
    smallest tendon force with its time and tendon, and the progress line on stderr.

    Parameters
    ----------
    csv_path : path or None
    columns : list of str
    vtk_dir : path or None
    vtk_every : int
    name : str
        Name of the ParaView series (parentheses dropped).
    label : str
        Progress label (``"vibrate 1-4"``).
    dt, t_end : float
        Time step and duration, for the progress line.
    progress : bool
        Print ``label: t = ... / ... s`` to stderr every 100 steps and at the end.
    """

    def __init__(self, *, csv_path, columns, vtk_dir, vtk_every, name: str, label: str,
                 dt: float, t_end: float, progress: bool):
        self.series = None
        if vtk_dir is not None:
            from tmfem.io.vtk import SeriesWriter
            if not (isinstance(vtk_every, int) and vtk_every >= 1):
                raise InputError(f"vtk_every: expected an integer >= 1, found {vtk_every!r}")
            self.series = SeriesWriter(vtk_dir, name=name.replace("(", "").replace(")", ""))
        self.fh = open(csv_path, "w", newline="") if csv_path else None
        self.writer = csv.writer(self.fh) if self.fh else None
        if self.writer:
            self.writer.writerow(columns)
        self.vtk_every = vtk_every
        self.label, self.dt, self.t_end, self.show = label, dt, t_end, progress
        self.count = 0
        self.min_force = [np.inf, 0.0, ""]        # smallest tendon force, its time and tendon

    def frame_due(self) -> bool:
        """True when the current step is written as a ParaView frame."""
        return self.series is not None and self.count % self.vtk_every == 0

    def tendon_forces(self, t: float, force: np.ndarray, names) -> None:
        """Keep the smallest of ``force`` (one per member, ``names[k]`` its tendon) over time."""
        k = int(np.argmin(force))
        if force[k] < self.min_force[0]:
            self.min_force[:] = [float(force[k]), float(t), names[k]]

    def row(self, t: float, values: np.ndarray) -> None:
        """Write the CSV row of time t (when a CSV is asked) and count the step."""
        self.count += 1
        if self.writer:
            self.writer.writerow([f"{t:.6g}"] + [f"{v:.10g}" for v in values])
            self.fh.flush()

    def progress(self, k: int, n: int) -> None:
        if self.show and (k % 100 == 0 or k == n):
            print(f"{self.label}: t = {k * self.dt:.2f} / {self.t_end:g} s", file=sys.stderr,
                  flush=True)

    def integrate(self, residual, *, x0, v0, n_steps: int, scheme: str, jacobian: str,
                  callback, **kw):
        """:func:`park_integrate` with this run's progress; the CSV is closed at the end
        (also on an error). Returns the ParkResult and the wall time [s]."""
        t0 = time.perf_counter()
        try:
            res = park_integrate(residual, x0=x0, v0=v0, dt=self.dt, n_steps=n_steps,
                                 scheme=scheme, jacobian=jacobian, callback=callback, store=False,
                                 progress=self.progress, **kw)
        finally:
            if self.fh:
                self.fh.close()
        return res, time.perf_counter() - t0

    def stats(self, res) -> dict:
        """Step and Newton counts of ``res``, the smallest tendon force, the .pvd path."""
        out = {"steps": res.steps, "newton_iterations": res.newton_iterations,
               "jacobian_evaluations": res.jacobian_evaluations,
               "min_tendon_force": self.min_force[0], "min_tendon_force_time": self.min_force[1],
               "min_tendon_force_tendon": self.min_force[2]}
        if self.series is not None:
            out["pvd"] = str(self.series.pvd)
        return out


class _Driven:
    """The model with prescribed rest lengths u(t), as a residual for park_integrate."""

    def __init__(self, model, u):
        self.model = model
        if callable(u):
            self._u = u
        else:
            arr = np.asarray(u, dtype=float)
            if arr.shape != (model.n_t,):
                raise InputError(f"rest lengths: expected {model.n_t} values, found shape {arr.shape}")
            self._u = lambda t: arr

    def rest_lengths(self, t):
        return np.asarray(self._u(t), dtype=float)

    def residual(self, x, v, a, t):
        return self.model.residual(x, v, a, t, u=self.rest_lengths(t))

    def jacobians(self, x, v, a, t):
        return self.model.jacobians(x, v, a, t, u=self.rest_lengths(t))

    def newton_matrix(self, x, v, a, t, cv, ca):
        return self.model.newton_matrix(x, v, a, t, cv, ca, u=self.rest_lengths(t))


@dataclass
class FreeVibration:
    """Result of :func:`free_vibration`."""

    t: np.ndarray
    z: np.ndarray
    zd: np.ndarray
    w: np.ndarray
    nodes: dict
    columns: list
    wall_time: float
    stats: dict = field(default_factory=dict)


def free_vibration(model, *, t_end: float, dt: float = 0.01, perturb: dict | None = None,
                   csv_path=None, scheme: str = "park", jacobian: str = "step",
                   monitor_nodes=None, progress: bool = False, vtk_dir=None,
                   vtk_every: int = 10, u=None) -> FreeVibration:
    """Free vibration from the equilibrium with an initial perturbation (6.5).

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
        Passed to :func:`park_integrate` (``jacobian="step"``: modified Newton).
    monitor_nodes : list of str, optional
        Node labels whose positions are recorded (default per preset, see MONITOR_NODES).
    u : array or callable, optional
        Tendon rest lengths during the run: an array, or ``u(t) -> array`` (e.g. a step of
        one rest length); default the model's nominal ``u0`` (free vibration). The run
        always starts from the equilibrium for ``u0``.
    vtk_dir : path, optional
        Write every ``vtk_every``-th step as a ParaView frame (bars, tendons with forces,
        deformed membrane with its deflection in O_f) and a ``.pvd`` collection, as the run
        goes (tmfem.io.vtk.SeriesWriter).
    """
    if not (t_end > 0 and dt > 0):
        raise InputError(f"expected t_end > 0 and dt > 0, found t_end={t_end!r}, dt={dt!r}")
    system = model.system
    dz, dzd = split_perturbation(perturb, model.z_names)
    z0 = model.equilibrium() + dz
    zd0 = dzd
    labels = MONITOR_NODES.get(system.name, []) if monitor_nodes is None else list(monitor_nodes)
    idx = [system.node_index(n) for n in labels]
    wnames = [f"w_{i + 1}" for i in range(len(model.output_points))]
    columns = (["t"] + model.z_names + [n + "_dot" for n in model.z_names] + wnames
               + [f"{n}_{c}" for n in labels for c in "xyz"])
    n_steps = int(round(t_end / dt))
    T, Z, ZD, W, XS = [], [], [], [], []
    out = RunOutputs(csv_path=csv_path, columns=columns, vtk_dir=vtk_dir, vtk_every=vtk_every,
                     name=f"com_{system.name}", label=f"vibrate {system.name}", dt=dt,
                     t_end=t_end, progress=progress)
    tendon_names = [t.name for t in system.tendons]

    def record(t, z, zd, a):
        w, X, L = model.fast_outputs(z, with_lengths=True)
        rest = model.u0 if u is None else driven.rest_lengths(t)
        force = model.k * (L - rest)                                   # eq. 3.8
        out.tendon_forces(t, force, tendon_names)
        pos = X[:, idx]
        if out.frame_due():
            from tmfem.io.vtk import MembraneField
            xm, defl = model.membrane_positions(z)
            out.series.append_configuration(
                t, system, q=(model.P @ z)[: model.nq], tendon_forces=force, rest_lengths=rest,
                membrane=MembraneField(mesh=model.membrane.mesh, x=xm,
                                       point_data={"deflection_Of": defl}))
        T.append(t); Z.append(z.copy()); ZD.append(zd.copy()); W.append(w); XS.append(pos)
        out.row(t, np.concatenate([z, zd, w, pos.T.ravel()]))

    driven = model if u is None else _Driven(model, u)
    res, wall = out.integrate(driven, x0=z0, v0=zd0, n_steps=n_steps, scheme=scheme,
                              jacobian=jacobian, callback=record)
    Xa = np.array(XS)
    nodes = {n: Xa[:, :, k] for k, n in enumerate(labels)}
    stats = out.stats(res)
    if stats["min_tendon_force"] <= 0:
        # the COM's tendons are bilateral springs (docs/com.md): a compressed tendon means the
        # motion left the model's range of validity
        print(f"warning: tendon {stats['min_tendon_force_tendon']} goes slack (force "
              f"{stats['min_tendon_force']:.4g} N at t = {stats['min_tendon_force_time']:.4g} s); "
              "the COM treats tendons as two-sided springs", file=sys.stderr)
    return FreeVibration(t=np.array(T), z=np.array(Z), zd=np.array(ZD), w=np.array(W), nodes=nodes,
                         columns=columns, wall_time=wall, stats=stats)


def plot_free_vibration(result: FreeVibration, path, *, title: str = "") -> str:
    """Monitored node coordinates and membrane deflections vs time (Figs. 6.21-6.28)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    nn = len(result.nodes)
    fig, axes = plt.subplots(nn + 1, 1, figsize=(8, 2.4 * (nn + 1)), sharex=True)
    axes = np.atleast_1d(axes)
    for ax, (name, X) in zip(axes, result.nodes.items()):
        for c, lab in enumerate("xyz"):
            ax.plot(result.t, 1e3 * (X[:, c] - X[0, c]), label=f"{lab} - {lab}(0)")
        ax.set_ylabel(f"{name} [mm]"); ax.legend(loc="upper right", fontsize=7)
    ax = axes[-1]
    for k in range(result.w.shape[1]):
        ax.plot(result.t, 1e3 * result.w[:, k], label=f"w_{k + 1}")
    ax.set_ylabel("w [mm]"); ax.set_xlabel("t [s]"); ax.legend(loc="upper right", fontsize=7)
    if title:
        axes[0].set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)
