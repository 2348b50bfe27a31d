"""The scheduled LPV state feedback of ch. 8 as a simulation controller (8.3-8.4).

u = u_e(rho_e) + K(rho) [x_z - x_e(rho_e); xi],   xi' = q_d(t) - q,   K(rho) = Q(rho) P(rho)^-1

(eq. 5.99 with the integral of the tracking error of eq. 5.98 as the extra states of
Fig. 8.1). The parameters rho are read from the measured outputs (8.4 schedules on the
measured theta_13, psi_13) and held inside the design grid; u_e, x_e are the equilibria of
the grid points (:class:`~tmfem.control.lpv.plant.GriddedLPV`) interpolated multilinearly at
rho_e: the measured rho by default, or the parameters rho_r(t) of the reference
(``reference_rho``). For a quasi-LPV plant, where rho is a state (theta_13), x_z - x_e(rho)
has no component along rho: about the measured rho the feedback cannot see an error in
theta_13 and only the integrators act (docs/guides/lpv.md); about rho_r(t), x_z - x_e(rho_r) is
the deviation from the equilibrium the reference passes through, and u_e(rho_r) its
feed-forward. Protocol of :mod:`tmfem.simulation.controllers`: the integrator advances by
forward Euler over the sample time dt (zero-order hold of q_d - q).
"""
from __future__ import annotations

import numpy as np

from tmfem.control.lpv.plant import GriddedLPV
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.errors import InputError


class Scheduled:
    """What the scheduled controllers share: the reference q_d(t), the parameters read from y
    at ``rho_index`` and held inside the design grid ``axes``, the operating point rho_r(t)
    (``reference_rho``, optional) and the sample time."""

    def _schedule(self, axes, rho_index, reference, what: str, reference_rho=None) -> None:
        self.rho_index = np.asarray(rho_index, dtype=int)
        if not callable(reference):
            raise InputError(f"{what}: expected the reference q_d(t) as a callable")
        if reference_rho is not None and not callable(reference_rho):
            raise InputError(f"{what}: expected the reference parameters rho_r(t) as a callable")
        self.reference, self.reference_rho = reference, reference_rho
        self._lo = np.array([a[0] for a in axes])
        self._hi = np.array([a[-1] for a in axes])
        self._what, self._dt = what, None

    def rho(self, y) -> np.ndarray:
        """Scheduling parameters from y, held inside the design grid."""
        return np.clip(np.asarray(y, dtype=float)[self.rho_index], self._lo, self._hi)

    def operating_rho(self, t, rho) -> np.ndarray:
        """Where x_e, u_e of the control law are taken: rho_r(t) (held inside the grid) when
        ``reference_rho`` is given, else ``rho``."""
        if self.reference_rho is None:
            return rho
        return np.clip(np.asarray(self.reference_rho(t), dtype=float), self._lo, self._hi)

    def _sample_time(self, dt) -> None:
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"{self._what}: expected a sample time dt > 0, found {dt!r}")
        self._dt = float(dt)


class LPVController(Scheduled):
    """Scheduled state feedback with integral action (module docstring).

    Parameters
    ----------
    design : LPVStateFeedback
        P_k, Q_k of eq. 5.99 over the states [x_z, xi] (``n_x + n_q``).
    plant : GriddedLPV
        The design plant: grid, equilibria x_e, u_e and the state order of x_z.
    state_index, q_index, rho_index : sequences of int
        Positions in the measured output vector y of x_z (in ``plant.state_names`` order), of
        the tracked coordinates q (in the order of the integrators) and of the scheduling
        parameters rho (in ``plant.parameter_names`` order).
    reference : callable
        t -> q_d(t), the tracked reference (absolute values, as q in y).
    reference_rho : callable, optional
        t -> rho_r(t), the operating point of x_e, u_e (module docstring); default the
        measured rho.
    """

    def __init__(self, design: LPVStateFeedback, plant: GriddedLPV, *, state_index, q_index, rho_index,
                 reference, reference_rho=None, name: str = "lpv"):
        self.design, self.plant, self.name = design, plant, name
        self.state_index = np.asarray(state_index, dtype=int)
        self.q_index = np.asarray(q_index, dtype=int)
        self._schedule(plant.axes, rho_index, reference, "LPV controller", reference_rho)
        n, nq = plant.nx, self.q_index.size
        nk = design.P[0].shape[0]
        if self.state_index.size != n or nk != n + nq or self.rho_index.size != len(plant.axes):
            raise InputError(f"LPV controller: expected {n} state, {nk - n} tracked and {len(plant.axes)} "
                             f"scheduling indices, found {self.state_index.size}, {nq} and "
                             f"{self.rho_index.size}")

    @property
    def read_index(self) -> np.ndarray:
        """The entries of y the controller reads (x_z and rho)."""
        return np.concatenate([self.state_index, self.rho_index])

    def reset(self, t0, y0, dt):
        self._sample_time(dt)
        return np.zeros(self.q_index.size)

    def output(self, t, y, xc):
        y = np.asarray(y, dtype=float)
        r = self.rho(y)
        re = self.operating_rho(t, r)
        x_e, u_e = self.plant.interpolate(("x_e", "u_e"), re)
        return u_e + self.design.gain(r) @ np.concatenate([y[self.state_index] - x_e, xc])

    def update(self, t, y, xc):
        return xc + self._dt * (np.asarray(self.reference(t), dtype=float) - np.asarray(y)[self.q_index])
