"""Free vibration of the shell-beam-cable model about its equilibrium (dissertation 6.5).

The SBC model of :mod:`tmfem.models.sbc.model` as the plant of Park's method (eqs.
5.34-5.35) through the shared finite-element plant :class:`tmfem.models.fe_plant.FEPlant`:

    M a + C v + f_int(u; rest) = 0,        C = alpha M + beta K_0,

on the free reduced dofs. The state u counts from the static equilibrium s_e: translations
are added and the nodal rotations composed by the exponential map (``SBCModel.advance``),

    x = x_e + T u (translations),   R = exp([theta(u)]) R_e,

so u = 0 is the equilibrium and every u is a configuration of the shells and beams (their
finite-rotation kinematics, 4.3). M is the mass at the equilibrium directors (shell rotary
inertia included) and held constant, as the MTC model's; with u the rotation vector from the
equilibrium, the rotational inertia terms are linear in the rotation rates (the gyroscopic
terms of the rotary inertia, of the order of the squared rates, are left out: the 51 um shell
and the slender bars carry almost none of the kinetic energy). The Newton matrix is the
tangent of the model along its incremental rotations, which differs from the derivative along
the total rotation vector by the exponential map's tangent operator, I + O(|theta|): Park's
modified Newton iteration converges to the same step either way.

Inputs, outputs (bar coordinates q, membrane deflections w_k at the monitored points of eqs.
5.36/5.38 in the floating frame) and the perturbed start are those of every FE plant.
"""
from __future__ import annotations

import numpy as np

from tmfem.models.fe_plant import FEPlant


class SBCDynamics(FEPlant):
    """The SBC equation of motion as a :class:`tmfem.models.base.Plant` (module docstring).

    Parameters
    ----------
    model : SBCModel
    state_eq : State
        The static equilibrium (``model.solve_static().state``).
    alpha, beta, perturb, output_points :
        Rayleigh damping, initial perturbation and monitored points, as for
        :class:`tmfem.models.mtc.dynamics.MTCDynamics`.
    """

    def __init__(self, model, state_eq, *, alpha: float = 0.0, beta: float = 0.0,
                 perturb: dict | None = None, output_points=None):
        self.model, self.mtc = model, model.mtc
        self.dofmap, self.constraints = model.dofmap, model.constraints
        self.free = model.free
        self.state_eq = state_eq
        self._n_mtc = model.numbering.n_mtc_nodes
        self._tr = self.dofmap.translation_dofs(np.arange(self._n_mtc))       # (n, 3)
        self._setup(model.mass(state_eq), alpha=alpha, beta=beta, perturb=perturb,
                    output_points=output_points)

    def state0(self) -> np.ndarray:
        """The equilibrium: zero increments."""
        return np.zeros(int(self.free.sum()))

    def _reduced(self, u) -> np.ndarray:
        du = np.zeros(self.free.size)
        du[self.free] = u
        return du

    def configuration(self, u):
        """The :class:`~tmfem.fem.element.State` of the free-dof state u (module docstring)."""
        return self.model.advance(self.state_eq, self._reduced(u))

    def positions(self, u) -> np.ndarray:
        """Positions (3, n) of the nodes the MTC numbering has (membrane, system labels,
        tendon internal nodes) at the free-dof state u."""
        d = self.constraints.full(self._reduced(u))
        return self.state_eq.x[:, :self._n_mtc] + d[self._tr].T

    def strain_energy(self, u) -> float:
        """Strain energy [J] of shells, beams and tendons (:meth:`SBCModel.energy`)."""
        return self.model.energy(self.configuration(u))

    def member_forces(self, u) -> dict:
        """Tendon element forces, tendon forces and bar axial forces [N] at the state u
        (:meth:`SBCModel.member_forces`)."""
        f = self.model.member_forces(self.configuration(u))
        return {"element_force": f["tendon_element"], "tendon_force": f["tendon"],
                "bar_force": f["bar"]}
