"""`tmfem lpv`: gridded LPV state-feedback synthesis of ch. 8 (eqs. 5.95-5.99) and its
verification on a finer grid (8.3)."""
from __future__ import annotations

import numpy as np

from tmfem.control.lpv_plant import com_lpv_plant
from tmfem.control.lpv_synthesis import interconnection_8_1, synthesize_state_feedback
from tmfem.control.lpv_verify import verify
from tmfem.errors import InputError
from tmfem.reference.tables import deployment_bases
from tmfem.system import load_preset

NAME = "lpv"
HELP = "LPV state feedback with rate bounds on the (theta, psi) grid of ch. 8 (eqs. 5.95-5.99)"


def configure(parser):
    parser.add_argument("--preset", default="2-3-lpv", help="symmetric 2-stage preset with a printed LPV grid")
    parser.add_argument("--grid", default="6x3", help="theta x psi points taken from the printed grid (8.3)")
    parser.add_argument("--rate-bound-deg", type=float, default=10.0, help="|d rho/dt| bound [deg/s] (8.3: 10)")
    parser.add_argument("--refine", type=int, default=4, help="verification grid refinement factor (>= 4)")
    parser.add_argument("--solver", default="SCS", choices=["CLARABEL", "SCS"])
    parser.add_argument("--max-iter", type=int, default=None)
    parser.add_argument("--save", default=None, help="write P_k, Q_k, gamma to this .npz")


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
    if args.refine < 4:
        raise InputError(f"--refine: expected >= 4 (the issue's verification standard), found {args.refine}")
    if not (np.isfinite(args.rate_bound_deg) and args.rate_bound_deg >= 0):
        raise InputError(f"--rate-bound-deg: expected >= 0, found {args.rate_bound_deg}")
    s = load_preset(args.preset)
    printed = dict(s.printed or {})
    if "theta_grid_deg" not in printed or "psi_grid_deg" not in printed:
        raise InputError(f"preset {args.preset!r}: expected a printed LPV grid (theta_grid_deg, psi_grid_deg), found none")
    th, ps = _grid(args.grid, printed)
    rb = np.radians(args.rate_bound_deg)
    plant = com_lpv_plant(s, theta=th, psi=ps, bases=deployment_bases(s), rate_bounds=[[-rb, rb], [-rb, rb]])
    ctrl = synthesize_state_feedback(interconnection_8_1(plant, tracked=s.q_names), solver=args.solver,
                                     max_iter=args.max_iter)
    fine_axes = plant.refined(args.refine)
    fine = com_lpv_plant(s, theta=fine_axes[0], psi=fine_axes[1], bases=deployment_bases(s),
                         rate_bounds=plant.rate_bounds)
    v = verify(ctrl, interconnection_8_1(fine, tracked=s.q_names))
    if args.save:
        ctrl.save(args.save)
    return {"gamma": ctrl.gamma, "grid": list(plant.grid_shape), "solver": ctrl.solver,
            "status": ctrl.status, "sizes": ctrl.sizes, "solve_time_s": ctrl.solve_time,
            **v.to_dict(), "printed_gamma_bound": 4.18}
