"""Cutting-plane refinement of a gridded LPV state feedback that fails between its grid points.

The gridded LMIs of eqs. 5.95-5.96 are imposed at the design grid points only (8.3); between
them the true plant may violate them, and :func:`tmfem.control.lpv.verify.verify` on a finer
grid refuses the design. Each round of :func:`refine_state_feedback` re-checks the design at
every point of the finer grid (:func:`tmfem.control.lpv.verify.pointwise_checks`), adds the
``per_round`` worst failing points to the imposed ones (with every rate vertex), and EIGOPT
(:class:`~tmfem.control.lpv.eigopt.EigOpt`) re-solves the LMIs on the imposed points from the
current P(rho), Q(rho) (also its balancing), which stay affine in rho (eq. 5.99). The level is
the design's gamma, raised to (1 + ``level_rtol``) times the largest state-feedback optimum
gamma_SF of the new points where that is higher (no P, Q meet the LMIs at a point below its
gamma_SF, :mod:`tmfem.control.lpv.bounds`; a level just above it leaves EIGOPT no room). It
ends when the finer grid passes, after ``max_rounds`` re-solves, when the time budget is
spent, or when a re-solve finds no point (reported, not a proof: EIGOPT is a local method).

The finer grid passes by construction once every failing point is imposed and found; what
it does not give is more than the finer grid: the controller is checked at its points only,
as every gridded design is.
"""
from __future__ import annotations

import itertools
import logging
import time

import numpy as np

from tmfem.control.linear.hinf_riccati import state_feedback_gamma
from tmfem.control.lpv.bounds import scaled_point
from tmfem.control.lpv.coordinates import Coordinates, Tm_back, design_points_in
from tmfem.control.lpv.defaults import GAMMA_RTOL
from tmfem.control.lpv.eigopt import EigOpt
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.control.lpv.verify import pointwise_checks
from tmfem.errors import InputError

log = logging.getLogger(__name__)


def next_cut(fail: list, score: np.ndarray, imposed: list, *, per_round: int, rounds_done: int,
             max_rounds: int, deadline: float, axes, row: dict) -> tuple:
    """The next cutting planes: the ``per_round`` failing points (index tuples) of largest
    ``score`` not imposed yet, their parameter values recorded in ``row["added_at"]``; and why
    the refinement stops instead ("an imposed point fails": none is new; "rounds": ``max_rounds``
    re-solves done; "time budget": past ``deadline``), else None."""
    new = [k for k in sorted(fail, key=lambda k: -score[k]) if k not in imposed][:per_round]
    row["added_at"] = [[float(a[i]) for a, i in zip(axes, k)] for k in new]
    if not new:
        return new, "an imposed point fails"
    if rounds_done >= max_rounds:
        return new, "rounds"
    return new, ("time budget" if time.perf_counter() > deadline else None)


def resolve_on_points(gp: GeneralizedLPV, co: Coordinates, start, *, gamma: float, points: list, row: dict,
                      started: tuple, what: str, max_iter: int, margin: float, t_schedule,
                      deadline: float, sample_time: float | None = None) -> tuple:
    """One cutting-plane re-solve: EIGOPT (:class:`~tmfem.control.lpv.eigopt.EigOpt`) on the
    ``points`` (index tuples) of ``gp``'s grid at level ``gamma``, balanced on and started from
    the coefficients ``start`` (P_k, Q_k in the coordinates ``co``). Records in ``row`` the
    start's and the result's largest scaled eigenvalue, the points imposed, the evaluations,
    the result ("found", "not found", "unfinished (time budget)") and the wall and CPU seconds
    since ``started`` = (perf_counter, process_time); logs it under ``what``.

    Returns
    -------
    (coefficients or None, reason)
        The scaled (P_k, Q_k) found (None when not) and the solver's reason.
    """
    e = EigOpt(gp, T=co.T, c_of=co.c_of, dvs=co.dvs, gamma=gamma, points=points, sample_time=sample_time,
               balance_on=start)
    z0 = e.start_from(*start)
    row["start_scaled_eig"] = e.largest(z0, gamma)
    z, top, reason = e.solve(gamma, z0, t_schedule=t_schedule, max_iter=max_iter, margin=margin, deadline=deadline)
    row.update(imposed=len(points), evaluations=e.evaluations, largest_scaled_eig=top,
               result="found" if top < 0 else ("unfinished (time budget)" if reason == "time" else "not found"),
               time_s=time.perf_counter() - started[0], cpu_s=time.process_time() - started[1])
    log.info("%s: round %d, %d points imposed: %s (%d evaluations, largest scaled eigenvalue %.3e, %.1f s)",
             what, row["round"], len(points), row["result"], e.evaluations, top, row["time_s"])
    return (e.coefficients(z) if top < 0 else None), reason


def refine_state_feedback(design: LPVStateFeedback, fine: GeneralizedLPV, *, per_round: int = 4,
                          max_rounds: int = 8, time_budget: float = 600.0, max_iter: int = 150,
                          margin: float = 1e-8, t_schedule=(1e-2, 1e-3, 1e-4), level_rtol: float = GAMMA_RTOL,
                          sample_time: float | None = None, progress=None) -> tuple[LPVStateFeedback, dict]:
    """Refine ``design`` by cutting planes until it passes its checks on ``fine`` (module
    docstring).

    Parameters
    ----------
    design : LPVStateFeedback
        A design on a grid contained in ``fine``'s.
    fine : GeneralizedLPV
        The interconnection of Figure 8.1 on the finer grid (e.g. the verification grid).
    per_round : int
        Failing points added per round (the worst by the LMI eigenvalue of eq. 5.95).
    max_rounds : int
        Re-solves at most (0: only the check).
    time_budget : float
        Seconds for all rounds.
    max_iter, margin, t_schedule
        Of each re-solve (:meth:`~tmfem.control.lpv.eigopt.EigOpt.solve`; the bisection's).
    level_rtol : float
        The level is at least (1 + level_rtol) times the new points' pointwise optima (default
        the bisection's relative tolerance).
    sample_time : float, optional
        Also the frozen loops sampled with a zero-order hold at this step stable, checked and
        imposed.
    progress : callable, optional
        Called with the number of rounds done.

    Returns
    -------
    (LPVStateFeedback, dict)
        The last design found (``design`` itself when no round found one; its gamma the level)
        and the record: ``passed``, ``design_gamma``, ``gamma`` (the level reached), ``stopped`` ("passed",
        "rounds", "time budget", "not found", "an imposed point fails"), per round the failing
        points, the largest relative LMI eigenvalue on the finer grid and where, the points
        added, the level and the new points' largest pointwise optimum, the re-solve's result
        and times;
        ``points_added``, ``fine_grid``, ``time_s``.

    Raises
    ------
    InputError
        Bad options, or a ``fine`` grid that misses a design point.
    """
    if not (int(per_round) == per_round >= 1 and int(max_rounds) == max_rounds >= 0 and time_budget > 0):
        raise InputError(f"design refinement: expected per_round >= 1, max_rounds >= 0 (integers) and a time "
                         f"budget > 0, found {per_round!r}, {max_rounds!r}, {time_budget!r}")
    if list(design.state_names) != list(fine.state_names):
        raise InputError(f"design refinement: expected the finer grid's plant over the design's "
                         f"{len(design.state_names)} states, found {len(fine.state_names)}")
    imposed = design_points_in(design.axes, fine.axes, what="design refinement")
    n_design = len(imposed)
    t0 = time.perf_counter()
    deadline = t0 + time_budget
    co = Coordinates.of(fine)
    rounds, current, stopped = [], design, "rounds"
    while True:
        t1, c1 = time.perf_counter(), time.process_time()
        checks = pointwise_checks(current, fine, sample_time=sample_time)
        fail = [tuple(int(i) for i in k) for k in np.argwhere(checks.failing())]
        k_max = np.unravel_index(int(np.argmax(checks.lmi)), checks.lmi.shape)
        row = {"round": len(rounds), "failing": len(fail), "fine_max_eig": float(checks.lmi[k_max]),
               "fine_max_eig_at": [float(a[i]) for a, i in zip(fine.axes, k_max)],
               "check_s": time.perf_counter() - t1}
        log.info("design refinement: %d imposed points, finer grid %s: %d failing, largest relative LMI "
                 "eigenvalue %.3e", len(imposed), fine.grid_shape, len(fail), row["fine_max_eig"])
        if not fail:
            rounds.append(row)
            stopped = "passed"
            break
        new, stop = next_cut(fail, checks.lmi, imposed, per_round=per_round, rounds_done=len(rounds),
                             max_rounds=max_rounds, deadline=deadline, axes=fine.axes, row=row)
        if stop:
            rounds.append(row)
            stopped = stop
            break
        imposed += new
        optimum = max(state_feedback_gamma(*scaled_point(fine, k, co.T)) for k in new)
        gamma = max(current.gamma, (1 + level_rtol) * optimum)
        row.update(level=gamma, pointwise_optimum=optimum)
        found, reason = resolve_on_points(fine, co, co.coefficients_of(current, fine), gamma=gamma, points=imposed,
                                          row=row, started=(t1, c1), what="design refinement",
                                          sample_time=sample_time, max_iter=max_iter, margin=margin,
                                          t_schedule=t_schedule, deadline=deadline)
        rounds.append(row)
        if progress is not None:
            progress(len(rounds))
        if found is None:
            stopped = "time budget" if reason == "time" else "not found"
            break
        Ps, Qs = found
        min_p = min(float(np.linalg.eigvalsh(sum(c * P for c, P in zip(co.c_of(rho), Ps))).min())
                    for rho in itertools.product(*fine.axes))
        current = LPVStateFeedback(
            gamma=gamma, P=[Tm_back(P, co.T) for P in Ps], Q=[Q * co.T[None, :] for Q in Qs],
            center=co.center, half_width=co.half, varying=co.varying, axes=[a.copy() for a in design.axes],
            parameter_names=list(design.parameter_names), rate_bounds=design.rate_bounds.copy(),
            state_names=list(design.state_names), solver=design.solver,
            status=f"{design.status}; refined: {len(imposed) - n_design} points of the "
                   f"{'x'.join(map(str, fine.grid_shape))} grid imposed",
            solve_time=design.solve_time + (time.perf_counter() - t0), build_time=design.build_time,
            sizes=design.sizes, max_lmi_eig=float(row["largest_scaled_eig"]), min_P_eig=min_p)
    record = {"passed": stopped == "passed", "design_gamma": design.gamma, "gamma": current.gamma,
              "stopped": stopped, "rounds": rounds,
              "points_added": len(imposed) - n_design, "fine_grid": list(fine.grid_shape),
              "time_s": time.perf_counter() - t0}
    log.info("design refinement: %s after %d checks, %d points added (%.1f s)", stopped, len(rounds),
             record["points_added"], record["time_s"])
    return current, record
