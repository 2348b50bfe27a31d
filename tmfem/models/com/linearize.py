"""Linearisation of the control-oriented model about an equilibrium (eq. 5.33).

With r(z, z', z'', u) = M_hat z'' + F_hat + B_hat u (eq. 5.27) and an equilibrium
(z_e, u_e) (F_hat(z_e, 0) + B_hat(z_e) u_e = 0), the perturbations x_z = [dz; dz'] obey

    x_z' = A x_z + B du,   A = [[0, I], [-M^-1 K, -M^-1 C]],   B = [[0], [-M^-1 B_hat]],

with K = dr/dz (total derivative, through zeta(q)), C = dr/dz', M = M_hat, all by casadi AD.
Outputs: the bar coordinates q and the transverse deflections w at the output points.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError
from tmfem.models.base import LinearPlant
from tmfem.solvers.eigen import Modes


@dataclass
class Linearization:
    """Second-order matrices at an equilibrium and the first-order (A, B, C, D) of eq. 5.33."""

    z_e: np.ndarray
    u_e: np.ndarray
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    B_hat: np.ndarray
    A: np.ndarray
    B: np.ndarray
    Cy: np.ndarray
    D: np.ndarray
    y_e: np.ndarray
    state_names: list
    input_names: list
    output_names: list

    def frequencies_hz(self) -> np.ndarray:
        """Undamped natural frequencies sqrt(eig(M^-1 K)) / 2 pi, ascending."""
        return self.modes().freq_hz

    def modes(self, k: int | None = None) -> Modes:
        """The ``k`` lowest (default all) undamped modes of K v = omega^2 M v (eq. 5.32 in
        the COM's coordinates), ascending in omega^2 (real parts; negative: unstable),
        shapes M-normalised (v^T M v = 1)."""
        import scipy.linalg as sla
        lam, V = sla.eig(self.K, self.M)
        order = np.argsort(lam.real)
        lam, V = lam.real[order][:k], V.real[:, order][:, :k]
        V = V / np.sqrt(np.einsum("ik,ij,jk->k", V, self.M, V))
        omega = np.sign(lam) * np.sqrt(np.abs(lam))
        return Modes(omega2=lam, omega=omega, freq_hz=omega / (2 * np.pi), shapes=V)

    def plant(self, *, x0=None, v0=None):
        """The linearised model as a simulation plant (:class:`tmfem.models.base.LinearPlant`)
        in the same coordinates: M a + C v + K (z - z_e) + B_hat (u - u_e) = 0."""
        return LinearPlant(M=self.M, C=self.C, K=self.K, B=self.B_hat, Cy=self.Cy, x_e=self.z_e,
                           u_e=self.u_e, y_e=self.y_e, input_names=self.input_names,
                           output_names=self.output_names, x0=x0, v0=v0)

    def to_ss(self, name: str = "com"):
        """python-control ``StateSpace`` with named states, inputs and outputs."""
        import control
        return control.ss(self.A, self.B, self.Cy, self.D, states=self.state_names,
                          inputs=self.input_names, outputs=self.output_names, name=name)


def linearize(model, *, z_e=None, u_e=None, find_equilibrium: bool = True) -> Linearization:
    """Linearise ``model`` (ControlOrientedModel) about an equilibrium (eq. 5.33).

    Parameters
    ----------
    z_e : array, optional
        Configuration; default: the model's equilibrium for ``u_e`` found by Newton from
        the design (``find_equilibrium=True``) or the design itself.
    u_e : array, optional
        Rest lengths; default the model's nominal ``u0``.
    """
    u_e = model.u0 if u_e is None else np.asarray(u_e, dtype=float)
    if u_e.shape != (model.n_t,):
        raise InputError(f"rest lengths: expected {model.n_t} values, found shape {u_e.shape}")
    if z_e is None:
        z_e = model.equilibrium(u_e).state if find_equilibrium else model.z0
    z_e = np.asarray(z_e, dtype=float)
    n = model.nz
    zero = np.zeros(n)
    K, C, M = model.jacobians(z_e, zero, zero, 0.0, u_e)
    Bh = model.input_matrix(z_e)
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    B = np.vstack([np.zeros((n, model.n_t)), -Minv @ Bh])
    Cy = np.hstack([output_jacobian(model, z_e), np.zeros((model.nq + len(model.output_points), n))])
    D = np.zeros((Cy.shape[0], model.n_t))
    return Linearization(z_e=z_e, u_e=u_e, M=M, C=C, K=K, B_hat=Bh, A=A, B=B, Cy=Cy, D=D,
                         y_e=model.outputs(z_e), state_names=model.state_names,
                         input_names=model.input_names, output_names=model.output_names)


def output_jacobian(model, z) -> np.ndarray:
    """d y / d z for y = [q, w(points)] (w depends on Delta(q) and eta, eq. 5.1)."""
    nq, nd = model.nq, model.layout.n_delta
    zm = model.P @ np.asarray(z, dtype=float)
    zeta = model.zeta(zm[:nq])
    dzq = model.constraints.dzeta_dq(zm[:nq], zeta)[:nd]          # eq. 5.23
    W = model.W_out
    Jw = np.hstack([W[:, 1:1 + nd] @ dzq, W[:, 1 + nd:]]) @ model.P
    return np.vstack([np.eye(nq, model.nz), Jw])
