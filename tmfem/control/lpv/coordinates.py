"""The synthesis coordinates of a generalized LPV plant and the acceptance test of a design.

Each parameter enters normalised, rho_n = (rho - c) / h with c the centre and h the
half-width of its grid (the affine span of eq. 5.99), and the states are scaled by a diagonal
T (x = T x_s, :func:`~tmfem.control.lpv.generalized_plant.state_scaling`). A design found in
these coordinates (by the conic solvers, by eigenvalue optimisation or by the gamma
bisection) is accepted only after every LMI of eq. 5.95 is re-computed from it in floating
point (:func:`accepted_design`).
"""
from __future__ import annotations

import itertools
import logging
from dataclasses import dataclass

import numpy as np

from tmfem.control.lpv.generalized_plant import GeneralizedLPV, lmi_matrix, state_scaling
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.control.lpv.verify import verify
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


@dataclass
class Coordinates:
    """The synthesis coordinates of a generalised plant (module docstring): parameters
    normalised to [-1, 1] over the grid (``center``, ``half``; ``varying``: the parameters
    with more than one grid value), states x = T x_s, the rate vertices and the LMI sizes."""

    grid_shape: tuple
    T: np.ndarray
    center: np.ndarray
    half: np.ndarray
    varying: list
    verts: np.ndarray
    sizes: dict

    @classmethod
    def of(cls, gp: GeneralizedLPV, *, scale: bool = True) -> "Coordinates":
        shp = gp.grid_shape
        n, nw, nu, npp = (gp.sizes[k] for k in ("n_x", "n_w", "n_u", "n_p"))
        lo = np.array([a[0] for a in gp.axes])
        hi = np.array([a[-1] for a in gp.axes])
        varying = [k for k in range(len(shp)) if shp[k] > 1]
        verts = gp.rate_vertices()
        nvar = (1 + len(varying)) * (n * (n + 1) // 2 + nu * n) + 1
        sizes = {"grid_points": int(np.prod(shp)), "rate_vertices": len(verts),
                 "lmis": int(np.prod(shp)) * len(verts), "lmi_size": n + nw + npp, "n_x": n, "n_w": nw,
                 "n_u": nu, "n_p": npp, "decision_variables": nvar}
        return cls(grid_shape=shp, T=state_scaling(gp.A[tuple(s // 2 for s in shp)]) if scale else np.ones(n),
                   center=(lo + hi) / 2, half=np.where(hi > lo, (hi - lo) / 2, 1.0), varying=varying,
                   verts=verts, sizes=sizes)

    def c_of(self, rho) -> np.ndarray:
        """The coefficients [1, rho_n...] of P_k in P(rho) (eq. 5.99, normalised rho)."""
        return np.concatenate([[1.0], ((np.asarray(rho) - self.center) / self.half)[self.varying]])

    @property
    def dvs(self) -> list:
        """The coefficients of P_k in dP/dt at each rate vertex."""
        return [np.concatenate([[0.0], (v / self.half)[self.varying]]) for v in self.verts]

    def coefficients_of(self, design: LPVStateFeedback, gp: GeneralizedLPV):
        """P_k, Q_k of ``design`` in these scaled coordinates (P = T P_s T, Q = Q_s T) and
        normalised parameters: P(rho) is affine, so they are P at the centre and its change
        over each half-width (zero along a parameter the design does not vary)."""
        T = self.T
        if list(design.state_names) != list(gp.state_names):
            raise InputError("gamma bisection start: expected a design over the same states, found "
                             f"{len(design.state_names)} states against {len(gp.state_names)}")

        def at(rho):
            return design.P_of(rho) / T[:, None] / T[None, :], design.Q_of(rho) / T[None, :]
        P0, Q0 = at(self.center)
        Ps, Qs = [P0], [Q0]
        for k in self.varying:
            d = np.zeros_like(self.center)
            d[k] = self.half[k]
            P1, Q1 = at(self.center + d)
            Ps.append(P1 - P0)
            Qs.append(Q1 - Q0)
        return Ps, Qs

    def accepted(self, gp, Ps, Qs, gamma, *, solver, status, solve, build,
                 sample_time: float | None = None) -> "LPVStateFeedback":
        """:func:`accepted_design` (strictly negative LMIs) of P_k, Q_k given in the scaled coordinates;
        with ``sample_time`` also every frozen sampled loop of the grid stable
        (:func:`tmfem.control.lpv.verify.verify`)."""
        T = self.T
        ctrl = accepted_design(gp, [Tm_back(P, T) for P in Ps], [Q * T[None, :] for Q in Qs], gamma, T, self.verts,
                         self.center, self.half, self.varying, solver=solver, status=status, solve=solve,
                         build=build, sizes=self.sizes, tol=-1e-300)
        if sample_time is not None:
            r = verify(ctrl, gp, sample_time=sample_time, allow_failure=True).max_sampled_radius
            if not r < 1:
                raise InfeasibleController(f"the frozen loops sampled at {sample_time} s have spectral radius "
                                           f"{r:.6f} (expected < 1)")
        return ctrl


def accepted_design(gp, Pv, Qv, g, T, verts, center, half, varying, *, solver, status, solve, build,
                    sizes, tol) -> LPVStateFeedback:
    """The design of coefficients P_k = ``Pv``, Q_k = ``Qv`` (original coordinates) at level
    ``g``, after re-computing every LMI (eq. 5.95) and P(rho_i) from them in floating point
    (largest eigenvalue in the scaled coordinates <= ``tol``, P > 0) at every grid point of
    ``gp`` and rate vertex ``verts`` (``T``, ``center``, ``half``, ``varying``: the
    coordinates of :class:`Coordinates`); ``solver``, ``status``, ``solve``, ``build``,
    ``sizes``: the solve's record kept in the result.

    Raises
    ------
    InfeasibleController
        When an LMI or P fails.
    """
    Ti = 1.0 / T
    n, nw, npp = gp.sizes["n_x"], gp.sizes["n_w"], gp.sizes["n_p"]
    worst, minP = -np.inf, np.inf
    for idx in np.ndindex(*gp.grid_shape):
        rho = np.array([a[i] for a, i in zip(gp.axes, idx)])
        c = np.concatenate([[1.0], ((rho - center) / half)[varying]])
        P = sum(ck * Pk for ck, Pk in zip(c, Pv))
        Q = sum(ck * Qk for ck, Qk in zip(c, Qv))
        minP = min(minP, np.linalg.eigvalsh((P * Ti[:, None] * Ti[None, :])).min())
        for v in verts:
            dP = sum((v[k] / half[k]) * Pv[1 + j] for j, k in enumerate(varying)) if varying \
                else np.zeros((n, n))
            M = lmi_matrix(A=gp.A[idx], B1=gp.B1[idx], B2=gp.B2[idx], C1=gp.C1[idx],
                           D11=gp.D11[idx], D12=gp.D12[idx], P=P, Q=Q, dP=dP, gamma=g)
            worst = max(worst, _max_eig_congruent(M, T, nw + npp))
    if not (worst <= tol and minP > 0):
        raise InfeasibleController(f"the LMI re-computed from the solution has largest eigenvalue "
                                   f"{worst:.3e} (expected <= {tol:.3e}) and min eig P {minP:.3e} "
                                   "(expected > 0)")
    log.info("LPV synthesis: gamma = %.6g (%s, %s, %.1f s)", g, solver, status, solve)
    return LPVStateFeedback(gamma=g, P=Pv, Q=Qv, center=center, half_width=half, varying=varying,
                            axes=[a.copy() for a in gp.axes], parameter_names=list(gp.parameter_names),
                            rate_bounds=gp.rate_bounds.copy(), state_names=list(gp.state_names),
                            solver=solver, status=status, solve_time=solve, build_time=build,
                            sizes=sizes, max_lmi_eig=float(worst), min_P_eig=float(minP))


def design_points_in(axes, fine_axes, *, what: str) -> list:
    """The index tuples in the grid of ``fine_axes`` of every point of the grid of ``axes``
    (a design grid inside a finer one, e.g. its refinement).

    Raises
    ------
    InputError
        A design point that is not a point of the finer grid (``what`` names the caller).
    """
    out = []
    for rho in itertools.product(*axes):
        hit = [np.flatnonzero(np.isclose(a, r, rtol=0, atol=1e-12 * max(1.0, np.abs(a).max())))
               for a, r in zip(fine_axes, rho)]
        if any(h.size == 0 for h in hit):
            raise InputError(f"{what}: expected the fine grid to contain every design point, "
                             f"found none at rho = {list(rho)}")
        out.append(tuple(int(h[0]) for h in hit))
    return out


def Tm_back(Ps: np.ndarray, T: np.ndarray) -> np.ndarray:
    """P in original coordinates from the scaled one: x = T x_s  ->  P = T P_s T."""
    return T[:, None] * Ps * T[None, :]


def _max_eig_congruent(M: np.ndarray, T: np.ndarray, n_extra: int) -> float:
    """Largest eigenvalue of diag(T^-1, I) M diag(T^-1, I) (the LMI in the scaled
    coordinates, where the margin is imposed; the sign is that of M)."""
    d = np.concatenate([1.0 / T, np.ones(n_extra)])
    S = d[:, None] * M * d[None, :]
    return float(np.linalg.eigvalsh((S + S.T) / 2).max())
