"""The simulation driver: a model's plant in closed loop with a controller (Park's method).

:func:`simulate` integrates ``plant.residual(x, v, a, t, u) = 0`` with Park's method started
by the trapezoidal rule (eqs. 5.34-5.35, :func:`tmfem.solvers.park.park_integrate`), with
the inputs u from a controller sampled every step (zero-order hold, see
:mod:`tmfem.simulation.controllers`):

    y_n = outputs(x_n, v_n, u_{n-1}),   u_n = k(t_n, y_n, x_c,n),   x_c,n+1 = update(t_n, y_n, x_c,n),

and the plant stepped from t_n to t_n+1 with u_n held -- or, for a plant with actuators
(``plant.actuate(x, u)``), with the input its model receives for the command u_n at the
sampled state x_n held (a tension-servoed tendon, :mod:`tmfem.control.fe_plant.tension_actuation`;
the record keeps the commanded u_n); a plant with a per-sample hook (``plant.sample(x, u)``)
is told the sampled state x_n and that held input before the step (an FE plant's damping on
the current tangent, :meth:`tmfem.models.fe.plant.FEPlant.sample`). Any model's plant serves: the
control-oriented model (eq. 5.27) and the finite-element models (M a + C v + f_int(x; u) with
the tendon rest lengths u as inputs).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from tmfem.errors import InputError
from tmfem.simulation.controllers import as_controller
from tmfem.solvers.park import park_integrate


@dataclass
class Simulation:
    """Result of :func:`simulate`: times (n+1,), outputs y (n+1, ny), inputs u (n+1, nu)
    (u[k] acts over [t_k, t_k+1]), the active controller at each time, the final state, the
    integrator's counts and the wall time [s]."""

    t: np.ndarray
    y: np.ndarray
    u: np.ndarray
    controller: list
    x: np.ndarray
    v: np.ndarray
    wall_time: float
    stats: dict = field(default_factory=dict)


class _ClosedLoop:
    """The plant with the input held over a step, as the residual system of park_integrate."""

    def __init__(self, plant):
        self.plant = plant
        self.u = np.asarray(plant.u0, dtype=float)
        if hasattr(plant, "factorize"):
            self.factorize = plant.factorize
        if hasattr(plant, "newton_matrix"):
            self.newton_matrix = lambda x, v, a, t, cv, ca: plant.newton_matrix(x, v, a, t, cv, ca,
                                                                                  self.u)
        if hasattr(plant, "mass_matrix"):
            self.mass_matrix = plant.mass_matrix

    def residual(self, x, v, a, t):
        return self.plant.residual(x, v, a, t, self.u)

    def jacobians(self, x, v, a, t):
        return self.plant.jacobians(x, v, a, t, self.u)


def check_time_grid(t_end: float, dt: float) -> int:
    """Number of steps of a run of ``t_end`` seconds at step ``dt``; a duration shorter than
    one step or a non-finite value is refused."""
    if not (np.isfinite(t_end) and np.isfinite(dt) and t_end > 0 and dt > 0):
        raise InputError(f"expected finite t_end > 0 and dt > 0, found t_end={t_end!r}, dt={dt!r}")
    n = int(round(t_end / dt))
    if n < 1:
        raise InputError(f"expected t_end >= dt (at least one step), found t_end={t_end:g} s, "
                         f"dt={dt:g} s")
    return n


def simulate(plant, *, t_end: float, dt: float, controller=None, x0=None, v0=None,
             scheme: str = "park", jacobian: str = "step", tol: float = 1e-10,
             record: Callable | None = None, progress: Callable | None = None,
             outputs: bool = True, line_search: bool = False) -> Simulation:
    """Integrate ``plant`` over [0, t_end] with inputs from ``controller`` (module docstring).

    Parameters
    ----------
    plant : tmfem.models.base.Plant
        ``residual``, ``jacobians`` (and optionally ``newton_matrix``, ``factorize``),
        ``outputs``, ``x0``, ``v0``, ``u0``, ``input_names``, ``output_names``; optionally
        ``actuate(x, u)``, the model input realising the command u at the sampled state x,
        and ``sample(x, u)``, called with the sampled state and the input held over the step
        (module docstring).
    t_end, dt : float
        Duration and step (7.4: dt = 0.01 s).
    controller : Controller, array, callable or None
        The controller hook; an array or ``u(t)`` is an open-loop schedule; None holds the
        plant's nominal input ``u0`` (free vibration).
    x0, v0 : array, optional
        Start (default the plant's).
    scheme, jacobian, tol :
        Passed to :func:`park_integrate` with ``sampled=True``: the acceleration is re-solved
        with the controller's input before every trapezoidal step (all of ``"trapezoidal"``,
        the two starting steps of ``"park"``), so the zero-order-hold steps of u are
        integrated to second order there and the first step starts from the acceleration of
        the first input u_0 (not of the plant's nominal ``u0``); Park's multistep formula is
        first order across the steps of u. The Newton predictor is the plant's
        ``predictor`` attribute when it has one (default constant acceleration).
    record : callable, optional
        ``record(t, x, v, a, u, y)`` at every time (the start included); a true return
        value stops the run.
    progress : callable, optional
        ``progress(step, n_steps)``.
    outputs : bool
        Evaluate the plant outputs y at every step for the record and the result even when
        the controller does not read them (an open loop); False skips them there (``record``
        then gets ``y = None`` and ``Simulation.y`` is empty) -- a free vibration that
        records its own quantities.
    line_search : bool
        Backtracking on the Newton corrections of every step (:func:`park_integrate`).
    """
    n_steps = check_time_grid(t_end, dt)
    ctrl = as_controller(controller, plant.u0)
    loop = _ClosedLoop(plant)
    x0 = np.asarray(plant.x0 if x0 is None else x0, dtype=float)
    v0 = np.asarray(plant.v0 if v0 is None else v0, dtype=float)
    nu = len(plant.input_names)
    actuate = getattr(plant, "actuate", None)
    sample = getattr(plant, "sample", None)
    measure = outputs or getattr(ctrl, "reads_outputs", True)
    y0 = np.asarray(plant.outputs(x0, v0, loop.u), dtype=float) if measure else None
    xc = ctrl.reset(0.0, y0, dt)
    T, Y, U, C = [], [], [], []
    state = {"xc": xc}

    def step(t, x, v, a):
        y = np.asarray(plant.outputs(x, v, loop.u), dtype=float) if measure else None
        u = np.asarray(ctrl.output(t, y, state["xc"]), dtype=float)
        if u.shape != (nu,) or not np.all(np.isfinite(u)):
            raise InputError(f"controller {ctrl.name}: expected {nu} finite inputs at t = {t:.6g} s, "
                             f"found {u}")
        state["xc"] = ctrl.update(t, y, state["xc"])
        loop.u = u if actuate is None else np.asarray(actuate(x, u), dtype=float)
        if sample is not None:
            sample(x, loop.u)
        T.append(t)
        U.append(u)
        C.append(ctrl.name)
        if outputs:
            Y.append(y)
        return bool(record(t, x, v, a, u, y)) if record is not None else False

    t0 = time.perf_counter()
    res = park_integrate(loop, x0=x0, v0=v0, dt=dt, n_steps=n_steps, scheme=scheme, tol=tol,
                         jacobian=jacobian, callback=step, store=False, progress=progress,
                         sampled=True, predictor=getattr(plant, "predictor", "acceleration"),
                         line_search=line_search)
    return Simulation(t=np.array(T), y=np.array(Y), u=np.array(U), controller=C, x=res.x[-1],
                      v=res.v[-1], wall_time=time.perf_counter() - t0,
                      stats={"steps": res.steps, "newton_iterations": res.newton_iterations,
                             "jacobian_evaluations": res.jacobian_evaluations,
                             "restarts": res.restarts})
