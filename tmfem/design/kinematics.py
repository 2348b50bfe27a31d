"""How the state of a finite-element model moves along a reduced increment, for the design
sensitivities (:func:`tmfem.design.sensitivities.design_sensitivities`).

* MTC (positions only): the reduced positions xr move to xr + du; the node positions are
  ``model.full`` of them (linear).
* SBC (positions and nodal rotations): the state advances by ``model.advance`` (translations
  added, rotations composed by the exponential map, the update its tangent differentiates);
  the translations of the full increment move the nodes. Its membrane stresses are those of
  the shells' mid surface at the 2 x 2 Gauss points (:func:`tmfem.models.sbc.post.shell_stresses`),
  its bar forces the beams' axial forces (``member_forces``).

Each adapter gives: ``T`` (the reduced-to-full map of the residual), ``x`` (node positions of
the model's own numbering, (3, n)), ``point(du)`` (the residual's argument after the reduced
increment du), ``tangent(point)``, ``mass(point)`` (the MTC model's does not depend on it),
``positions(du)`` (the translations (3, n) of a reduced increment), ``supports(rate)`` (the
reduced increment that moves the pinned bases A_1j by ``rate`` (3, N) and nothing else: a
1-N system's angle moves them), ``membrane(point)`` (von
Mises and minor principal stresses and the reference points (2, ne, nqp) where they are
evaluated), ``areas()`` (the reference areas dA_g (ne, nqp) of those points: the MTC
membrane's Gauss weights |det J| w; the SBC shells' element areas / 4, their Gauss points
being those of the same 2 x 2 rule on the same mesh) and, for the SBC model,
``bar_forces(point)``.
"""
from __future__ import annotations

import numpy as np

from tmfem.design.responses import minor_principal
from tmfem.fem.membrane import q1_gauss_arrays


def _gauss_areas(mesh) -> np.ndarray:
    """Reference areas |det J| w (ne, 4) of the 2 x 2 Gauss points of the quadrilateral ``mesh``."""
    return q1_gauss_arrays(np.asarray(mesh.p, dtype=float), np.asarray(mesh.t))[2]


class MTCKinematics:
    """The MTC model's (module docstring)."""

    def __init__(self, model, eq):
        self.model = model
        self.x = eq.state
        self.xr = model.reduce(self.x)
        self.T = model.topology.T
        self.n_mesh = model.topology.n_mesh

    def point(self, du):
        return self.xr + du

    def tangent(self, point):
        return self.model.residual(point)[1]

    def mass(self, point):
        return self.model.mass()

    def positions(self, du) -> np.ndarray:
        return self.model.full(du)

    def supports(self, rate) -> np.ndarray:
        x = np.zeros((3, self.model.topology.n_nodes))
        x[:, self.model.topology.fixed_nodes] = rate
        return self.model.reduce(x)

    def membrane(self, point):
        st = self.model.membrane.stresses(self.model.full(point)[:, :self.n_mesh])
        return st.von_mises, minor_principal(st.cauchy), st.points

    def areas(self) -> np.ndarray:
        return _gauss_areas(self.model.topology.mesh)


class SBCKinematics:
    """The SBC model's (module docstring)."""

    def __init__(self, model, eq):
        self.model = model
        self.state = eq.state
        self.x = eq.state.x
        self.T = model.constraints.T
        self.n_mesh = model.topology.n_mesh
        self._tr = model.dofmap.translation_dofs(np.arange(model.dofmap.n_nodes))      # (n, 3)
        mesh = model.topology.mesh
        centres = np.asarray(mesh.p)[:, np.asarray(mesh.t)].mean(axis=1)                 # (2, ne)
        self._points = np.repeat(centres[:, :, None], 4, axis=2)

    def point(self, du):
        return self.model.advance(self.state, du)

    def tangent(self, point):
        K = self.model.residual(point)[1]
        return 0.5 * (K + K.T)

    def mass(self, point):
        return self.model.mass(point)

    def positions(self, du) -> np.ndarray:
        return self.model.constraints.full(du)[self._tr].T

    def supports(self, rate) -> np.ndarray:
        u = np.zeros(self.model.dofmap.ndof)
        u[self._tr[self.model.topology.fixed_nodes]] = np.asarray(rate).T
        return self.model.constraints.reduce(u)

    def membrane(self, point):
        from tmfem.models.sbc.post import shell_stresses
        g = shell_stresses(self.model, point)["gauss"]
        return g["von_mises"][1], g["sigma_p2"][1], self._points

    def areas(self) -> np.ndarray:
        return np.repeat(_gauss_areas(self.model.topology.mesh).mean(axis=1, keepdims=True), 4, axis=1)

    def bar_forces(self, point) -> np.ndarray:
        return self.model.member_forces(point)["bar"]


def kinematics(model, eq):
    """The adapter of ``model`` (an MTC or SBC model, ``model.name``) at the equilibrium ``eq``."""
    return (SBCKinematics if model.name == "sbc" else MTCKinematics)(model, eq)
