"""The LPV options shared by ``tmfem control lpv`` and ``tmfem deploy --controller lpv``:
the synthesis options, their checks, and the calls of the library's LPV workflow
(:mod:`tmfem.control.lpv.workflow`) with the CLI's progress bars. The library is reached
through the lazy attributes of its packages (``lpv.design_plant``), so that the command line
starts without loading the models."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tmfem import reference
from tmfem.cli.common import progress_bar, say
from tmfem.control import lpv
from tmfem.control.lpv.defaults import DESIGN_PER_ROUND, DESIGN_ROUNDS, GAMMA_RTOL, TIME_BUDGET
from tmfem.errors import InputError, ResourceLimit
from tmfem.resources import MAX_SYNTHESIS_S

#: Largest verification grid: every point is one COM linearisation (~2 s for 2-3 on this
#: machine under load), so 500 points is about a quarter of an hour.
MAX_VERIFY_POINTS = 500
#: Largest ``--max-iter``: SCS's own cap (each SCS iteration projects onto the PSD cone of
#: every grid point's LMI; a solve that does not converge runs to the cap); CLARABEL (an
#: interior-point Newton step an iteration) and EIGOPT (an L-BFGS step, the LMI eigenvalues at
#: every imposed point) stop by 200 and 150 iterations unless told otherwise.
MAX_ITER = 100_000


def configure_synthesis(parser, *, prefix: str = "lpv: ") -> None:
    """The synthesis options shared by `tmfem control lpv` and `tmfem deploy --controller lpv`."""
    parser.add_argument("--grid", default=None,
                        help=prefix + "theta x psi points of the system file's [lpv] grid (evenly spread, both "
                             "ends; default all of it: 6x3 for 2-3-lpv, 8.3)")
    parser.add_argument("--refine", type=int, default=None,
                        help=prefix + "verification grid refinement factor (>= 4, default 4)")
    parser.add_argument("--verify-rounds", type=int, default=None,
                        help=prefix + "where the design fails its verification between the design points, at most "
                             f"this many cutting-plane rounds on the verification grid (each imposes the "
                             f"{DESIGN_PER_ROUND} worst failing points and re-solves at the design's gamma; default "
                             f"{DESIGN_ROUNDS}; 0: refuse the design as it is)")
    parser.add_argument("--gamma", type=float, default=None,
                        help=prefix + "EIGOPT: the first (upper) level of the gamma bisection (default 2 x the "
                             "pointwise lower bound), or the only level with --fixed-gamma")
    parser.add_argument("--gamma-rtol", type=float, default=None,
                        help=prefix + f"EIGOPT: stop the bisection when (hi - lo) <= rtol hi (default {GAMMA_RTOL})")
    parser.add_argument("--time-budget", type=float, default=None,
                        help=prefix + f"EIGOPT: seconds for the gamma bisection (default {TIME_BUDGET:g}); "
                             f"CLARABEL, SCS: the longest solve started, against the estimate printed before it "
                             f"(default {MAX_SYNTHESIS_S:g} CPU s)")
    parser.add_argument("--fixed-gamma", action="store_true", default=None,
                        help=prefix + "EIGOPT: a feasible point at --gamma only (no bisection)")
    parser.add_argument("--start", metavar="FILE.npz", default=None,
                        help=prefix + "EIGOPT bisection: start the first level from this saved design (e.g. "
                             "one on a sub-grid: continuation in the grid) instead of the Riccati fit (with "
                             "--sample-time and no --start, the bisection first runs on the grid with psi "
                             "at its middle value and starts from that design)")


def lpv_grid(spec: str | None, system):
    """The --grid AxB points (default: all) of the grid of ``system``'s ``[lpv]`` table
    (``theta_grid_deg``, ``psi_grid_deg``), evenly spread, both ends; one point: the middle one."""
    p = system.problem.lpv
    if p is None or p.theta_grid_deg is None or p.psi_grid_deg is None:
        raise InputError(f"{system.name}: expected an [lpv] table with the design grid theta_grid_deg and "
                         f"psi_grid_deg [deg] (and rate_bound_deg [deg/s], default 10; "
                         f"docs/guides/system-file.md), found " + ("no [lpv] table" if p is None else "no grid"))
    th, ps = np.radians(p.theta_grid_deg), np.radians(p.psi_grid_deg)
    if spec is None:
        return th, ps
    try:
        nt, nps = (int(v) for v in spec.lower().split("x"))
    except ValueError:
        raise InputError(f"--grid: expected AxB (e.g. 6x3), found {spec!r}") from None
    if not (1 <= nt <= th.size and 1 <= nps <= ps.size):
        raise InputError(f"--grid: expected at most {th.size}x{ps.size} points of the [lpv] grid, found {spec}")
    # k evenly spread points including both ends; one point: the middle one (psi_0 = 8.36 deg of
    # eq. 5.100 on the 2-3-lpv psi axis, so a reduced grid still holds the 8.4 reference)
    pick = lambda a, k: a[np.round(np.linspace(0, a.size - 1, k)).astype(int)] if k > 1 \
        else a[[a.size // 2]]                                                    # noqa: E731
    return pick(th, nt), pick(ps, nps)


def check_synthesis(args, *, solver: str, system) -> dict:
    """The synthesis options and ``system``'s ``[lpv]`` grid (:func:`lpv_grid`), checked before
    any work; returns the resolved settings (system, grid axes, refine, EIGOPT bisection or
    fixed level)."""
    refine = 4 if args.refine is None else args.refine
    if refine < 4:
        raise InputError(f"--refine: expected >= 4 (the verification standard: 4 points between grid "
                         f"points), found {refine}")
    if solver not in ("CLARABEL", "SCS", "EIGOPT"):
        raise InputError(f"--solver {solver}: applies to `tmfem control hinf` only; lpv takes CLARABEL, SCS or EIGOPT")
    eig = {k: getattr(args, k, None) for k in ("gamma_rtol", "time_budget", "fixed_gamma", "start")}
    if solver != "EIGOPT":
        given = [k for k, v in {**eig, "gamma": args.gamma, "sample_time": getattr(args, "sample_time", None)}.items()
                 if v is not None and k != "time_budget"]
        if given:
            raise InputError(f"options {['--' + k.replace('_', '-') for k in given]} apply to --solver EIGOPT "
                             f"only, found --solver {solver}")
    elif args.fixed_gamma:
        if args.gamma is None or any(eig[k] is not None for k in ("gamma_rtol", "time_budget", "start")):
            raise InputError("--fixed-gamma: expected --gamma G and none of --gamma-rtol, --time-budget, --start "
                             "(one level, no bisection)")
    start = None
    if eig["start"] is not None:
        if not Path(eig["start"]).is_file():
            raise InputError(f"--start: expected a design saved by `tmfem control lpv --save`, found no file "
                             f"{eig['start']!r}")
        start = lpv.LPVStateFeedback.load(eig["start"])
    rtol = GAMMA_RTOL if eig["gamma_rtol"] is None else eig["gamma_rtol"]
    budget = TIME_BUDGET if eig["time_budget"] is None else eig["time_budget"]
    if not (0 < rtol < 1):
        raise InputError(f"--gamma-rtol: expected 0 < rtol < 1, found {rtol}")
    if not (np.isfinite(budget) and budget > 0):
        raise InputError(f"--time-budget: expected seconds > 0, found {budget}")
    if args.gamma is not None and not (np.isfinite(args.gamma) and args.gamma > 0):
        raise InputError(f"--gamma: expected > 0, found {args.gamma}")
    th, ps = lpv_grid(args.grid, system)
    fine_n = [(a.size - 1) * refine + 1 for a in (th, ps)]
    if fine_n[0] * fine_n[1] > MAX_VERIFY_POINTS:
        grid = f"--grid {args.grid}" if args.grid else f"the [lpv] grid {th.size}x{ps.size} of {system.name}"
        raise ResourceLimit(f"{grid} --refine {refine}: the verification grid "
                            f"has {fine_n[0]} x {fine_n[1]} = {fine_n[0] * fine_n[1]:,} points, one COM "
                            f"linearisation each (~2 s); the limit is {MAX_VERIFY_POINTS}")
    check_iteration_limits(args, fine_points=fine_n[0] * fine_n[1], design_points=th.size * ps.size)
    extra = fine_n[0] * fine_n[1] - th.size * ps.size
    rounds = min(DESIGN_ROUNDS, extra) if getattr(args, "verify_rounds", None) is None else args.verify_rounds
    if not 0 <= rounds <= extra:
        raise InputError(f"--verify-rounds: expected 0 to {extra} (each round "
                         f"imposes at least one more of the verification grid's points beyond the design "
                         f"grid's), found {rounds}")
    return {"system": system, "preset": system.name, "theta": th, "psi": ps, "refine": refine, "solver": solver,
            "gamma": args.gamma, "fixed": bool(args.fixed_gamma), "rtol": rtol, "budget": budget, "start": start,
            "time_budget": eig["time_budget"], "verify_rounds": rounds}


def progress(total, label):
    """The library's ``progress`` factory as a CLI progress bar."""
    return progress_bar(total, 1, label)


def check_iteration_limits(args, *, fine_points: int, design_points: int) -> None:
    """Upper bounds of ``control lpv --max-iter`` (:data:`MAX_ITER`, exit 3) and
    ``--certificate-rounds`` (exit 2): a cutting-plane round that goes on imposes at least one
    verification-grid point that is not imposed yet and re-solves the certificate's LMI by
    EIGOPT on all imposed points, so more rounds than the verification grid has points beyond
    the design grid cannot add anything (:func:`tmfem.control.lpv.certificate.refine_certificate`)."""
    max_iter = getattr(args, "max_iter", None)
    if max_iter is not None and max_iter > MAX_ITER:
        raise ResourceLimit(f"--max-iter {max_iter:,}: each iteration is one pass of the solver over the "
                            f"LMIs of every grid point, and a solve that does not converge runs to the "
                            f"cap; the limit is {MAX_ITER:,} (SCS's own cap)")
    rounds, extra = getattr(args, "certificate_rounds", None), fine_points - design_points
    if rounds is not None and rounds > extra:
        raise InputError(f"--certificate-rounds: expected at most {extra} (each round re-solves the "
                         f"certificate by EIGOPT with at least one more of the verification grid's "
                         f"{fine_points} points imposed, {design_points} are the design grid's), "
                         f"found {rounds}")


def design_plant(cfg: dict, *, rate_deg: float | None = None, command: str = "control lpv"):
    """The gridded plant of ``cfg`` (:func:`check_synthesis`), its interconnection (Fig. 8.1)
    and the pointwise lower bound of gamma (:func:`tmfem.control.lpv.workflow.design_plant`)
    with the rate bound ``rate_deg`` [deg/s] (default the ``[lpv]`` table's ``rate_bound_deg``);
    returns (plant, gp, bound, JSON dict), with the ``[printed] lpv_gamma_bound`` when the
    file carries one; its progress line names ``command``."""
    s, th, ps = cfg["system"], cfg["theta"], cfg["psi"]
    rate_deg = s.problem.lpv.rate_bound_deg if rate_deg is None else rate_deg
    say(command, f"{cfg['preset']}: linearising at {th.size * ps.size} grid points")
    p = lpv.design_plant(s, theta=th, psi=ps, bases=reference.lpv_bases(s), rate_bound=np.radians(rate_deg),
                              progress=progress)
    out = {"system": cfg["preset"], "grid": list(p.plant.grid_shape), "rate_bound_deg": rate_deg,
           "scheduling_parameters": list(p.plant.parameter_names),
           **p.bound.to_dict()}
    printed = (s.printed or {}).get("lpv_gamma_bound")
    if printed is not None:
        out["printed_gamma_bound"] = printed
    return p.plant, p.generalized, p.bound, out


def synthesize(cfg: dict, gp, bound, *, max_iter=None, sample_time=None):
    """The controller of the settings ``cfg`` (:func:`tmfem.control.lpv.workflow.synthesize_design`)
    and its JSON entries."""
    return lpv.synthesize_design(gp, bound=bound, solver=cfg["solver"], gamma=cfg["gamma"],
                                      fixed_gamma=cfg["fixed"], rtol=cfg["rtol"], time_budget=cfg["time_budget"],
                                      start=cfg["start"], max_iter=max_iter, sample_time=sample_time,
                                      progress=progress)


def refined_plant(s, plant, factor: int, *, what: str):
    """The plant of system ``s`` on the grid ``factor`` times finer than ``plant``'s
    (:func:`tmfem.control.lpv.workflow.refined_plant`)."""
    return lpv.refined_plant(s, plant, factor=factor, bases=reference.lpv_bases(s), what=what,
                                  progress=progress)


def verify_finer(cfg: dict, plant, ctrl, *, sample_time=None, fine=None):
    """:func:`tmfem.control.lpv.workflow.verified_design` on the grid ``refine`` times finer
    (or ``fine`` when given): (controller, verification, JSON entries); a controller that fails
    there is refined by cutting planes (``--verify-rounds``), and refused when it still fails."""
    fine = refined_plant(cfg["system"], plant, cfg["refine"], what="verification plant") if fine is None else fine
    ctrl, v, record = lpv.verified_design(ctrl, fine, tracked=cfg["system"].q_names, sample_time=sample_time,
                                          rounds=cfg["verify_rounds"], time_budget=cfg["budget"], progress=progress)
    refined = {} if record is None else {"design_refinement": record, "gamma": ctrl.gamma, "status": ctrl.status}
    return ctrl, v, {**v.to_dict(), **refined}
