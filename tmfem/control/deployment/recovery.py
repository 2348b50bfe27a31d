"""Stress recovery of a deployment run (dissertation 7.4), vectorised over recorded samples.

Tendons, at every sample: stress T / A with T = k (|d| - r) (eq. 3.8, the model's fixed
spring constants k).

Membrane and bars, at the samples of the output rate: the corner displacements Delta(q) of
eq. 3.5 (closed form, :func:`tmfem.equilibrium.general.corner_state`); the in-plane
membrane solution of the equilibrium design (linear plane-stress FE, eq. 5.8, point
attachment) is linear in Delta, so its stresses and corner forces are superposed from the
2N solutions for unit corner displacements (computed once):

    sigma(Delta) = sum_c Delta_c sigma^(c),    F(Delta) = sum_c Delta_c F^(c);

the maximum von Mises stress (eq. 5.30) is taken over all quadrature points, and the bar
compression from the equilibrium of each bar under the tendon and membrane-corner forces
(:func:`tmfem.equilibrium.design.bar_axial_loads`, against the Euler load of eq. 5.31).
"""
from __future__ import annotations

import numpy as np

from tmfem.equilibrium.design import bar_axial_loads, membrane_state
from tmfem.equilibrium.general import corner_state
from tmfem.errors import InputError
from tmfem.fem.plane_stress import von_mises


class StressRecovery:
    """Unit corner-displacement solutions of the membrane of ``system`` (module docstring).

    Parameters
    ----------
    system : System
    mesh_n : int
        Membrane mesh: N patches of mesh_n x mesh_n quads (7.4: 10; 20 for the 1-4(D)
        square of 7.4.1).
    """

    def __init__(self, system, *, mesh_n: int = 10):
        self.system = system
        N = system.N
        pm = membrane_state(system, system.q, mesh_n=mesh_n)[1]
        sig, F = [], []
        for c in range(2 * N):
            d = np.zeros((2, N))
            d.flat[c] = 1.0
            sol = pm.solve(d)
            sig.append(sol.sigma)
            F.append(sol.corner_forces)
        self._sigma = np.stack(sig, axis=-1)          # (3, n_el, n_qp, 2N)
        self._F = np.stack(F, axis=-1)                # (2, N, 2N)
        sections = [system.tendon_section(t) for t in system.tendons]
        self.area = np.array([s.area for s in sections])
        self.tendon_yield = np.array([np.nan if s.yield_stress is None else s.yield_stress
                                      for s in sections])
        self.critical_load = float(np.min(np.vectorize(system.bar.euler_critical_load)(system.l)))

    def membrane(self, delta) -> tuple[np.ndarray, np.ndarray]:
        """Maximum von Mises stress (n,) and corner forces on the membrane (n, 2, N) for
        in-plane corner displacements ``delta`` (n, 2, N)."""
        delta = np.asarray(delta, dtype=float)
        N = self.system.N
        if delta.ndim != 3 or delta.shape[1:] != (2, N):
            raise InputError(f"corner displacements: expected shape (n, 2, {N}), found {delta.shape}")
        D = delta.reshape(delta.shape[0], 2 * N)
        sig = np.einsum("aeqc,nc->naeq", self._sigma, D)
        vm = von_mises(np.moveaxis(sig, 1, 0)).reshape(D.shape[0], -1).max(axis=1)
        return vm, np.einsum("aic,nc->nai", self._F, D)

    def tendon_stress(self, k, lengths, rest_lengths) -> np.ndarray:
        """T / A (n, n_t) with T = k (|d| - r) (eq. 3.8)."""
        return k * (np.asarray(lengths) - np.asarray(rest_lengths)) / self.area

    def failed_checks(self, *, t, tendon_stress, bar_t, bar_compression, von_mises) -> list[str]:
        """The strength checks that a run fails, one line each: the largest stress of each
        tendon against its yield stress (section 6.2; tendons without one are not checked),
        the peak bar compression against the Euler load (eq. 5.31) and the largest membrane
        von Mises stress against the membrane's yield stress (eq. 5.30).

        Parameters
        ----------
        t, tendon_stress : (n,), (n, n_t)
            Sample times [s] and tendon stresses [Pa] (:meth:`tendon_stress`).
        bar_t, bar_compression, von_mises : (m,), (m,), (m,)
            Times [s], peak bar compression [N] and membrane von Mises stress [Pa] of
            :meth:`bars_and_membrane`.
        """
        failed = []
        ratio = np.where(np.isfinite(self.tendon_yield), tendon_stress / self.tendon_yield, -np.inf)
        if ratio.size and np.max(ratio) > 1:
            i, k = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
            failed.append(f"tendon yield: {self.system.tendons[k].name} at {tendon_stress[i, k] / 1e6:.4g} MPa "
                          f"(t = {t[i]:.4g} s) above its yield stress {self.tendon_yield[k] / 1e6:.4g} MPa")
        if bar_compression.size and np.max(bar_compression) > self.critical_load:
            i = int(np.argmax(bar_compression))
            failed.append(f"bar buckling: compression {bar_compression[i]:.4g} N (t = {bar_t[i]:.4g} s) "
                          f"above the Euler load {self.critical_load:.4g} N (eq. 5.31)")
        sy = self.system.membrane.yield_stress
        if sy is not None and von_mises.size and np.max(von_mises) > sy:
            i = int(np.argmax(von_mises))
            failed.append(f"membrane yield: von Mises {von_mises[i] / 1e6:.4g} MPa (t = {bar_t[i]:.4g} s) "
                          f"above the yield stress {sy / 1e6:.4g} MPa (eq. 5.30)")
        return failed

    def bars_and_membrane(self, q, tendon_forces) -> tuple[np.ndarray, np.ndarray]:
        """Peak bar compression (n,) [N] and maximum membrane von Mises stress (n,) [Pa] at
        the configurations q (n, n_q) with tendon forces (n, n_t)."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        states = [corner_state(self.system, qk) for qk in q]
        vm, F = self.membrane(np.array([s.delta[:2] for s in states]))
        bar = np.empty(q.shape[0])
        for k, (qk, st) in enumerate(zip(q, states)):
            F3 = np.vstack([F[k], np.zeros((1, self.system.N))])
            bar[k] = np.max(bar_axial_loads(self.system, qk, tendon_forces[k], -(st.R @ F3)))
        return bar, vm
