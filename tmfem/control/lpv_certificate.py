"""Rate-bounded certificate of the output-feedback LPV loop (:mod:`tmfem.control.lpv_output`):
an analysis LMI with a parameter-dependent Lyapunov matrix (docs/lpv.md).

The loop of plant, integrators and gridded estimator (states [x_z, xi, e], w = [q_d, n_d, n],
p = [W_e e_q, W_u u]; :meth:`~tmfem.control.lpv_output.LPVOutputFeedback.frozen_closed_loop`)

    x' = A(rho) x + B(rho) w,    p = C(rho) x + D(rho) w

is stable with ||p||_2 < gamma ||w||_2 for every parameter trajectory in the grid's box with
rates in the rate box when there is X(rho) = X_0 + sum_k rho_k X_k > 0 (normalised rho, the
span of eq. 5.99) with, at every rate vertex,

    [[A^T X + X A + dX/dt, X B, C^T], [B^T X, -gamma I, D^T], [C, D, -gamma I]] < 0

(bounded real lemma with V = x^T X(rho) x: dV/dt + |p|^2 / gamma - gamma |w|^2 < 0). Gridded:
imposed at the grid points and re-checked on a finer grid, as the state-feedback LMI of 8.3.
It is the LMI of eq. 5.95 for the transposed system (A^T, C^T, B^T, D^T) without a control
input, with P(rho) = X(rho) and the rate box negated (-dP/dt there is +dX/dt here; the block
permutation that swaps the w and p rows is a congruence): so the EIGOPT bisection of
:mod:`tmfem.control.lpv_bisect` solves it, from the pointwise bounded-real Riccati solutions
of the frozen loops. Its proven lower bound is the largest frozen-loop H-infinity norm of the
design grid (a constant rho is an admissible trajectory).

Not covered: the estimator's state is the absolute x^ and the law reads x^ - x_e(rho), so a
moving rho adds dx_e/dt terms that this (as every linearised LPV analysis) leaves out; the
sampled loops are checked frozen only (:func:`~tmfem.control.lpv_output.verify_output_feedback`).
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from tmfem.control.lpv_plant import GriddedLPV
from tmfem.control.lpv_synthesis import GeneralisedLPV, LPVStateFeedback
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


def transposed_loop(design, plant: GriddedLPV, *, W_e: float, W_u: float) -> GeneralisedLPV:
    """The frozen closed loops of ``design`` with the plants of ``plant``'s grid (its A, B and
    measured C_m; the controller interpolated there), transposed and without control input:
    the generalised plant whose eq. 5.95 is the analysis LMI of the module docstring."""
    from tmfem.control.lpv_output import _measurement
    C, _ = _measurement(plant, design.measured)
    loops = [design.frozen_closed_loop(plant.A[idx], plant.B[idx], C[idx], rho, W_e=W_e, W_u=W_u)
             for idx, rho in plant.points()]
    shp = plant.grid_shape
    A, B1, C1, D11 = (np.array([lp[k].T for lp in loops]).reshape(shp + loops[0][k].T.shape) for k in (0, 2, 1, 3))
    n = A.shape[-1]
    rb = np.asarray(plant.rate_bounds, dtype=float)
    gp = GeneralisedLPV.from_matrices(axes=plant.axes, parameter_names=plant.parameter_names,
                                      rate_bounds=-rb[:, ::-1], A=A, B1=B1, B2=np.zeros(shp + (n, 0)), C1=C1,
                                      D11=D11, D12=np.zeros(shp + (C1.shape[-2], 0)))
    gp.state_names = (list(plant.state_names) + [f"int_e_{design.measured[i]}" for i in design.tracked_rows]
                      + [f"est_{s}" for s in plant.state_names])
    return gp


@dataclass
class RateBoundedCertificate:
    """Result of :func:`rate_bounded_certificate`. ``lyapunov``: X(rho) as the P(rho) of an
    :class:`~tmfem.control.lpv_synthesis.LPVStateFeedback` (no gain: Q has no rows), None when
    no level was found; ``gamma``: its certified L2-gain bound; ``lower_bound``: the largest
    frozen-loop norm of the design grid (proven: no certificate below it); ``bracket``: the
    :class:`~tmfem.control.lpv_bisect.GammaBracket`, or None; ``message``: why none was found."""

    lyapunov: LPVStateFeedback | None
    gamma: float | None
    lower_bound: float
    lower_bound_at: list
    bracket: object
    time_s: float
    message: str = ""

    @property
    def found(self) -> bool:
        return self.lyapunov is not None

    def to_dict(self) -> dict:
        d = {"rate_bounded_certificate": self.found, "rate_bounded_gamma": self.gamma,
             "rate_bounded_frozen_norm_max": self.lower_bound, "rate_bounded_frozen_norm_max_at": self.lower_bound_at,
             "rate_bounded_time_s": self.time_s, "rate_bounded_message": self.message}
        if self.bracket is not None:
            d["rate_bounded_levels"] = self.bracket.levels
        return d


def rate_bounded_certificate(design, plant: GriddedLPV, *, W_e: float, W_u: float, upper: float | None = None,
                             rtol: float = 0.05, time_budget: float = 300.0, max_iter: int = 150,
                             progress=None) -> RateBoundedCertificate:
    """X(rho) and the lowest gamma found for the analysis LMI of the module docstring on the
    design grid of ``plant`` (the plants ``design`` was made for), by the EIGOPT bisection
    between the largest frozen norm and ``upper`` (default 2 x it).

    Returns a certificate with ``found`` False (and the reason) when no point is found at the
    upper level within the budget: that proves nothing either way (EIGOPT is local).

    Raises
    ------
    InfeasibleController
        When a frozen loop of the design grid is unstable (no certificate can exist).
    """
    import control

    from tmfem.control.lpv_bisect import bisect_gamma
    if upper is not None and not (np.isfinite(upper) and upper > 0):
        raise InputError(f"rate-bounded certificate: expected an upper level > 0, found {upper!r}")
    t0 = time.perf_counter()
    gp = transposed_loop(design, plant, W_e=W_e, W_u=W_u)
    lo, lo_at = -np.inf, None
    for idx in np.ndindex(*gp.grid_shape):
        A = gp.A[idx]
        if np.linalg.eigvals(A).real.max() >= 0:
            rho = [a[i] for a, i in zip(gp.axes, idx)]
            raise InfeasibleController(f"rate-bounded certificate: the frozen output-feedback loop at rho = "
                                       f"{rho} is unstable (expected stable at every design point)")
        nrm = float(control.norm(control.ss(A, gp.B1[idx], gp.C1[idx], gp.D11[idx]), p="inf"))
        if nrm > lo:
            lo, lo_at = nrm, [float(a[i]) for a, i in zip(gp.axes, idx)]
    hi = 2.0 * lo if upper is None else upper
    if not hi > lo:
        raise InputError(f"rate-bounded certificate: expected an upper level above the largest frozen norm "
                         f"{lo:.6g} (no certificate below it), found {hi!r}")
    log.info("rate-bounded certificate: %d-state loops on %s, frozen norms up to %.6g at %s; levels (%.6g, %.6g]",
             gp.A.shape[-1], gp.grid_shape, lo, lo_at, lo, hi)
    try:
        X, br = bisect_gamma(gp, lower=lo, upper=hi, rtol=rtol, time_budget=time_budget, max_iter=max_iter,
                             progress=progress)
    except InfeasibleController as exc:
        return RateBoundedCertificate(lyapunov=None, gamma=None, lower_bound=lo, lower_bound_at=lo_at,
                                      bracket=None, time_s=time.perf_counter() - t0, message=str(exc))
    return RateBoundedCertificate(lyapunov=X, gamma=X.gamma, lower_bound=lo, lower_bound_at=lo_at, bracket=br,
                                  time_s=time.perf_counter() - t0, message=X.status)
