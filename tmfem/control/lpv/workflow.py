"""The LPV design workflow of 8.3 as library functions: the gridded plant and its
interconnection, the controller, its verification on a finer grid and the observer-based
output feedback.

``tmfem control lpv`` and ``tmfem deploy --controller lpv|lpv-output`` call these functions
with the options they parse; a Python user calls them directly::

    from tmfem.control.lpv import design_plant, synthesize_design, refined_plant, verify_design
    p = design_plant(system, theta=theta, psi=psi, bases=bases, rate_bound=np.radians(10))
    ctrl, info = synthesize_design(p.generalized, bound=p.bound, solver="EIGOPT")
    fine = refined_plant(system, p.plant, factor=4, bases=bases)
    v = verify_design(ctrl, fine, tracked=system.q_names)

``progress`` (every function that loops long): a factory ``progress(total, label)`` of a
context manager that yields an ``update(k, n)`` callback (the CLI's progress bars); default
none.
"""
from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from tmfem.control.lpv.bounds import PointwiseBound, pointwise_state_feedback_bound
from tmfem.control.lpv.certificate import rate_bounded_certificate, refine_certificate
from tmfem.control.lpv.defaults import (CERTIFICATE_PER_ROUND, DESIGN_PER_ROUND, DESIGN_ROUNDS, GAMMA_RTOL,
                                        TIME_BUDGET, W_E, W_U)
from tmfem.control.lpv.generalized_plant import GeneralizedLPV, interconnection_8_1
from tmfem.control.lpv.gridded_synthesis import lpvsyn
from tmfem.control.lpv.output_feedback import (LPVOutputFeedback, design_output_feedback,
                                               verify_output_feedback)
from tmfem.control.lpv.plant import GriddedLPV, com_lpv_plant, grid_point_text, scheduling_parameters
from tmfem.control.lpv.refinement import refine_state_feedback
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.control.lpv.verify import Verification, verify
from tmfem.errors import InfeasibleController, InputError


@contextmanager
def no_progress(total, label):
    """The default ``progress`` factory: reports nothing."""
    yield lambda k, n: None


@dataclass
class DesignPlant:
    """The gridded COM plant of a design (:func:`~tmfem.control.lpv.plant.com_lpv_plant`),
    its interconnection of Figure 8.1 (eq. 5.98) and the pointwise lower bound of gamma."""

    plant: GriddedLPV
    generalized: GeneralizedLPV
    bound: PointwiseBound


def design_plant(system, *, theta, psi, bases, rate_bound: float, progress=no_progress) -> DesignPlant:
    """The gridded design plant of ``system`` and its interconnection of Figure 8.1.

    The COM is linearised at the symmetric equilibria of eq. 5.97 at every grid point
    (:func:`~tmfem.control.lpv.plant.com_lpv_plant`); the interconnection (eq. 5.98) tracks
    the system's q; the pointwise state-feedback optimum of every frozen plant gives the lower
    bound of gamma (:func:`~tmfem.control.lpv.bounds.pointwise_state_feedback_bound`).

    Parameters
    ----------
    system : System
        A symmetric M >= 2 system (rho = theta_1N, psi_1N).
    theta, psi : array_like
        The grid axes [rad].
    bases : callable
        ``bases(theta, psi) -> {"r", "z", "sigma"}`` of the stage bases along the grid, e.g.
        :func:`tmfem.reference.deployments.lpv_bases` (the file's ``[lpv] path``: the Table 7.7
        rule or the automatic deployment path).
    rate_bound : float
        |d rho_k / dt| <= ``rate_bound`` [rad/s] for both parameters.
    progress : callable, optional
        The progress factory (module docstring).

    Returns
    -------
    DesignPlant
    """
    theta, psi = np.atleast_1d(theta), np.atleast_1d(psi)
    with progress(theta.size * psi.size, "LPV plant (grid points)") as bar:
        plant = com_lpv_plant(system, theta=theta, psi=psi, bases=bases,
                              rate_bounds=[[-rate_bound, rate_bound], [-rate_bound, rate_bound]],
                              progress=bar)
    gp = interconnection_8_1(plant, tracked=system.q_names)
    return DesignPlant(plant=plant, generalized=gp, bound=pointwise_state_feedback_bound(gp))


def refined_plant(system, plant: GriddedLPV, *, factor: int, bases, what: str = "verification plant",
                  progress=no_progress) -> GriddedLPV:
    """The plant of ``system`` on the grid ``factor`` times finer than ``plant``'s.

    New COM linearisations at the refined axes (:meth:`GriddedLPV.refined`) with the design's
    membrane points and rate bounds: the true plant between the design points, where a design
    is verified (8.3) or the estimator of the output feedback is built.

    Parameters
    ----------
    system : System
        The system of ``plant``.
    plant : GriddedLPV
        The design plant.
    factor : int
        Refinement of each axis (4: three new points between two design points).
    bases : callable
        The stage bases of ``plant`` (:func:`design_plant`).
    what : str
        The plant's name in the progress label.
    progress : callable, optional
        The progress factory (module docstring).
    """
    axes = plant.refined(factor)
    with progress(axes[0].size * axes[1].size, f"{what} (grid points)") as bar:
        return com_lpv_plant(system, theta=axes[0], psi=axes[1], bases=bases,
                             rate_bounds=plant.rate_bounds, membrane_points=plant.membrane_points,
                             progress=bar)


def synthesize_design(generalized: GeneralizedLPV, *, bound: PointwiseBound, solver: str = "EIGOPT",
                      gamma: float | None = None, fixed_gamma: bool = False, rtol: float = GAMMA_RTOL,
                      time_budget: float | None = None, start: LPVStateFeedback | None = None,
                      max_iter: int | None = None, sample_time: float | None = None,
                      progress=no_progress) -> tuple[LPVStateFeedback, dict]:
    """The state feedback of eqs. 5.95-5.99 on ``generalized`` and its JSON entries.

    Parameters
    ----------
    generalized : GeneralizedLPV
        The interconnection of Figure 8.1 (:func:`design_plant`).
    bound : PointwiseBound
        Its pointwise lower bound of gamma (:func:`design_plant`).
    solver : {"EIGOPT", "CLARABEL", "SCS"}
        "EIGOPT": :func:`~tmfem.control.lpv.gridded_synthesis.lpvsyn` on its EIGOPT route
        (affine basis, verified at the design points; :mod:`tmfem.control.lpv.eigopt_route`):
        without ``fixed_gamma`` the gamma bisection between the bound and ``gamma`` (default
        2 x the bound) to relative width ``rtol`` within ``time_budget`` s (default
        :data:`~tmfem.control.lpv.defaults.TIME_BUDGET`), from ``start`` when
        given; with ``fixed_gamma`` one feasible point at ``gamma``.
        "CLARABEL" or "SCS": their minimisation of gamma
        (:func:`~tmfem.control.lpv.synthesis.synthesize_state_feedback`) when its
        estimate stays within ``time_budget`` CPU seconds (default
        :data:`tmfem.resources.MAX_SYNTHESIS_S`) and the memory limit (refused up front:
        :class:`~tmfem.errors.ResourceLimit`).
    max_iter : int, optional
        Iteration limit of each EIGOPT level or of the conic solver.
    sample_time : float, optional
        EIGOPT: also the frozen loops sampled at this zero-order-hold step stable.
    progress : callable, optional
        The progress factory (module docstring).

    Returns
    -------
    (LPVStateFeedback, dict)
        The design and its JSON entries (gamma, solver, status, sizes, times; the bisection's
        levels and bracket; EIGOPT: ``route``, the lpvsyn route and why it was taken).

    Raises
    ------
    InputError
        An upper level not above the pointwise lower bound.
    InfeasibleController
        No controller found (the message holds the pointwise lower bound).
    """
    try:
        if solver == "EIGOPT":
            time_budget = TIME_BUDGET if time_budget is None else time_budget
            with progress(time_budget, "gamma bisection (s of budget)") as bar:
                res = lpvsyn(generalized, 0, generalized.sizes["n_u"], grid=generalized.axes,
                             rate_bounds=generalized.rate_bounds, basis="affine", method="eigopt", verify_refine=1,
                             gamma=gamma, fixed_gamma=fixed_gamma, gamma_rtol=rtol, time_budget=time_budget,
                             start=start, max_iter=max_iter, sample_time=sample_time, bound=bound,
                             progress=lambda t: bar(int(t), time_budget))
            ctrl = res.design
            extra = {k: v for k, v in res.info.items() if k.startswith("gamma_")}     # the bisection's bracket
            extra["route"] = {"lpvsyn": res.info["method"], "reason": res.info["route_reason"],
                              "verified_at_design_points": res.verification["passed"]}
            return ctrl, {"gamma": ctrl.gamma, "solver": ctrl.solver, "status": ctrl.status, "sizes": ctrl.sizes,
                          "solve_time_s": ctrl.solve_time, "sample_time_s": sample_time, **extra}
        ctrl = synthesize_state_feedback(generalized, solver=solver, max_iter=max_iter, gamma=gamma,
                                         sample_time=sample_time,
                                         **({} if time_budget is None else {"time_budget": time_budget}))
        extra = {}
    except InfeasibleController as exc:
        if solver == "EIGOPT":      # the EIGOPT route's messages name the pointwise lower bound
            raise
        at = grid_point_text(generalized.parameter_names, bound.at)
        raise InfeasibleController(f"{exc} (pointwise state-feedback lower bound of gamma: "
                                   f"{bound.lower_bound:.4g} at {at})") from None
    return ctrl, {"gamma": ctrl.gamma, "solver": ctrl.solver, "status": ctrl.status, "sizes": ctrl.sizes,
                  "solve_time_s": ctrl.solve_time, "sample_time_s": sample_time, **extra}


def verify_design(design: LPVStateFeedback, plant: GriddedLPV, *, tracked,
                  sample_time: float | None = None) -> Verification:
    """The check of ``design`` between its grid points (8.3).

    :func:`tmfem.control.lpv.verify.verify` on the interconnection of ``plant`` (e.g. a grid 4 x
    finer than the design's, :func:`refined_plant`) tracking ``tracked``: the LMI of eq. 5.95 at
    every point and rate vertex, the frozen closed loops, and with ``sample_time`` the loops
    sampled with a zero-order hold at that step.

    Raises
    ------
    InfeasibleController
        Where the LMI does not hold or a frozen loop is unstable.
    """
    return verify(design, interconnection_8_1(plant, tracked=tracked), sample_time=sample_time)


def verified_design(design: LPVStateFeedback, plant: GriddedLPV, *, tracked, sample_time: float | None = None,
                    rounds: int = DESIGN_ROUNDS, per_round: int = DESIGN_PER_ROUND,
                    time_budget: float = TIME_BUDGET, progress=no_progress) -> tuple:
    """:func:`verify_design` of ``design`` on ``plant`` (a grid finer than the design's); where
    it fails between the design points, the cutting-plane refinement of
    :func:`tmfem.control.lpv.refinement.refine_state_feedback` on ``plant``'s grid (at most
    ``rounds`` re-solves of ``per_round`` more points each, within ``time_budget`` seconds)
    and the check again.

    Returns
    -------
    (LPVStateFeedback, Verification, dict or None)
        The design (refined when it was), its verification on ``plant`` and the refinement's
        record (None when the design passed as it was).

    Raises
    ------
    InfeasibleController
        The design, refined or not, fails on ``plant`` (the message says what the refinement did).
    """
    gp = interconnection_8_1(plant, tracked=tracked)
    if rounds == 0:
        return design, verify(design, gp, sample_time=sample_time), None
    v = verify(design, gp, sample_time=sample_time, allow_failure=True)
    if v.passed:
        return design, v, None
    with progress(rounds, "cutting-plane refinement (rounds)") as bar:
        refined, record = refine_state_feedback(design, gp, per_round=per_round, max_rounds=rounds,
                                                time_budget=time_budget, sample_time=sample_time,
                                                progress=lambda k: bar(k, rounds))
    try:
        v = verify(refined, gp, sample_time=sample_time)
    except InfeasibleController as exc:
        raise InfeasibleController(f"{exc}; the cutting-plane refinement on that grid stopped on "
                                   f"{record['stopped']} after {len(record['rounds'])} checks "
                                   f"({record['points_added']} points added)") from None
    return refined, v, record


def output_feedback_design(design: LPVStateFeedback, plant: GriddedLPV, fine: GriddedLPV, *, tracked,
                           noise: float = 1e-3, sample_time: float | None = None, certificate=None,
                           interpolation: str = "multilinear", estimator_plant: GriddedLPV | None = None,
                           progress=no_progress) -> tuple[LPVOutputFeedback, dict]:
    """The observer-based output feedback on q and the membrane point coordinates, verified
    frozen on the fine grid (sampled at ``sample_time`` when given), and its JSON entries.

    JSON: ``gamma`` becomes the largest frozen closed-loop norm from [q_d, n_d, n] to p over
    ``fine`` (``state_feedback_gamma`` the certified level of K(rho));
    ``verification_max_eig`` stays the LMI of K(rho) re-checked there.

    Parameters
    ----------
    design : LPVStateFeedback
        K(rho) on the grid of ``plant``.
    plant, fine : GriddedLPV
        The design plant and the plant of the verification grid.
    tracked : list of str
        The tracked outputs (the system's q).
    noise : float
        Measurement-noise weight W_n of the estimator [rad, m].
    certificate : (rtol, time budget, rounds), optional
        The rate-bounded certificate of the loop (:mod:`tmfem.control.lpv.certificate`) on
        the design grid, refined by cutting planes on ``fine`` (at most ``rounds``
        re-solves within another time budget) and re-checked there (keys
        ``rate_bounded_*``).
    interpolation : {"multilinear", "spline"}
        The estimator's between its grid points.
    estimator_plant : GriddedLPV, optional
        The Kalman estimator's plant on a grid finer than the design's (default ``plant``).
    """
    nz = plant.nx // 2
    measured = list(plant.state_names[:nz])          # q and the K point coordinates (eq. 5.17)
    t0 = time.perf_counter()
    est = plant if estimator_plant is None else estimator_plant
    d = design_output_feedback(design, est, tracked=tracked, measured=measured, W_n=noise,
                               interpolation=interpolation)
    cert = None
    if certificate is not None:
        rtol, budget, rounds = certificate
        with progress(budget, "rate-bounded certificate (s of budget)") as bar:
            t1 = time.perf_counter()
            cert = rate_bounded_certificate(d, plant, W_e=W_E, W_u=W_U, rtol=rtol, time_budget=budget,
                                            progress=lambda w: bar(int(min(time.perf_counter() - t1, budget)),
                                                                   budget))
        if cert.found and rounds > 0:
            with progress(rounds, "certificate refinement (rounds)") as bar:
                cert = refine_certificate(cert, d, fine, W_e=W_E, W_u=W_U, per_round=CERTIFICATE_PER_ROUND,
                                          max_rounds=rounds, time_budget=budget,
                                          progress=lambda k: bar(min(k, rounds), rounds))
    with progress(int(np.prod(fine.grid_shape)), "output-feedback verification (points)") as bar:
        vo = verify_output_feedback(d, fine, W_e=W_E, W_u=W_U, dt=sample_time, certificate=cert, progress=bar)
    return d, {"output_feedback": True, "measured": measured, "noise_weight": noise, "W_d": d.W_d,
               "estimator_interpolation": interpolation, "estimator_grid": list(est.grid_shape),
               "state_feedback_gamma": design.gamma, "gamma": vo.max_hinf,
               "guarantee": ("rate-bounded (X(rho) of the loop on the design grid, re-checked on the fine grid)"
                             if cert is not None and cert.found else
                             "frozen-parameter (fine grid) only; K(rho) alone is rate-bounded on the design grid"),
               "output_feedback_time_s": time.perf_counter() - t0, **vo.to_dict()}


def saved_design_plant(design: LPVStateFeedback, system, *, bases, progress=no_progress) -> GriddedLPV:
    """The design plant of a saved ``design`` (:meth:`LPVStateFeedback.load`) rebuilt on its
    grid (its rate bounds, the COM linearisations of ``system`` with the stage bases
    ``bases``), so that the design can be checked and deployed there.

    Raises
    ------
    InputError
        A design not scheduled on the system's [theta_1N, psi_1N]
        (:func:`~tmfem.control.lpv.plant.scheduling_parameters`).
    """
    expected = scheduling_parameters(system.N)
    if list(design.parameter_names) != expected or len(design.axes) != 2:
        raise InputError(f"expected a design scheduled on {expected} (the {system.N}-bar system's), found "
                         f"{list(design.parameter_names)}")
    with progress(design.axes[0].size * design.axes[1].size, "LPV plant (grid points)") as bar:
        return com_lpv_plant(system, theta=design.axes[0], psi=design.axes[1], bases=bases,
                             rate_bounds=design.rate_bounds, progress=bar)
