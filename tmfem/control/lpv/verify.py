"""Verification of a gridded LPV state feedback between the design grid points (8.3).

The gridded LMI of eqs. 5.95-5.96 guarantees nothing between grid points. :func:`verify`
re-evaluates, on a (finer) grid of generalised plants, the LMI with the synthesised
P(rho), Q(rho) and gamma at every rate vertex, and the frozen-parameter closed loop
A(rho) + B2(rho) K(rho) (K = Q P^-1), and reports the worst values and where they occur.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from tmfem.control.lpv.eigopt import zoh
from tmfem.control.lpv.generalized_plant import GeneralizedLPV, lmi_matrix
from tmfem.control.lpv.plant import grid_point_text
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.errors import InfeasibleController

log = logging.getLogger(__name__)


@dataclass
class Verification:
    """Worst LMI eigenvalue (eq. 5.95; < 0 holds) and worst closed-loop eigenvalue real part
    (< 0 stable) over the verification grid, with the parameter values where they occur."""

    grid: tuple
    max_lmi_eig: float
    max_lmi_eig_at: list
    max_cl_real: float
    max_cl_real_at: list
    passed: bool
    sample_time: float | None = None
    max_sampled_radius: float | None = None
    max_sampled_radius_at: list | None = None

    def to_dict(self) -> dict:
        return {"verification_grid": list(self.grid), "verification_max_eig": self.max_lmi_eig,
                "verification_max_eig_at": self.max_lmi_eig_at,
                "closed_loop_max_real": self.max_cl_real, "closed_loop_max_real_at": self.max_cl_real_at,
                "sample_time_s": self.sample_time, "sampled_max_radius": self.max_sampled_radius,
                "sampled_max_radius_at": self.max_sampled_radius_at, "passed": self.passed}


@dataclass
class PointwiseChecks:
    """The checks of :func:`verify` at every point of a grid (arrays of the grid's shape):
    ``lmi`` the largest relative eigenvalue of eq. 5.95 over the rate vertices, ``closed_loop``
    the largest real part of the frozen closed loop, ``sampled`` the spectral radius of the
    frozen loop sampled with a zero-order hold (None without a sample time)."""

    lmi: np.ndarray
    closed_loop: np.ndarray
    sampled: np.ndarray | None = None

    def failing(self) -> np.ndarray:
        """Boolean array: the points where a check fails (LMI eigenvalue >= 0, closed-loop real
        part >= 0, sampled spectral radius >= 1)."""
        bad = (self.lmi >= 0) | (self.closed_loop >= 0)
        return bad if self.sampled is None else bad | (self.sampled >= 1)


def pointwise_checks(controller: LPVStateFeedback, gp: GeneralizedLPV, *,
                     sample_time: float | None = None) -> PointwiseChecks:
    """:class:`PointwiseChecks` of ``controller`` on every point of ``gp``: the LMI of eq. 5.95
    with the synthesised P(rho), Q(rho) and gamma at every rate vertex (divided by the
    matrix's largest |entry|: a scale-free sign test), the frozen closed loop A(rho) + B2(rho)
    K(rho), and with ``sample_time`` that loop sampled with a zero-order hold
    (:func:`tmfem.control.lpv.eigopt.zoh`)."""
    verts = gp.rate_vertices()
    lmi, cl = np.full(gp.grid_shape, -np.inf), np.full(gp.grid_shape, -np.inf)
    sr = None if sample_time is None else np.full(gp.grid_shape, -np.inf)
    for idx in np.ndindex(*gp.grid_shape):
        rho = np.array([a[i] for a, i in zip(gp.axes, idx)])
        P, Q = controller.P_of(rho), controller.Q_of(rho)
        K = controller.gain(rho)
        cl[idx] = np.linalg.eigvals(gp.A[idx] + gp.B2[idx] @ K).real.max()
        if sample_time is not None:
            Ad, Bd = (X[0] for X in zoh(gp.A[idx][None], gp.B2[idx][None], sample_time))
            sr[idx] = np.abs(np.linalg.eigvals(Ad + Bd @ K)).max()
        for v in verts:
            dP = sum((v[k] / controller.half_width[k]) * controller.P[1 + j]
                     for j, k in enumerate(controller.varying)) if controller.varying else 0.0 * P
            M = lmi_matrix(A=gp.A[idx], B1=gp.B1[idx], B2=gp.B2[idx], C1=gp.C1[idx], D11=gp.D11[idx],
                           D12=gp.D12[idx], P=P, Q=Q, dP=dP, gamma=controller.gamma)
            lmi[idx] = max(lmi[idx], float(np.linalg.eigvalsh((M + M.T) / 2).max() / np.abs(M).max()))
    return PointwiseChecks(lmi=lmi, closed_loop=cl, sampled=sr)


def _worst(values: np.ndarray, gp: GeneralizedLPV) -> tuple[float, list]:
    """The largest entry of a grid array and the parameter values where it occurs."""
    idx = np.unravel_index(int(np.argmax(values)), values.shape)
    return float(values[idx]), [float(a[i]) for a, i in zip(gp.axes, idx)]


def verify(controller: LPVStateFeedback, gp: GeneralizedLPV, *, allow_failure: bool = False,
           sample_time: float | None = None) -> Verification:
    """Check ``controller`` on every point of ``gp`` (e.g. a grid 4x finer than the design's);
    with ``sample_time`` also the frozen loops sampled with a zero-order hold at that step
    (spectral radius of A_d + B_d K < 1, :func:`tmfem.control.lpv.eigopt.zoh`).

    The LMI eigenvalue reported is that of the matrix of eq. 5.95 divided by its largest
    |entry| (a scale-free sign test).

    Raises
    ------
    InfeasibleController
        Where the LMI does not hold (largest eigenvalue >= 0) or a frozen closed loop is
        not stable, unless ``allow_failure`` (then ``passed`` is False).
    """
    c = pointwise_checks(controller, gp, sample_time=sample_time)
    (worst, worst_at), (cl, cl_at) = _worst(c.lmi, gp), _worst(c.closed_loop, gp)
    sr, sr_at = _worst(c.sampled, gp) if c.sampled is not None else (-np.inf, None)
    sampled = sample_time is not None
    ok = not bool(c.failing().any())
    res = Verification(grid=gp.grid_shape, max_lmi_eig=worst, max_lmi_eig_at=worst_at, max_cl_real=cl,
                       max_cl_real_at=cl_at, passed=ok, sample_time=sample_time,
                       max_sampled_radius=sr if sampled else None, max_sampled_radius_at=sr_at)
    at = lambda rho: grid_point_text(gp.parameter_names, rho)          # noqa: E731
    log.info("LPV verification on %s: max LMI eig %.3e at %s, max closed-loop Re %.3e at %s%s",
             gp.grid_shape, worst, at(worst_at), cl, at(cl_at),
             f", sampled at {sample_time} s: max spectral radius {sr:.6f} at {at(sr_at)}" if sampled else "")
    if not ok and not allow_failure:
        raise InfeasibleController(
            f"LPV controller fails its verification on a {gp.grid_shape} grid: largest LMI "
            f"eigenvalue (eq. 5.95, relative) {worst:.3e} at {at(worst_at)} and largest closed-loop "
            f"real part {cl:.3e} at {at(cl_at)}; expected both < 0"
            + ("; the gridded LMI of eqs. 5.95-5.96 is imposed at the design points only: a design grid "
               "with points between them, or a level gamma above the bisection's end, leaves room "
               "between them" if worst >= 0 else "")
            + (f"; sampled at {sample_time} s the largest spectral radius is {sr:.6f} at {at(sr_at)} "
               "(expected < 1" + ("; a design with the sampled-loop LMI at this step, the synthesis' "
                                  "sample time, bounds it)" if sr >= 1 else ")") if sampled else ""))
    return res
