"""Free vibration of the shell-beam-cable model about its equilibrium (dissertation 6.5).

The SBC model of :mod:`tmfem.models.sbc.model` as the plant of Park's method (eqs.
5.34-5.35) through the shared finite-element plant :class:`tmfem.models.fe.plant.FEPlant`:

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
derivative of the residual along u: the model's tangent K_T, which is along the incremental
spins, times the tangent operator of the exponential map (:func:`dexp`),

    d omega = dexp(theta) d theta,   dexp(theta) = I + (1 - cos p) / p^2 [theta]x
                                                 + (p - sin p) / p^3 [theta]x^2,   p = |theta|,

with theta = a_1 V_1 + a_2 V_2 (equilibrium directors) on a shell node and the spin taken back
onto the current V_1, V_2 (the spin about the director moves nothing).

Inputs, outputs (bar coordinates q, membrane deflections w_k at the monitored points of eqs.
5.36/5.38 in the floating frame) and the perturbed start are those of every FE plant.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from tmfem.fem.element import assemble, skew
from tmfem.models.fe.plant import FEPlant


def dexp(theta: np.ndarray) -> np.ndarray:
    """Tangent operators (n, 3, 3) of the exponential map at rotation vectors theta (n, 3)
    (module docstring; the series 1/2, 1/6 below |theta| = 1e-6)."""
    p = np.linalg.norm(theta, axis=1)
    small = p < 1e-6
    ps = np.where(small, 1.0, p)
    c1 = np.where(small, 0.5 - p**2 / 24, (1 - np.cos(ps)) / ps**2)
    c2 = np.where(small, 1 / 6 - p**2 / 120, (ps - np.sin(ps)) / ps**3)
    S = skew(theta)
    return np.eye(3) + c1[:, None, None] * S + c2[:, None, None] * (S @ S)


class SBCDynamics(FEPlant):
    """The SBC equation of motion as a :class:`tmfem.models.base.Plant` (module docstring).

    Parameters
    ----------
    model : SBCModel
    state_eq : State
        The static equilibrium (``model.equilibrium().state``).
    alpha, beta, perturb, output_points, damping_tangent :
        Rayleigh damping (and its tangent), initial perturbation and monitored points, as for
        :class:`tmfem.models.mtc.dynamics.MTCDynamics`.
    """

    name = "sbc"
    #: Park's Newton predictor (:func:`tmfem.solvers.park.park_integrate`): the shell's nodal
    #: rotations carry almost no inertia, so the acceleration is not extrapolated
    predictor = "velocity"

    def __init__(self, model, state_eq, *, alpha: float = 0.0, beta: float = 0.0,
                 perturb: dict | None = None, output_points=None,
                 damping_tangent: str | None = None):
        self.model = model
        self.dofmap, self.constraints = model.dofmap, model.constraints
        self.free = model.free
        self.state_eq = state_eq
        self._n_mtc = model.numbering.n_mtc_nodes
        self._tr = self.dofmap.translation_dofs(np.arange(self._n_mtc))       # (n, 3)
        self._setup(model.mass(state_eq), alpha=alpha, beta=beta, perturb=perturb,
                    output_points=output_points, damping_tangent=damping_tangent)

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

    def _rotation_jacobian(self, state, du) -> sp.csr_matrix:
        """d(spin increments) / d(parameters) (ndof, ndof) at the state of the full increment du
        from the equilibrium (module docstring): identity on translations."""
        dm = self.dofmap
        rows, cols, vals = [np.arange(dm.ndof)], [np.arange(dm.ndof)], [np.ones(dm.ndof)]
        keep = np.ones(dm.ndof, dtype=bool)
        for n_rot in (2, 3):
            nodes = np.flatnonzero(dm.counts == 3 + n_rot)
            if nodes.size == 0:
                continue
            rd = dm.rotation_dofs(nodes)                                    # (n, n_rot)
            a = du[rd]
            keep[rd.ravel()] = False
            if n_rot == 3:
                B_in = B_out = np.broadcast_to(np.eye(3), (nodes.size, 3, 3))
                theta = a
            else:
                Ve = np.einsum("nij,njk->nik", self.state_eq.R[nodes], self.state_eq.frames[nodes])
                B_in = Ve[:, :, :2]                                           # d theta / d a
                theta = np.einsum("nik,nk->ni", B_in, a)
                Vc = np.einsum("nij,njk->nik", state.R[nodes], state.frames[nodes])
                B_out = Vc[:, :, :2]                                          # spin -> b
            J = np.einsum("nji,njk,nkl->nil", B_out, dexp(theta), B_in)        # (n, n_rot, n_rot)
            rows.append(np.repeat(rd, n_rot, axis=1).ravel())
            cols.append(np.tile(rd, (1, n_rot)).ravel())
            vals.append(J.ravel())
        rows[0], cols[0], vals[0] = rows[0][keep], cols[0][keep], vals[0][keep]
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(dm.ndof, dm.ndof))

    def _tangent(self, x):
        """dr/du on the free dofs: T^T K_T dexp T (module docstring)."""
        du = self.constraints.full(self._reduced(x))
        state = self.model.advance(self.state_eq, self._reduced(x))
        _, K = assemble(self.model.elements, state)
        T = self.constraints.T
        Kr = (T.T @ (K @ (self._rotation_jacobian(state, du) @ T))).tocsr()
        return Kr[self.free][:, self.free].tocsc()

    def positions(self, u) -> np.ndarray:
        """Positions (3, n) of the nodes the MTC numbering has (membrane, system labels,
        tendon internal nodes) at the free-dof state u."""
        d = self.constraints.full(self._reduced(u))
        return self.state_eq.x[:, :self._n_mtc] + d[self._tr].T

    def bar_chain_positions(self, u) -> tuple[np.ndarray, np.ndarray]:
        """Positions (3, n_bars, n_chain) of every bar's beam-chain nodes, A_ij first and
        B_ij last (H_1j among them for a 1-N(D) system), at the free-dof state u, and their
        reference fractions s along the bar (``numbering.chain_s``)."""
        ch = self.model.numbering.bar_chain
        d = self.constraints.full(self._reduced(u))
        tr = self.dofmap.translation_dofs(ch.ravel())                          # (n, 3)
        x = self.state_eq.x[:, ch.ravel()] + d[tr].T
        return x.reshape(3, *ch.shape), self.model.numbering.chain_s

    def strain_energy(self, u) -> float:
        """Strain energy [J] of shells, beams and tendons (:meth:`SBCModel.energy`)."""
        return self.model.energy(self.configuration(u))

    def member_forces(self, u) -> dict:
        """Tendon element forces, tendon forces and bar axial forces [N] at the state u
        (:meth:`SBCModel.member_forces`); a tendon is slack where one of its elements is."""
        f = self.model.member_forces(self.configuration(u))
        slack = np.any(f["tendon_element"].reshape(f["tendon"].size, -1) <= 0.0, axis=1)
        return {"element_force": f["tendon_element"], "tendon_force": f["tendon"],
                "bar_force": f["bar"], "tendon_slack": slack}

    def state_of(self, xf: np.ndarray) -> np.ndarray:
        """The free-dof state whose positions (MTC numbering) are xf (3, n_mtc_nodes), the bars
        straight (their interior nodes on the chords of xf) and the nodal rotations those of
        the reference state (zero rotation vectors)."""
        x = self.state_eq.x.copy()
        x[:, :self._n_mtc] = xf
        ch = self.model.numbering.bar_chain
        x[:, ch] = self.model.along_bars(x)
        d = np.zeros(self.dofmap.ndof)
        tr = self.dofmap.translation_dofs(np.arange(x.shape[1]))
        d[tr] = (x - self.state_eq.x).T
        return self.constraints.reduce(d)[self.free]

    def membrane_stress(self, u) -> dict:
        """Peak shell stresses [Pa] (``max_von_mises``, ``max_sigma_p1``: Gauss points of the
        bottom, middle and top surfaces, :func:`tmfem.models.sbc.post.membrane_peaks`) at u."""
        from tmfem.models.sbc.post import membrane_peaks
        m = membrane_peaks(self.model, self.configuration(u))
        return {"max_von_mises": m["max_von_mises"], "max_sigma_p1": m["max_sigma_p1"]}
