"""A lower bound on the gamma of a gridded LPV state feedback (eqs. 5.95-5.96).

At a grid point, the LMIs of the two rate vertices +v and -v average to the zero-rate LMI
(the dP/dt term cancels), which is the bounded real lemma of the frozen (LTI) closed loop
with Lyapunov matrix P(rho_i) and gain Q(rho_i) P(rho_i)^-1. So every P(rho), Q(rho) that
meet the gridded LMIs at gamma make each frozen plant's state-feedback problem feasible at
gamma: gamma_LPV >= max_i gamma_SF(rho_i), the pointwise optimum of static state feedback,
computed here by :func:`tmfem.control.linear.hinf_riccati.state_feedback_gamma` (Riccati test; no SDP).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from tmfem.control.linear.hinf_riccati import state_feedback_gain, state_feedback_gamma
from tmfem.control.lpv.generalized_plant import GeneralizedLPV, state_scaling
from tmfem.control.lpv.plant import grid_point_text

log = logging.getLogger(__name__)


@dataclass
class PointwiseBound:
    """Pointwise state-feedback optima on the grid and their maximum (a lower bound of the
    LPV gamma) with the parameter values where it occurs; ``achieved_norm``: the closed-loop
    H-infinity norm (python-control ``norm``) of a static gain designed there at 1.01 x the
    bound (the bound is tight: achieved_norm in [bound, 1.01 bound])."""

    gamma: np.ndarray
    lower_bound: float
    at: list
    achieved_norm: float

    def to_dict(self) -> dict:
        return {"pointwise_gamma": self.gamma.tolist(), "lpv_gamma_lower_bound": self.lower_bound,
                "lpv_gamma_lower_bound_at": self.at,
                "lpv_gamma_lower_bound_achieved_norm": self.achieved_norm}


def scaled_point(gp: GeneralizedLPV, idx, T: np.ndarray) -> tuple:
    """(A, B1, B2, C1, D11, D12) of the grid point ``idx`` of ``gp`` in the scaled states x = T x_s."""
    Ti = 1.0 / T
    return (Ti[:, None] * gp.A[idx] * T[None, :], Ti[:, None] * gp.B1[idx], Ti[:, None] * gp.B2[idx],
            gp.C1[idx] * T[None, :], gp.D11[idx], gp.D12[idx])


def pointwise_state_feedback_bound(gp: GeneralizedLPV, *, eps: float = 1e-8,
                                   rtol: float = 1e-5) -> PointwiseBound:
    """gamma_SF at every grid point of ``gp`` (states scaled as in the synthesis, diagonal
    balancing of A at the grid centre; ``eps`` is the Riccati perturbation of
    :func:`~tmfem.control.linear.hinf_riccati.state_feedback_gamma` in those coordinates)."""
    import control
    shp = gp.grid_shape
    T = state_scaling(gp.A[tuple(s // 2 for s in shp)])
    g = np.zeros(shp)
    for idx in np.ndindex(*shp):
        g[idx] = state_feedback_gamma(*scaled_point(gp, idx, T), eps=eps, rtol=rtol)
    k = np.unravel_index(int(np.argmax(g)), shp)
    at = [float(a[i]) for a, i in zip(gp.axes, k)]
    A, B1, B2, C1, D11, D12 = scaled_point(gp, k, T)
    K = state_feedback_gain(A, B1, B2, C1, D11, D12, 1.01 * float(g[k]), eps=eps)
    Acl = A + B2 @ K
    if np.max(np.linalg.eigvals(Acl).real) >= 0:
        nrm = float("inf")
    else:
        nrm = float(control.norm(control.ss(Acl, B1, C1 + D12 @ K, D11), p="inf"))
    log.info("pointwise state-feedback gamma: max %.5g at %s (min %.5g); a gain at 1.01 x it: "
             "||T|| = %.5g", g.max(), grid_point_text(gp.parameter_names, at), g.min(), nrm)
    return PointwiseBound(gamma=g, lower_bound=float(g.max()), at=at, achieved_norm=nrm)
