"""The model interface every model of a tensegrity-membrane system implements.

A model is built from one :class:`~tmfem.system.System` (and, for the finite-element models, a
linear-algebra ``backend=``) and offers

* named signals: ``input_names`` (tendon rest lengths ``r_<tendon>``, the control inputs u of
  eq. 5.19), ``output_names`` (bar coordinates q of eqs. 3.1-3.2 and membrane deflections
  ``w_k`` at the monitored points, eqs. 5.36-5.38), and the nominal input ``u0``;
* ``equilibrium(u=None) -> Equilibrium``: the static equilibrium for rest lengths u (default
  ``u0``) with its state, tangent, iteration history and named outputs;
* ``modes(k=..., at=result)``: the ``k`` lowest natural modes about an equilibrium (eq. 5.32);
* ``plant(at=result, ...)``: the equation of motion as a :class:`Plant` that the simulation
  driver and Park's method (eqs. 5.34-5.35) integrate, with the inputs u(t) entering the
  residual -- so a controller can drive any model, the finite-element models included;
* ``linearize(at=result) -> control.StateSpace``: the linearisation about an equilibrium
  (eq. 5.33) with named states, inputs and outputs.

A :class:`Plant` is the second-order residual form of a model about a start state,

``residual(x, v, a, t, u) -> r``              eq. 5.27 (COM) or M a + C v + f_int(x; u) (FE);
``jacobians(x, v, a, t, u) -> (K, C, M)``     dr/dx, dr/dv, dr/da (Park's method, eq. 5.34);
``newton_matrix(x, v, a, t, cv, ca, u)``      K + cv C + ca M (the Newton matrix of eq. 5.34);
``outputs(x, v, u) -> y``                     the measured signals, ordered as ``output_names``;
``x0, v0``                                    the start state; ``u0`` the nominal input;

plus ``input_names``/``output_names``. The registry of models and their options is
:mod:`tmfem.models.registry`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from tmfem.errors import InputError


@runtime_checkable
class Plant(Protocol):
    """The equation of motion of a model with its inputs (module docstring)."""

    input_names: list
    output_names: list
    u0: np.ndarray
    x0: np.ndarray
    v0: np.ndarray

    def residual(self, x, v, a, t, u) -> np.ndarray: ...

    def jacobians(self, x, v, a, t, u): ...

    def newton_matrix(self, x, v, a, t, cv, ca, u): ...

    def outputs(self, x, v, u) -> np.ndarray: ...


@dataclass
class Equilibrium:
    """A static equilibrium of a model and the iteration that reached it.

    Attributes
    ----------
    state : object
        The model's configuration: node positions (3, n_nodes) of the MTC model, the nodal
        :class:`~tmfem.fem.element.State` (positions and rotations) of the SBC model, the
        coordinates z of the control-oriented model.
    u : ndarray
        The tendon rest lengths (inputs) of the equilibrium, ordered as ``input_names``.
    outputs : dict
        Output name -> value at the equilibrium (``output_names``: q, w_k).
    tangent : matrix, optional
        The tangent at the equilibrium as the last iteration assembled it; ``modes`` and
        ``linearize`` reuse it.
    iterations : int
    residual_history : list of float
        Norm of the residual after each iteration (first: the start).
    mu_history : list of float
        The trust-region (Levenberg-Marquardt) parameter mu of each step of the finite-element
        static solves (0: a Newton step); empty for a plain Newton iteration.
    monitor : dict
        Node label -> array (iterations + 1, 3) of monitored node positions (FE models).
    time : float
        Wall time [s].
    level_iterations : list of int
        Iterations per level of a mesh-sequenced solve, or of the predictor and the model.
    predictor_iterations : int
        Iterations of a predictor solve (the SBC model's MTC predictor), included in
        ``monitor`` and ``residual_history`` but not in ``iterations``.
    """

    state: object
    u: np.ndarray
    outputs: dict = field(default_factory=dict)
    tangent: object = None
    iterations: int = 0
    residual_history: list = field(default_factory=list)
    mu_history: list = field(default_factory=list)
    monitor: dict = field(default_factory=dict)
    time: float = 0.0
    level_iterations: list = field(default_factory=list)
    predictor_iterations: int = 0

    @property
    def x(self) -> np.ndarray:
        """Node positions (3, n_nodes) of a finite-element state; the coordinates z of the
        control-oriented model."""
        return getattr(self.state, "x", self.state)

    def __repr__(self) -> str:
        r = self.residual_history
        its = f"{self.iterations} iterations" + (f", |r| {r[0]:.3g} -> {r[-1]:.3g}" if r else "")
        return f"Equilibrium({its})"


@runtime_checkable
class Model(Protocol):
    """What every model of a system provides (module docstring)."""

    system: object
    input_names: list
    output_names: list
    u0: np.ndarray

    def equilibrium(self, u=None) -> Equilibrium: ...

    def modes(self, *, k: int, at=None): ...

    def plant(self, *, at=None) -> Plant: ...

    def linearize(self, *, at=None): ...


def split_perturbation(perturb: dict | None, names) -> tuple[np.ndarray, np.ndarray]:
    """Initial offsets and rates of the coordinates ``names`` from a perturbation by name.

    Parameters
    ----------
    perturb : dict or None
        ``{"theta_11_dot": 0.01, "theta_12": 0.001}``: a coordinate name adds to its value,
        ``<name>_dot`` to its rate (6.5.1-6.5.2).
    names : list of str
        The coordinates (``system.q_names`` for the FE models, ``model.z_names`` for the COM).

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
        if not np.isfinite(val):
            raise InputError(f"perturbation {k}: expected a finite number, found {val!r}")
        i = accepted.index(k)
        if i < len(names):
            d[i] += val
        else:
            d_dot[i - len(names)] += val
    return d, d_dot


class LinearPlant:
    """The linear second-order plant M a + C v + K (x - x_e) + B (u - u_e) = 0 with outputs
    y = y_e + C_y [x - x_e; v] (a linearisation, eq. 5.33), as a :class:`Plant`.

    Parameters
    ----------
    M, C, K, B : ndarray
    x_e, u_e, y_e : ndarray
        Operating point.
    Cy : ndarray (ny, 2 n)
    x0, v0 : ndarray, optional
        Start (default the operating point at rest).
    """

    def __init__(self, *, M, C, K, B, Cy, x_e, u_e, y_e, input_names, output_names,
                 x0=None, v0=None):
        self.M, self.C, self.K, self.B, self.Cy = (np.asarray(a, dtype=float) for a in (M, C, K, B, Cy))
        self.x_e, self.u0, self.y_e = (np.asarray(a, dtype=float) for a in (x_e, u_e, y_e))
        self.input_names, self.output_names = list(input_names), list(output_names)
        self.x0 = self.x_e.copy() if x0 is None else np.asarray(x0, dtype=float)
        self.v0 = np.zeros_like(self.x_e) if v0 is None else np.asarray(v0, dtype=float)

    def residual(self, x, v, a, t, u):
        """M a + C v + K (x - x_e) + B (u - u_e)."""
        return self.M @ a + self.C @ v + self.K @ (x - self.x_e) + self.B @ (u - self.u0)

    def jacobians(self, x, v, a, t, u):
        """(K, C, M)."""
        return self.K, self.C, self.M

    def newton_matrix(self, x, v, a, t, cv, ca, u):
        """K + cv C + ca M."""
        return self.K + cv * self.C + ca * self.M

    def outputs(self, x, v, u):
        """y_e + C_y [x - x_e; v]."""
        return self.y_e + self.Cy @ np.concatenate([x - self.x_e, v])
