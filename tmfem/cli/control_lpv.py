"""``tmfem control lpv``: gridded LPV state feedback of ch. 8 (eqs. 5.95-5.99), its pointwise
lower bound and its verification on a finer grid (8.3). Called by :mod:`tmfem.cli.control`."""
from __future__ import annotations

import sys

import numpy as np

from tmfem.cli.common import output_file
from tmfem.errors import InfeasibleController, InputError, ResourceLimit

#: Largest verification grid: every point is one COM linearisation (~2 s for 2-3 on this
#: machine under load), so 500 points is about a quarter of an hour.
MAX_VERIFY_POINTS = 500

# the options of `tmfem control` that only `lpv` takes (refused by the other actions)
LPV_ONLY = ("grid", "rate_bound_deg", "refine", "max_iter", "bound_only", "gamma")


def configure(parser) -> None:
    parser.add_argument("--grid", default=None, help="lpv: theta x psi points of the printed grid (8.3; default 6x3)")
    parser.add_argument("--rate-bound-deg", type=float, default=None,
                        help="lpv: |d rho/dt| bound [deg/s] (8.3: 10, the default)")
    parser.add_argument("--refine", type=int, default=None,
                        help="lpv: verification grid refinement factor (>= 4, default 4)")
    parser.add_argument("--max-iter", type=int, default=None, help="lpv: SDP solver iteration limit")
    parser.add_argument("--gamma", type=float, default=None,
                        help="lpv: the fixed level of --solver EIGOPT (required there)")
    parser.add_argument("--bound-only", action="store_true", default=None,
                        help="lpv: only the pointwise state-feedback lower bound of gamma (no SDP)")


def _grid(spec: str, printed: dict):
    try:
        nt, nps = (int(v) for v in spec.lower().split("x"))
    except ValueError:
        raise InputError(f"--grid: expected AxB (e.g. 6x3), found {spec!r}") from None
    th, ps = np.radians(printed["theta_grid_deg"]), np.radians(printed["psi_grid_deg"])
    if not (1 <= nt <= th.size and 1 <= nps <= ps.size):
        raise InputError(f"--grid: expected at most {th.size}x{ps.size} points of the printed grid, found {spec}")
    pick = lambda a, k: a[np.round(np.linspace(0, a.size - 1, k)).astype(int)]   # noqa: E731
    return pick(th, nt), pick(ps, nps)


def run(args) -> dict:
    from tmfem.cli.common import progress_bar
    from tmfem.control.lpv_bounds import pointwise_state_feedback_bound
    from tmfem.control.lpv_plant import com_lpv_plant
    from tmfem.control.lpv_synthesis import interconnection_8_1, synthesize_state_feedback
    from tmfem.control.lpv_verify import verify
    from tmfem.reference.tables import deployment_bases
    from tmfem.system import load_preset
    refine = 4 if args.refine is None else args.refine
    rate = 10.0 if args.rate_bound_deg is None else args.rate_bound_deg
    if refine < 4:
        raise InputError(f"--refine: expected >= 4 (the issue's verification standard), found {refine}")
    if not (np.isfinite(rate) and rate >= 0):
        raise InputError(f"--rate-bound-deg: expected >= 0, found {rate}")
    if args.max_iter is not None and args.max_iter < 1:
        raise InputError(f"--max-iter: expected an integer >= 1, found {args.max_iter}")
    output_file(args.save, option="--save", suffixes=(".npz",))
    if args.solver == "ARE":
        raise InputError("--solver ARE: applies to `tmfem control hinf` only; lpv takes CLARABEL or SCS")
    if args.spec is not None:
        raise InputError(f"lpv: expected --preset (a preset with a printed LPV grid), found the file {args.spec!r}")
    preset = args.preset or "2-3-lpv"
    s = load_preset(preset)
    printed = dict(s.printed or {})
    if "theta_grid_deg" not in printed or "psi_grid_deg" not in printed:
        raise InputError(f"preset {preset!r}: expected a printed LPV grid (theta_grid_deg, psi_grid_deg), found none")
    th, ps = _grid(args.grid or "6x3", printed)
    fine_n = [(a.size - 1) * refine + 1 for a in (th, ps)]
    if fine_n[0] * fine_n[1] > MAX_VERIFY_POINTS:
        raise ResourceLimit(f"--grid {args.grid or '6x3'} --refine {refine}: the verification grid "
                            f"has {fine_n[0]} x {fine_n[1]} = {fine_n[0] * fine_n[1]:,} points, one COM "
                            f"linearisation each (~2 s); the limit is {MAX_VERIFY_POINTS}")
    rb = np.radians(rate)
    print(f"tmfem control lpv: {preset}: linearising at {th.size * ps.size} grid points", file=sys.stderr)
    with progress_bar(th.size * ps.size, 1, "LPV plant (grid points)") as bar:
        plant = com_lpv_plant(s, theta=th, psi=ps, bases=deployment_bases(s),
                              rate_bounds=[[-rb, rb], [-rb, rb]], progress=bar)
    gp = interconnection_8_1(plant, tracked=s.q_names)
    bound = pointwise_state_feedback_bound(gp)
    out = {"action": "lpv", "preset": preset, "grid": list(plant.grid_shape), "rate_bound_deg": rate,
           **bound.to_dict(), "printed_gamma_bound": 4.18}
    if args.bound_only:
        return out
    try:
        ctrl = synthesize_state_feedback(gp, solver=args.solver or "SCS", max_iter=args.max_iter,
                                         gamma=args.gamma)
    except InfeasibleController as exc:
        raise InfeasibleController(f"{exc} (pointwise state-feedback lower bound of gamma: "
                                   f"{bound.lower_bound:.4g} at rho = {bound.at})") from None
    fine_axes = plant.refined(refine)
    with progress_bar(fine_axes[0].size * fine_axes[1].size, 1, "verification plant (grid points)") as bar:
        fine = com_lpv_plant(s, theta=fine_axes[0], psi=fine_axes[1], bases=deployment_bases(s),
                             rate_bounds=plant.rate_bounds, progress=bar)
    v = verify(ctrl, interconnection_8_1(fine, tracked=s.q_names))
    if args.save:
        ctrl.save(args.save)
        out["saved"] = args.save
    return {**out, "gamma": ctrl.gamma, "solver": ctrl.solver, "status": ctrl.status, "sizes": ctrl.sizes,
            "solve_time_s": ctrl.solve_time, **v.to_dict()}


def format_text(r: dict) -> str:
    deg = [f"{np.degrees(a):.2f} deg" for a in r["lpv_gamma_lower_bound_at"]]
    lines = [f"LPV state feedback, {r['preset']}, grid {r['grid'][0]}x{r['grid'][1]}, rates +-{r['rate_bound_deg']:g} deg/s",
             f"pointwise state-feedback lower bound of gamma: {r['lpv_gamma_lower_bound']:.4g} at "
             f"(theta_13, psi_13) = ({', '.join(deg)}) (printed ||G_pw|| < {r['printed_gamma_bound']})"]
    if "gamma" in r:
        lines += [f"gamma = {r['gamma']:.5g} ({r['solver']}, {r['status']}, {r['solve_time_s']:.1f} s, sizes {r['sizes']})",
                  f"verification on {r['verification_grid']}: max LMI eigenvalue {r['verification_max_eig']:.3e}, "
                  f"max closed-loop Re {r['closed_loop_max_real']:.3e}"]
    if "saved" in r:
        lines.append(f"saved {r['saved']}")
    return "\n".join(lines)
