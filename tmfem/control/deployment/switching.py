"""Switch from the deployment controller to a linear controller about the final equilibrium
(dissertation 7.3-7.4, eq. 5.70).

The switch happens at the first sample where

    || (q - q_e) / q_e ||_2 <= R_c     (eq. 5.70, element-wise division; R_c = 0.01 in 7.4),

and is permanent. q_d of eq. 5.70 is read as the final configuration q_e: with the
time-varying reference the condition would hold at t = 0, where q = q_d(0) (docs/validation/errata.md).

The linear controller is any :class:`tmfem.simulation.controllers.LinearController` from
y_lin - y_e to u - u_e (an H-infinity controller of 7.3, an LQR state feedback, ...);
``measure(y)`` maps the plant outputs seen by the switching controller onto its inputs
y_lin. The linear controller's state x_c at the switch (``start``):

* ``"bumpless"``: chosen, in the least-squares sense, so that its first output equals the
  last input of the deployment controller (C_k x_c = u_prev - u_e - D_k (y_lin - y_e)). The
  minimum-norm solution depends on the controller's state coordinates (two realisations of
  one transfer function start differently).
* ``"estimate"``: x_c = y_lin - y_e, for a controller whose state estimates the measured
  state perturbation in the coordinates of y_lin (an observer, such as the central
  H-infinity controller, :mod:`tmfem.control.linear.hinf_central`): it starts with zero estimation
  error; the input then jumps to the controller's own. A controller designed on the reachable
  part of the plant (:meth:`tmfem.control.linear.partitioned_plant.GeneralizedPlant.reachable_part`,
  states x_r = Z_r^T x) starts at x_c = E (y_lin - y_e) with ``estimate`` E = Z_r^T.

A static gain has no state. The jump in u at the switch is reported (``switch_jump``).
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError

#: initialisations of the linear controller's state at the switch
STARTS = ("bumpless", "estimate")


def relative_error(q, q_e):
    """|| (q - q_e) / q_e ||_2 of eq. 5.70: a float for one configuration q, an array for
    a history q (n, n_q)."""
    q_e = np.asarray(q_e, dtype=float)
    if np.any(q_e == 0):
        raise InputError("eq. 5.70: expected nonzero final coordinates q_e (element-wise "
                         f"division), found zeros at {np.flatnonzero(q_e == 0).tolist()}")
    r = np.linalg.norm((np.asarray(q, dtype=float) - q_e) / q_e, axis=-1)
    return float(r) if np.ndim(r) == 0 else r


class SwitchingController:
    """Controller hook: ``first`` until eq. 5.70 holds, then ``second`` (module docstring).

    Parameters
    ----------
    first : controller
        The deployment controller (reads the plant outputs y).
    second : LinearController
    q_of_y : callable
        q from y (for eq. 5.70).
    q_e : array
        Final configuration.
    measure : callable
        y -> inputs of ``second``.
    R_c : float
        Switching radius (7.4: 0.01).
    start : {"bumpless", "estimate"}
        The linear controller's state at the switch (module docstring).
    estimate : array, optional
        E of an ``"estimate"`` start, x_c = E (y_lin - y_e) (module docstring); default the
        identity.
    """

    def __init__(self, *, first, second, q_of_y, q_e, measure, R_c: float = 0.01,
                 start: str = "bumpless", estimate=None):
        if not R_c > 0:
            raise InputError(f"R_c: expected > 0, found {R_c!r}")
        if start not in STARTS:
            raise InputError(f"start: expected one of {STARTS}, found {start!r}")
        self.start = start
        self.estimate = None if estimate is None else np.asarray(estimate, dtype=float)
        self.first, self.second = first, second
        self.q_of_y, self.q_e, self.measure, self.R_c = q_of_y, np.asarray(q_e, float), measure, R_c
        relative_error(self.q_e, self.q_e)                   # refuses zero entries of q_e
        self._inv_q_e = 1.0 / self.q_e                       # eq. 5.70, element-wise
        self.switch_time = None
        self.switch_jump = None
        self._n1 = 0

    @property
    def name(self) -> str:
        return self.second.name if self.switch_time is not None else self.first.name

    def reset(self, t0, y0, dt):
        self.dt = dt
        self.switch_time = None
        self.switch_jump = None
        self._u_prev = None
        x1 = np.asarray(self.first.reset(t0, y0, dt), dtype=float)
        self._n1 = x1.size
        return x1

    def _maybe_switch(self, t, y, xc):
        if self.switch_time is not None or \
                np.linalg.norm((self.q_of_y(y) - self.q_e) * self._inv_q_e) > self.R_c:
            return xc
        self.switch_time = float(t)
        yl = np.asarray(self.measure(y), dtype=float)
        x2 = np.asarray(self.second.reset(t, yl, self.dt), dtype=float)
        _, _, C, D = self.second.discrete
        if x2.size and self.start == "estimate" and self.estimate is not None:
            return self.estimate @ (yl - self.second.y_e)
        if x2.size and self.start == "estimate":
            if x2.size != yl.size:
                raise InputError(f"start 'estimate': expected a controller of order "
                                 f"{yl.size} (its state estimates y - y_e), found {x2.size}")
            return yl - self.second.y_e
        if x2.size and self._u_prev is not None:
            rhs = self._u_prev - self.second.u_e - D @ (yl - self.second.y_e)
            x2 = np.linalg.lstsq(C, rhs, rcond=None)[0]
        return x2

    def output(self, t, y, xc):
        if self.switch_time is None:
            xc2 = self._maybe_switch(t, y, xc)
            if self.switch_time is None:
                u = np.asarray(self.first.output(t, y, xc), dtype=float)
                self._u_prev = u
                return u
            self._xc_switch = xc2
            u = np.asarray(self.second.output(t, self.measure(y), xc2), dtype=float)
            if self._u_prev is not None:
                self.switch_jump = float(np.max(np.abs(u - self._u_prev)))
            return u
        return np.asarray(self.second.output(t, self.measure(y), xc), dtype=float)

    def update(self, t, y, xc):
        if self.switch_time is None:
            return self.first.update(t, y, xc)
        if self.switch_time == t:
            xc = self._xc_switch
        return self.second.update(t, self.measure(y), xc)
