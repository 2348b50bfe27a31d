"""gamma minimisation of the gridded LPV state feedback (eqs. 5.95-5.96) by bisection over
eigenvalue-optimisation levels, with continuation in gamma (docs/guides/lpv.md).

The LMIs at a fixed gamma are solved for a feasible point by :class:`tmfem.control.lpv.eigopt.
EigOpt`. :func:`bisect_gamma` brackets the optimum between a proven lower bound (the pointwise
state-feedback optima, :mod:`tmfem.control.lpv.bounds`: below it the LMIs are infeasible) and
a level where a point is found, halving the bracket [lo, hi] with each level mid = (lo + hi)/2;
every level starts from the point found at the lowest feasible level so far (continuation in
gamma: that point already meets every LMI block that does not involve gamma). A level where
no point is found raises lo, but **does not prove infeasibility** (the method is local and
stops after a fixed number of iterations): the bracket it returns is
[highest level not found, lowest level found] next to the proven lower bound. Stops when
hi - lo <= rtol hi or when the time budget is spent; the controller is that of the lowest
feasible level, accepted only after the LMIs are re-computed in floating point.

Continuation in the grid (automatic with the sampled-loop LMI and no given start, on a grid
where more than one parameter varies): the pointwise Riccati start knows nothing of the
sample time, and on the 2-3 plant at 6 x 3 with dt = 0.01 s the first level was not found
from it (docs/guides/lpv.md, run D). So the last varying parameter is first collapsed to its middle
grid value (:func:`collapsed`; for 2-3 the 6 x 1 grid at psi_13 = 8.36 deg), the gamma
bisection runs there (recursively: a further parameter is collapsed the same way) within half
of the time budget, and its design, extended constant along the collapsed parameter
(P(rho) = P_0 + rho_1 P_1 with P_2 = 0, Q likewise), starts the first level on the full grid.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from tmfem.control.lpv.eigopt import EigOpt
from tmfem.control.lpv.coordinates import Coordinates
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


@dataclass
class GammaBracket:
    """Where the gamma minimisation ended. ``lower_bound``: proven (no controller below it);
    ``not_found``: the highest level where no point was found (None: none failed; not a
    proof of infeasibility); ``feasible``: the lowest level with a verified point (the
    controller's gamma); ``levels``: one dict per level tried, in order; ``start_grid``,
    ``start_levels``: the collapsed grid of the continuation in the grid and the levels tried
    there (None and empty without it)."""

    lower_bound: float
    feasible: float
    not_found: float | None
    rtol: float
    converged: bool
    stopped: str
    time_s: float
    levels: list = field(default_factory=list)
    start_grid: list | None = None
    start_levels: list = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"gamma_lower_bound_proven": self.lower_bound, "gamma_not_found": self.not_found,
                "gamma_feasible": self.feasible, "gamma_rtol": self.rtol, "gamma_converged": self.converged,
                "gamma_stopped": self.stopped, "gamma_search_time_s": self.time_s,
                "gamma_levels": self.levels, "gamma_start_grid": self.start_grid,
                "gamma_start_levels": self.start_levels,
                "gamma_note": "EIGOPT failing at a level does not prove that level infeasible: the "
                              "optimum lies in [gamma_lower_bound_proven, gamma_feasible]"}


def bisect_gamma(gp: GeneralizedLPV, *, lower: float, upper: float, rtol: float = 0.02,
                 time_budget: float = 300.0, max_iter: int = 150, margin: float = 1e-8,
                 t_schedule=(1e-2, 1e-3, 1e-4), sample_time: float | None = None,
                 start: LPVStateFeedback | None = None, grid_continuation: bool | None = None,
                 carry_not_found: bool = True, first_free: bool = True,
                 progress=None) -> tuple[LPVStateFeedback, GammaBracket]:
    """Minimise gamma of eqs. 5.95-5.96 on the grid of ``gp`` (module docstring).

    Parameters
    ----------
    lower : float
        A proven lower bound of gamma (e.g. the pointwise bound), the bisection's start lo.
    upper : float
        The first level tried (from the pointwise Riccati start); no point there: refused.
    rtol : float
        Stop when hi - lo <= rtol * hi.
    time_budget : float
        Seconds for the whole search (a level running past it is abandoned, not counted).
    max_iter : int
        L-BFGS iterations per smoothing stage of a level.
    t_schedule : sequence of float
        Smoothing parameters of each level (:meth:`~tmfem.control.lpv.eigopt.EigOpt.solve`).
    margin : float
        A level is feasible once the largest scaled LMI eigenvalue is below -margin.
    sample_time : float, optional
        Also the sampled-loop stability LMI at this zero-order-hold step
        (:class:`~tmfem.control.lpv.eigopt.EigOpt`).
    start : LPVStateFeedback, optional
        The first level starts from this design's P(rho), Q(rho) instead of the Riccati fit:
        a design on a sub-grid (continuation in the grid; coefficients of parameters it does
        not vary are zero) or an earlier run.
    grid_continuation : bool, optional
        Start from the design of the bisection on the :func:`collapsed` grid (module
        docstring). Default: with ``sample_time``, no ``start`` and more than one varying
        parameter. The sub-grid stage's levels are ``GammaBracket.start_levels``.
    carry_not_found : bool
        With the continuation in the grid, the highest level not found on the sub-grid becomes
        the full grid's lo (and ``not_found``): a full-grid design restricted to the sub-grid's
        line is a sub-grid design at the same gamma (the LMIs of the line are among the full
        grid's; the rate vertices +-v of the collapsed parameter average to its zero rate), so
        that level is "not found" for the full grid in the same local sense (docs/guides/lpv.md).
    first_free : bool
        From a given start (or the sub-grid design), the first level is the lowest gamma at
        which the start holds every LMI as it is (a bisection on the sign of the largest
        eigenvalue, which decreases with gamma; no iteration) when that is below ``upper``.
    progress : callable, optional
        Called with (hi - lo) / hi after each level.

    A ``gp`` without control input (B2 with no column: the analysis LMI of a closed loop,
    :mod:`tmfem.control.lpv.certificate`) given a ``start`` is balanced on it instead of on the
    pointwise Riccati solutions.

    Raises
    ------
    InfeasibleController
        No point found at ``upper`` (raise it), or the time budget spent before.
    """
    if not (0 < lower < upper):
        raise InputError(f"gamma bisection: expected 0 < lower < upper, found lower = {lower!r}, "
                         f"upper = {upper!r}")
    if not (0 < rtol < 1) or not time_budget > 0:
        raise InputError(f"gamma bisection: expected 0 < rtol < 1 and a time budget > 0, found rtol = "
                         f"{rtol!r}, budget = {time_budget!r} s")
    t0 = time.perf_counter()
    deadline = t0 + time_budget
    co = Coordinates.of(gp)
    if grid_continuation is None:
        grid_continuation = sample_time is not None and start is None and len(co.varying) > 1
    if grid_continuation and start is not None:
        raise InputError("gamma bisection: grid_continuation starts from its own sub-grid design; expected no "
                         "given start with it")
    first, sub = ("riccati" if start is None else "given design"), None
    if grid_continuation:
        if len(co.varying) < 2:
            raise InputError(f"gamma bisection: grid continuation needs a grid where at least two parameters "
                             f"vary, found grid {gp.grid_shape}")
        sub = collapsed(gp, co.varying[-1])
        log.info("gamma bisection: continuation in the grid, first on the %s grid", sub.grid_shape)
        start, sub_br = bisect_gamma(sub, lower=lower, upper=upper, rtol=rtol, time_budget=time_budget / 2,
                                     max_iter=max_iter, margin=margin, t_schedule=t_schedule,
                                     sample_time=sample_time)
        first = f"sub-grid design {'x'.join(map(str, sub.grid_shape))} (gamma {start.gamma:.5g})"
    analysis = gp.sizes["n_u"] == 0
    given = None if start is None else co.coefficients_of(start, gp)
    e = EigOpt(gp, T=co.T, c_of=co.c_of, dvs=co.dvs, gamma=upper, sample_time=sample_time,
               balance_on=given if analysis else None)
    levels, best, not_found = [], None, None
    z_start = e.riccati_start(upper) if start is None else e.start_from(*given)
    lo, hi, gamma, stopped = lower, upper, upper, "tolerance"
    if sub is not None and carry_not_found and sub_br.not_found is not None and sub_br.not_found > lo:
        lo = not_found = sub_br.not_found
        levels.append({"gamma": lo, "evaluations": 0, "time_s": 0.0, "cpu_s": 0.0, "largest_scaled_eig": None,
                       "start": first, "result": f"not found on the {'x'.join(map(str, sub.grid_shape))} "
                                                 "sub-grid (carried)"})
    if start is not None and first_free:
        gamma = _lowest_free_level(e, z_start, lo, upper, margin=margin, rtol=rtol / 4)
    while True:
        t1, c1, n1 = time.perf_counter(), time.process_time(), e.evaluations
        z, worst, reason = e.solve(gamma, z_start, t_schedule=t_schedule, max_iter=max_iter, margin=margin,
                                   deadline=deadline)
        row = {"gamma": gamma, "evaluations": e.evaluations - n1, "time_s": time.perf_counter() - t1,
               "cpu_s": time.process_time() - c1,
               "largest_scaled_eig": worst, "start": first if best is None else "continuation"}
        if reason == "time":
            levels.append({**row, "result": "unfinished (time budget)"})
            stopped = "time budget"
            break
        ctrl = None
        if worst < 0:
            try:
                ctrl = co.accepted(gp, *e.coefficients(z), gamma, solver="EIGOPT", status="",
                                   solve=0.0, build=0.0, sample_time=sample_time)
            except InfeasibleController as exc:
                log.info("gamma bisection: level %.5g rejected on re-computation: %s", gamma, exc)
        levels.append({**row, "result": "feasible" if ctrl else "not found"})
        log.info("gamma bisection: level %.5g %s (%d evaluations, %.1f s)", gamma, levels[-1]["result"],
                 row["evaluations"], row["time_s"])
        if ctrl is not None:
            best, hi, z_start = ctrl, gamma, z
        elif best is None and gamma < upper:      # a free first level refused on re-computation
            gamma = upper
            continue
        elif best is None:
            raise InfeasibleController(f"gamma bisection: expected a feasible point at the upper level "
                                       f"gamma = {upper:.5g}, found none (largest scaled LMI eigenvalue "
                                       f"{worst:.3e}); try a higher upper level")
        else:
            lo = not_found = gamma
        if progress is not None:
            progress((hi - lo) / hi)
        if hi - lo <= rtol * hi:
            break
        gamma = (lo + hi) / 2
    if best is None:
        raise InfeasibleController(f"gamma bisection: the time budget of {time_budget:g} s ran out before a "
                                   f"feasible point at gamma = {upper:.5g}")
    total = time.perf_counter() - t0
    br = GammaBracket(lower_bound=lower, feasible=hi, not_found=not_found, rtol=rtol,
                      converged=hi - lo <= rtol * hi, stopped=stopped, time_s=total, levels=levels,
                      start_grid=None if sub is None else list(sub.grid_shape),
                      start_levels=[] if sub is None else sub_br.start_levels + sub_br.levels)
    best.status = (f"bisection: feasible at {hi:.5g}, not found at "
                   f"{'-' if not_found is None else f'{not_found:.5g}'}, proven lower bound {lower:.5g} "
                   f"({len(levels)} levels, {e.evaluations} evaluations, stopped on {stopped})")
    best.solve_time = total
    log.info("gamma bisection: %s", best.status)
    return best, br


def _lowest_free_level(e: EigOpt, z, lo: float, hi: float, *, margin: float, rtol: float) -> float:
    """The lowest level in (lo, hi] (to ``rtol``) where ``z`` holds every LMI of ``e`` as it is
    (largest scaled eigenvalue < -margin, the test of :meth:`EigOpt.solve` before iterating); the
    LMIs of eq. 5.95 decrease with gamma (-gamma I blocks), so the sign test is monotone. ``hi``
    when ``z`` fails there too."""
    def holds(g):
        return e.largest(z, g) < -margin
    if not holds(hi):
        return hi
    a, b = lo, hi
    while b - a > rtol * b:
        m = (a + b) / 2
        a, b = (a, m) if holds(m) else (m, b)
    log.info("gamma bisection: the start holds every LMI as it is from gamma = %.5g", b)
    return b


def collapsed(gp: GeneralizedLPV, k: int) -> GeneralizedLPV:
    """``gp`` on the sub-grid where parameter ``k`` takes only its middle grid value (index
    size // 2; for the 2-3 grid of P_D, psi_13 = 8.36 deg), the other axes and every rate bound
    unchanged."""
    mid = gp.grid_shape[k] // 2
    cut = lambda X: np.take(X, [mid], axis=k)               # noqa: E731
    sub = GeneralizedLPV.from_matrices(
        axes=[a if j != k else a[[mid]] for j, a in enumerate(gp.axes)], parameter_names=gp.parameter_names,
        rate_bounds=gp.rate_bounds, A=cut(gp.A), B1=cut(gp.B1), B2=cut(gp.B2), C1=cut(gp.C1),
        D11=cut(gp.D11), D12=cut(gp.D12))
    sub.state_names = list(gp.state_names)
    return sub
