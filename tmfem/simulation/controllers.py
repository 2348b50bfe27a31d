"""Controllers in the simulation loop: u = k(t, y, x_c), x_c+ = update(t, y, x_c).

A controller is sampled at the simulation's time step dt (a digital controller with a
zero-order hold, as the deployment simulations of 7.4 and 8.4 run at dt = 0.01 s): at t_n it
reads the plant outputs y_n, returns the input u_n that the plant sees over [t_n, t_n+1],
and advances its own states x_c. The protocol:

``reset(t0, y0, dt) -> x_c0``          initial controller state (bumpless start from y0);
``output(t, y, x_c) -> u``             the input, ordered as the plant's ``input_names``;
``update(t, y, x_c) -> x_c``           the controller state at t + dt;
``name``                               which controller acts (recorded per step; a switching
                                       controller reports the active one);
``reads_outputs`` (optional, True)     False for a controller that ignores y (an open loop):
                                       the driver may then skip evaluating the outputs.
"""
from __future__ import annotations

from typing import Protocol

import numpy as np

from tmfem.errors import InputError


class Controller(Protocol):
    """The controller hook of :func:`tmfem.simulation.simulate` (module docstring)."""

    name: str

    def reset(self, t0: float, y0: np.ndarray, dt: float) -> np.ndarray: ...

    def output(self, t: float, y: np.ndarray, xc: np.ndarray) -> np.ndarray: ...

    def update(self, t: float, y: np.ndarray, xc: np.ndarray) -> np.ndarray: ...


class OpenLoop:
    """Prescribed inputs: a constant array or a schedule ``u(t)`` (no controller states)."""

    name = "open-loop"
    reads_outputs = False

    def __init__(self, u):
        self._u = u if callable(u) else np.asarray(u, dtype=float)

    def reset(self, t0, y0, dt):
        return np.zeros(0)

    def output(self, t, y, xc):
        return np.asarray(self._u(t), dtype=float) if callable(self._u) else self._u

    def update(self, t, y, xc):
        return xc


class LinearController:
    """A linear time-invariant controller about an operating point, discretised exactly for a
    zero-order-hold sample time dt (python-control ``sample_system``, method ``"zoh"``):

        u = u_e + C_k x_c + D_k (y - y_e),      x_c(t + dt) = A_d x_c + B_d (y - y_e).

    Parameters
    ----------
    system : control.StateSpace or array_like
        Continuous-time controller from y - y_e to u - u_e, or a static gain matrix
        (state feedback u = u_e + K (y - y_e) with K = -gain for a stabilising law).
    u_e, y_e : array_like
        Operating point (equilibrium input and outputs).
    name : str
    """

    def __init__(self, system, *, u_e, y_e, name: str = "linear"):
        import control
        self.u_e = np.asarray(u_e, dtype=float)
        self.y_e = np.asarray(y_e, dtype=float)
        if not isinstance(system, control.StateSpace):
            D = np.atleast_2d(np.asarray(system, dtype=float))
            system = control.ss(np.zeros((0, 0)), np.zeros((0, D.shape[1])),
                                np.zeros((D.shape[0], 0)), D)
        if system.dt not in (0, None):
            raise InputError(f"linear controller: expected a continuous-time system, found dt = {system.dt}")
        if system.ninputs != self.y_e.size or system.noutputs != self.u_e.size:
            raise InputError(f"linear controller: expected {self.y_e.size} inputs (plant outputs) and "
                             f"{self.u_e.size} outputs (plant inputs), found {system.ninputs} and "
                             f"{system.noutputs}")
        self.system, self.name = system, name
        #: (A_d, B_d, C_k, D_k) of the zero-order-hold discretisation, set by :meth:`reset`
        self.discrete = None

    def reset(self, t0, y0, dt):
        """Discretise for dt; the controller state starts at zero (bumpless when the plant
        starts at the operating point)."""
        import control
        n = self.system.nstates
        if n:
            sd = control.sample_system(self.system, dt, method="zoh")
            self.discrete = (np.asarray(sd.A), np.asarray(sd.B), np.asarray(sd.C), np.asarray(sd.D))
        else:
            D = np.asarray(self.system.D)
            self.discrete = (np.zeros((0, 0)), np.zeros((0, D.shape[1])), np.zeros((D.shape[0], 0)), D)
        return np.zeros(n)

    def output(self, t, y, xc):
        _, _, C, D = self.discrete
        return self.u_e + C @ xc + D @ (np.asarray(y) - self.y_e)

    def update(self, t, y, xc):
        A, B, _, _ = self.discrete
        return A @ xc + B @ (np.asarray(y) - self.y_e)


class MeasurementNoise:
    """``controller`` reading y + sigma * n_k: independent zero-mean Gaussian samples of
    standard deviation ``sigma`` (scalar or one per entry of ``index``) added to the entries
    ``index`` of y (all by default), one sample per time step (the same at ``output`` and
    ``update`` of a step), seeded for reproducibility. Sampled white noise: its intensity
    over dt is sigma^2 dt."""

    def __init__(self, controller, *, sigma, index=None, seed: int = 0):
        self.controller = controller
        self.sigma = np.asarray(sigma, dtype=float)
        if not np.all(np.isfinite(self.sigma)) or np.any(self.sigma < 0):
            raise InputError(f"measurement noise: expected sigma >= 0, found {sigma!r}")
        self.index = None if index is None else np.asarray(index, dtype=int)
        self._rng = np.random.default_rng(seed)
        self._t, self._n = None, None

    @property
    def name(self) -> str:
        return self.controller.name

    def _noisy(self, t, y):
        y = np.array(y, dtype=float)
        idx = np.arange(y.size) if self.index is None else self.index
        if t != self._t:
            self._t, self._n = t, self.sigma * self._rng.standard_normal(idx.size)
        y[idx] += self._n
        return y

    def reset(self, t0, y0, dt):
        self._t = None
        return self.controller.reset(t0, self._noisy(t0, y0), dt)

    def output(self, t, y, xc):
        return self.controller.output(t, self._noisy(t, y), xc)

    def update(self, t, y, xc):
        return self.controller.update(t, self._noisy(t, y), xc)


def as_controller(controller, u0) -> Controller:
    """``controller`` itself (it has reset/output/update), an open loop at the plant's nominal
    input ``u0`` when None, or an open loop at the given array or schedule ``u(t)``."""
    if controller is None:
        return OpenLoop(u0)
    if all(hasattr(controller, m) for m in ("reset", "output", "update")):
        return controller
    if callable(controller) or isinstance(controller, (np.ndarray, list, tuple)):
        return OpenLoop(controller)
    raise InputError(f"controller: expected an object with reset/output/update (tmfem.simulation."
                     f"controllers), an array or a schedule u(t), found {type(controller).__name__}")
