"""The EIGOPT route of :func:`tmfem.control.lpv.lpvsyn`: gridded state feedback with the affine
basis of eq. 5.99 by the gamma bisection over eigenvalue-optimisation levels.

The interior-point SDP of the general route keeps a dense Nesterov-Todd block per cone and
grows as the fourth power of the LMI order (:mod:`tmfem.control.lpv.cost`): on the 2-3 plant
of ch. 8 (71 states) it would need about 1650 GiB. The LMIs of eqs. 5.95-5.96 with P(rho),
Q(rho) affine in the normalised parameters (eq. 5.99) are solved instead at fixed levels of
gamma by :class:`~tmfem.control.lpv.eigopt.EigOpt` (a smoothed maximum eigenvalue minimised
by L-BFGS, memory linear in the number of LMI entries) and gamma is bisected between the
pointwise state-feedback lower bound and the lowest level where a point is found
(:func:`~tmfem.control.lpv.bisect.bisect_gamma`). This is the route of ``tmfem control lpv``
and of the LPV deployment of 8.4.

Structure it supports: state feedback (``nmeas = 0``), the affine basis for both the Lyapunov
matrix and the gain (eq. 5.99; on a grid where no parameter varies it is the constant basis),
finite rate bounds. The design it returns, K(rho) = Q(rho) P(rho)^-1, is re-expressed as the
general route's :class:`~tmfem.control.lpv.gridded_synthesis.Certificate` (the affine basis
with an identity change of basis, the synthesis's state scaling) and verified off the grid by the same
:func:`~tmfem.control.lpv.gridded_synthesis.verify_design`.
"""
from __future__ import annotations

import time

import numpy as np

from tmfem.control.lpv.basis import Basis
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.plant import grid_point_text
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.errors import InputError


def unsupported(*, nmeas: int, lyap: Basis, gain: Basis, affine: Basis, points: np.ndarray, rb: np.ndarray) -> str:
    """Why the EIGOPT route cannot carry a problem ('' when it can): output feedback, a basis
    other than the affine one of eq. 5.99 (compared by its values at ``points``), unbounded
    rates."""
    if nmeas:
        return f"it is a state-feedback route (eq. 5.99), found output feedback with nmeas = {nmeas}"
    ref = affine.values(points)
    for what, b in (("basis", lyap), ("gain_basis", gain)):
        v = b.values(points)
        if v.shape != ref.shape or not np.allclose(v, ref, rtol=1e-12, atol=1e-12):
            return (f"it uses the affine basis {list(affine.names)} of eq. 5.99, found {what} "
                    f"{list(b.names)}")
    if not np.all(np.isfinite(rb)):
        return f"it needs finite rate bounds, found {rb.tolist()}"
    return ""


def generalized_on_grid(P, plant, *, axes, rb: np.ndarray, ncon: int) -> GeneralizedLPV:
    """The plant as a :class:`GeneralizedLPV` on the design grid with the rate box ``rb``: ``P``
    itself when it is one on these axes, else ``plant`` (a
    :class:`~tmfem.control.lpv.gridded_plant.PlantFunction`) evaluated at every grid point."""
    if isinstance(P, GeneralizedLPV) and len(P.axes) == len(axes) and all(
            np.array_equal(np.asarray(a, dtype=float), b) for a, b in zip(P.axes, axes)):
        return GeneralizedLPV(axes=P.axes, parameter_names=P.parameter_names, rate_bounds=rb, A=P.A, B1=P.B1,
                              B2=P.B2, C1=P.C1, D11=P.D11, D12=P.D12, state_names=P.state_names)
    shp = tuple(a.size for a in axes)
    mats = [plant.at([a[i] for a, i in zip(axes, idx)]) for idx in np.ndindex(*shp)]
    A, B, C, D = (np.stack([m[k] for m in mats]).reshape(shp + mats[0][k].shape) for k in range(4))
    nw = B.shape[-1] - ncon
    return GeneralizedLPV(axes=list(axes), parameter_names=[f"rho{k}" for k in range(len(axes))], rate_bounds=rb,
                          A=A, B1=B[..., :nw], B2=B[..., nw:], C1=C, D11=D[..., :nw], D12=D[..., nw:],
                          state_names=[f"x{i}" for i in range(A.shape[-1])])


def scaling(gp: GeneralizedLPV, *, scale: bool) -> np.ndarray:
    """The diagonal state scaling T (x = T x_s) of the EIGOPT synthesis of ``gp``
    (:class:`~tmfem.control.lpv.coordinates.Coordinates`), in which the certificate is
    stored and verified (ones without ``scale``)."""
    from tmfem.control.lpv.coordinates import Coordinates
    return Coordinates.of(gp, scale=scale).T


def synthesize_eigopt(gp: GeneralizedLPV, *, gamma: float | None, fixed_gamma: bool, rtol: float,
                      time_budget: float, start: LPVStateFeedback | None, max_iter: int | None,
                      sample_time: float | None, bound=None, progress=None) -> tuple[LPVStateFeedback, dict]:
    """K(rho) of eqs. 5.95-5.99 on ``gp`` by EIGOPT and its record.

    Without ``fixed_gamma``: the bisection (:func:`~tmfem.control.lpv.bisect.bisect_gamma`)
    between the pointwise lower bound and ``gamma`` (default twice the bound) to relative width
    ``rtol`` within ``time_budget`` s, from ``start`` when given. With ``fixed_gamma``: one
    feasible point at ``gamma``
    (:func:`~tmfem.control.lpv.synthesis.synthesize_state_feedback`). ``sample_time``: the
    frozen loops sampled with a zero-order hold at that step also stable. ``bound``: the
    pointwise lower bound of ``gp`` when already computed
    (:func:`~tmfem.control.lpv.bounds.pointwise_state_feedback_bound`).

    Returns
    -------
    (LPVStateFeedback, dict)
        The design and its record (the lower bound, the bisection's levels and bracket).

    Raises
    ------
    InputError
        An upper level not above the pointwise lower bound; ``fixed_gamma`` without ``gamma``.
    InfeasibleController
        No point found (the message holds the pointwise lower bound).
    """
    from tmfem.control.lpv.bisect import bisect_gamma
    from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
    from tmfem.control.lpv.synthesis import synthesize_state_feedback
    from tmfem.errors import InfeasibleController
    bound = pointwise_state_feedback_bound(gp) if bound is None else bound
    record = {"pointwise_lower_bound": bound.lower_bound, "pointwise_lower_bound_at": bound.at}
    try:
        if fixed_gamma:
            if gamma is None:
                raise InputError("LPV synthesis (EIGOPT route): fixed_gamma needs the level gamma, found none")
            ctrl = synthesize_state_feedback(gp, solver="EIGOPT", max_iter=max_iter, gamma=gamma,
                                             sample_time=sample_time)
            return ctrl, record
        upper = gamma if gamma is not None else 2.0 * bound.lower_bound
        if upper <= bound.lower_bound:
            raise InputError(f"gamma {upper:g}: expected an upper level above the pointwise lower "
                             f"bound {bound.lower_bound:.5g} (no controller below it)")
        t0 = time.perf_counter()
        ctrl, br = bisect_gamma(gp, lower=bound.lower_bound, upper=upper, rtol=rtol, time_budget=time_budget,
                                max_iter=max_iter or 150, sample_time=sample_time, start=start,
                                progress=None if progress is None else
                                (lambda w: progress(min(time.perf_counter() - t0, time_budget))))
    except InfeasibleController as exc:
        at = grid_point_text(gp.parameter_names, bound.at)
        raise InfeasibleController(f"{exc} (pointwise state-feedback lower bound of gamma: "
                                   f"{bound.lower_bound:.4g} at {at})") from None
    return ctrl, {**record, **br.to_dict()}
