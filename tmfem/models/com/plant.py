"""The control-oriented model as a simulation plant (eq. 5.27 with its inputs)."""
from __future__ import annotations

import numpy as np

from tmfem.models.base import split_perturbation


class COMPlant:
    """M_hat z'' + F_hat + B_hat u = 0 (eq. 5.27) of a :class:`ControlOrientedModel` as a
    :class:`tmfem.models.base.Plant`: inputs the rest lengths ``r_<tendon>``, outputs
    y = [q, w at the output points], started at the equilibrium for ``u0`` plus a
    perturbation by state name (``theta_11_dot=0.01``, 6.5)."""

    def __init__(self, model, *, perturb: dict | None = None, z_e=None):
        self.model = model
        dz, dzd = split_perturbation(perturb, model.z_names)
        self.x_e = model.equilibrium().state if z_e is None else np.asarray(z_e, dtype=float)
        self.x0 = self.x_e + dz
        self.v0 = dzd
        self.u0 = np.asarray(model.u0, dtype=float)
        self.input_names, self.output_names = model.input_names, model.output_names

    def residual(self, x, v, a, t, u):
        return self.model.residual(x, v, a, t, u=u)

    def jacobians(self, x, v, a, t, u):
        return self.model.jacobians(x, v, a, t, u=u)

    def newton_matrix(self, x, v, a, t, cv, ca, u):
        return self.model.newton_matrix(x, v, a, t, cv, ca, u=u)

    def outputs(self, x, v, u):
        return self.model.outputs(x)
