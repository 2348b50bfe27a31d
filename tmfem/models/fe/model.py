"""The part of the model interface (:mod:`tmfem.models.base`) that both finite-element models
share: named signals, the equilibrium argument ``at=``, outputs, plant and linearisation.

A finite-element model (:class:`tmfem.models.mtc.model.MTCModel`,
:class:`tmfem.models.sbc.model.SBCModel`) provides ``system``, ``backend``, ``rest_lengths``
and ``nominal_rest_lengths``, ``equilibrium(u=None, ...)`` and ``modes(k=..., at=...)``, the
placement ``topology`` (:class:`tmfem.models.fe.topology.MTCTopology`: system nodes, membrane
mesh) on which its node positions are numbered, ``positions_of(state)`` (the node positions in
that numbering) and ``plant_type`` (its :class:`tmfem.models.fe.plant.FEPlant`).
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError, ResourceLimit
from tmfem.models.base import Equilibrium
from tmfem.models.fe.outputs import MeasuredOutputs
from tmfem.models.fe.plant import perturbation_names

#: largest number of free dofs of a full (unreduced) linearisation: its A is dense
MAX_FULL_LINEARIZATION = 4000


class FEModel:
    """Mix-in of the finite-element models (module docstring)."""

    plant_type = None
    _measured = None

    # ------------------------------------------------------------------ named signals
    @property
    def u0(self) -> np.ndarray:
        """The nominal inputs: the tendon rest lengths the model was built with."""
        return self.nominal_rest_lengths

    @property
    def input_names(self) -> list[str]:
        """``r_<tendon>``: the tendon rest lengths (eq. 5.19)."""
        return [f"r_{t.name}" for t in self.system.tendons]

    @property
    def output_names(self) -> list[str]:
        """The bar coordinates q (eqs. 3.1-3.2) and the deflections ``w_k`` at
        ``system.monitor_points`` (eqs. 5.36-5.38)."""
        return self.measured.names

    @property
    def measured(self) -> MeasuredOutputs:
        """The outputs at ``system.monitor_points`` (:class:`MeasuredOutputs`)."""
        if self._measured is None:
            self._measured = MeasuredOutputs(self.system, self.topology)
        return self._measured

    def outputs(self, state) -> np.ndarray:
        """y = [q, w_k] of a configuration of the model (ordered as ``output_names``)."""
        return self.measured.of(self.positions_of(state))

    def named_outputs(self, state) -> dict:
        """:meth:`outputs` by name."""
        return dict(zip(self.output_names, self.outputs(state).tolist()))

    @property
    def perturbation_names(self) -> list[str]:
        """The initial perturbations a plant accepts: the q of 3.2 and their rates
        (``theta_12_dot``, :func:`tmfem.models.fe.plant.initial_state`)."""
        return perturbation_names(self.system)

    @property
    def max_modes(self) -> int:
        """The most modes :meth:`modes` can compute: one less than the free dofs."""
        return self.ndof - 1

    def describe(self) -> dict:
        """Size and discretisation of the model, for reports."""
        return {"mesh": int(self.topology.mesh.n), "ndof": self.ndof,
                "tendon_elements": self.topology.tendon_elements}

    def describe_text(self) -> str:
        """:meth:`describe` as text for titles: "mesh 10 x 10, 5,067 DOFs, 3 elements per tendon"."""
        d = self.describe()
        return (f"mesh {d['mesh']} x {d['mesh']}, {d['ndof']:,} DOFs, {d['tendon_elements']} "
                f"element{'s' if d['tendon_elements'] != 1 else ''} per tendon")

    # ------------------------------------------------------------------ at=
    def _at(self, at):
        """(state, tangent) of ``at``: an :class:`Equilibrium` of this model, a configuration
        (tangent None) or None (:meth:`equilibrium` with its defaults)."""
        if at is None:
            at = self.equilibrium()
        if isinstance(at, Equilibrium):
            return at.state, at.tangent
        return at, None

    # ------------------------------------------------------------------ plant
    def plant(self, *, at=None, alpha: float = 0.0, beta: float = 0.0, perturb: dict | None = None,
              output_points=None, damping_tangent: str | None = None):
        """The equation of motion about the equilibrium ``at`` (default :meth:`equilibrium`)
        as a :class:`tmfem.models.base.Plant` (:class:`tmfem.models.fe.plant.FEPlant`):
        Rayleigh damping C = alpha M + beta K (``damping_tangent``), an initial ``perturb``
        by coordinate name and the monitored ``output_points`` (default
        ``system.monitor_points``)."""
        state, _ = self._at(at)
        return self.plant_type(self, state, alpha=alpha, beta=beta, perturb=perturb,
                               output_points=output_points, damping_tangent=damping_tangent)

    # ------------------------------------------------------------------ linearisation
    def linearize(self, *, at=None, modes: int | None = None, alpha: float = 0.0,
                  beta: float = 0.0, name: str | None = None):
        """The linearisation about the equilibrium ``at`` (eq. 5.33) as a python-control
        ``StateSpace`` with named states, inputs ``r_<tendon>`` and outputs [q, w_k].

        With the plant M a + C v + f_int(x; u) = 0 of :meth:`plant` (C = alpha M + beta K_0),
        K = K_0 its tangent and B_u = d f_int / d u (central differences of the residual in
        each rest length), the perturbations obey M dx'' + C dx' + K dx + B_u du = 0 and
        dy = C_y dx with C_y = dy/dx (central differences of the outputs).

        ``modes=None`` keeps every free dof: x = [dx, dx'], 2 n states ``dof_i``,
        ``dof_i_dot`` (dense: refused above :data:`MAX_FULL_LINEARIZATION` dofs).
        ``modes=k`` reduces to the k lowest modes Phi of (K, M) (M-orthonormal):
        x = [eta, eta'], A = [[0, I], [-Omega^2, -Phi^T C Phi]], B = [0; -Phi^T B_u],
        C = [C_y Phi, 0] -- exact for the retained modes, the static response of the others
        truncated (``eta_i``, ``eta_i_dot``).
        """
        import control
        import scipy.sparse as sp

        from tmfem.solvers.eigen import lowest_modes

        plant = self.plant(at=at, alpha=alpha, beta=beta)
        x0, u0 = plant.x0, plant.u0
        n, m = x0.size, u0.size
        zero = np.zeros(n)
        B_u = np.empty((n, m))
        for i in range(m):
            h = 1e-7 * max(1.0, abs(u0[i]))
            du = np.zeros(m)
            du[i] = h
            B_u[:, i] = (plant.residual(x0, zero, zero, 0.0, u0 + du)
                         - plant.residual(x0, zero, zero, 0.0, u0 - du)) / (2 * h)
        plant.residual(x0, zero, zero, 0.0, u0)          # back to the nominal inputs
        K, M = plant.K0, plant.M
        C = plant.C if plant.C is not None else sp.csc_matrix((n, n))
        if modes is None:
            if n > MAX_FULL_LINEARIZATION:
                raise ResourceLimit(f"linearize: the full linearisation has {2 * n:,} states "
                                    f"(dense); expected at most {2 * MAX_FULL_LINEARIZATION:,}: "
                                    f"use modes=k for the modal one")
            basis = np.eye(n)
            Md, Kd, Cd = (np.asarray(a.todense()) for a in (M, K, C))
            Minv = np.linalg.inv(Md)
            Arr, Arv, Bv = -Minv @ Kd, -Minv @ Cd, -Minv @ B_u
            names = [f"dof_{i + 1}" for i in range(n)]
        else:
            if not (isinstance(modes, int) and 1 <= modes < n):
                raise InputError(f"linearize: expected 1 <= modes < {n} (the free dofs), found "
                                 f"{modes!r}")
            Ks = (0.5 * (K + K.T)).tocsc()
            md = lowest_modes(Ks, M, k=modes, backend=self.backend)
            basis = md.shapes
            Arr = -np.diag(md.omega2)
            Arv = -basis.T @ (C @ basis)
            Bv = -basis.T @ B_u
            names = [f"eta_{i + 1}" for i in range(modes)]
        k = basis.shape[1]
        y0 = plant.outputs(x0)
        Cy = np.empty((y0.size, k))
        for j in range(k):
            d = basis[:, j]
            h = 1e-7 / max(np.max(np.abs(d)), 1e-300)
            Cy[:, j] = (plant.outputs(x0 + h * d) - plant.outputs(x0 - h * d)) / (2 * h)
        A = np.block([[np.zeros((k, k)), np.eye(k)], [Arr, Arv]])
        B = np.vstack([np.zeros((k, m)), Bv])
        Cfull = np.hstack([Cy, np.zeros((y0.size, k))])
        return control.ss(A, B, Cfull, np.zeros((y0.size, m)),
                          states=names + [s + "_dot" for s in names], inputs=plant.input_names,
                          outputs=plant.output_names, name=name or self.name)
