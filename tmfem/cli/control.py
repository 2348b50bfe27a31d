"""``tmfem control``: linear control at a deployed configuration (7.3-7.4).

``tmfem control hinf --preset 1-4D [--alpha 0.5] [--save k.npz] [--plot out.png] [--json]``:
H-infinity output feedback by LMIs with alpha-stability; ``tmfem control pbh --preset ...``:
the PBH tests alone; ``tmfem control recheck k.npz``: re-verify a saved design;
``tmfem control lpv FILE|--preset 2-3-lpv [--grid 6x3] [--rate-bound-deg 10] [--save lpv.npz]``: the
gridded LPV state feedback of ch. 8 (:mod:`tmfem.cli.control_lpv`).
"""
from __future__ import annotations


from tmfem.cli import control_lpv
from tmfem.cli.common import add_system_args, output_file, say, system_from_args
from tmfem.cli.uncontrollable import add_uncontrollable_arg
from tmfem.errors import InputError, ResourceLimit

NAME = "control"
HELP = ("linear control: PBH tests, H-infinity LMI synthesis at a deployed configuration (7.3-7.4), "
        "gridded LPV state feedback (ch. 8)")

_HINF_ONLY = ("alpha", "u_m", "save", "plot", "solver", "method", "exclude_uncontrollable")


def configure(parser) -> None:
    parser.add_argument("action", choices=("hinf", "pbh", "recheck", "lpv"),
                        help="hinf: synthesis; pbh: controllability/observability only; "
                             "recheck FILE.npz: re-verify a saved design; lpv: gridded LPV state "
                             "feedback with rate bounds (ch. 8)")
    add_system_args(parser)
    parser.add_argument("--membrane-modes", type=int, default=None,
                        help="membrane modes K of the control-oriented model (default: the file's [models.com] "
                             "membrane_modes, else chosen automatically against the FE model; docs/guides/com.md)")
    parser.add_argument("--alpha", type=float, default=None,
                        help="alpha_1 [1/s]: closed-loop poles with Re < -alpha_1 (default: the file's "
                             "[control] alpha, else 0.1 x 2 pi f_1 of the deployed plant)")
    parser.add_argument("--u-m", type=float, default=None,
                        help="u_m [m] of W_u = I/u_m (default: the file's [control] u_m, else 0.5 %% of the "
                             "mean bar length)")
    parser.add_argument("--solver", choices=("ARE", "CLARABEL", "SCS", "EIGOPT"), default=None,
                        help="hinf --method lmi: how the eliminated LMIs are solved: ARE (default; their Riccati "
                             "characterisation, bisection on gamma, LMIs re-checked), or the SDP "
                             "solvers CLARABEL / SCS (the 50-state 2-3 LMI fails in Clarabel; "
                             "docs/guides/control.md); lpv: EIGOPT (default; eigenvalue optimisation: bisection on "
                             "gamma, or one level with --fixed-gamma; docs/guides/lpv.md), or the conic solvers "
                             "SCS / CLARABEL (one SDP, a cross-check on small plants)")
    parser.add_argument("--method", choices=("auto", "lmi", "riccati", "central"), default=None,
                        help="auto (default): tmfem.control.hinfsyn's verified route (Riccati "
                             "bisection with the central controller on regular plants, else the "
                             "LMIs; docs/guides/hinf.md); lmi: eliminated LMIs of eq. 5.65; riccati: python-control "
                             "hinfsyn (SLICOT SB10AD) on the alpha-shifted plant; central: the "
                             "central (minimum-entropy) controller at 1.01 gamma_opt, solver-"
                             "independent, the one `tmfem deploy` uses (docs/guides/control.md)")
    parser.add_argument("--pbh-tol", type=float, default=None,
                        help="PBH margin below which a mode is uncontrollable/unobservable (default 1e-8)")
    add_uncontrollable_arg(parser, what="the H-infinity controller (hinf)")
    parser.add_argument("--save", help="write plant and controller to this .npz")
    parser.add_argument("--plot", help="write the closed-loop analysis figure (PNG)")
    control_lpv.configure(parser)


#: Largest plant of `hinf`/`pbh`: 2 (n_q + K) states. 1-4(D) with K = 3 (22 states) takes
#: seconds; the COM is built symbolically (K = 40: ~25 s) and the LMIs grow with the square
#: of the states (the 50-state 2-3 LMI already fails in Clarabel, docs/guides/control.md).
MAX_STATES = 60


def check_control_modes(system, K) -> None:
    """``--membrane-modes K``: 1 <= K (the membrane outputs w of eqs. 5.73-5.75 are membrane
    deflections) and a plant of at most :data:`MAX_STATES` states."""
    if K is None:
        return
    nq = len(system.q_names)
    if K < 1:
        raise InputError(f"--membrane-modes: expected K >= 1 (the outputs w of eqs. 5.73-5.75 "
                         f"are membrane deflections), found {K}")
    if 2 * (nq + K) > MAX_STATES:
        raise ResourceLimit(f"--membrane-modes {K}: the plant of {system.name} has 2 (n_q + K) = "
                            f"{2 * (nq + K)} states; the limit is {MAX_STATES} (K <= "
                            f"{MAX_STATES // 2 - nq}): the symbolic model grows fast with K and "
                            "the LMIs with the square of the states (docs/guides/control.md)")


def run(args) -> dict:
    if args.action == "lpv":
        given = [k for k in ("alpha", "u_m", "plot", "method", "membrane_modes", "pbh_tol")
                 if getattr(args, k) is not None]
        if given or args.as_printed:
            raise InputError(f"lpv: options {['--' + k.replace('_', '-') for k in given] or ['--as-printed']} "
                             "do not apply")
        return control_lpv.run(args)
    lpv_given = [k for k in control_lpv.LPV_ONLY if getattr(args, k) is not None]
    if lpv_given:
        raise InputError(f"{args.action}: options {['--' + k.replace('_', '-') for k in lpv_given]} apply "
                         "to `tmfem control lpv` only")
    if args.action == "recheck":
        from tmfem.control.linear.deployed_design import recheck
        if args.spec is None or args.preset is not None:
            raise InputError("recheck: expected one design file (.npz), found "
                             f"spec={args.spec!r}, --preset={args.preset!r}")
        given = [k for k in _HINF_ONLY + ("membrane_modes", "pbh_tol") if getattr(args, k) is not None]
        if given:
            raise InputError(f"recheck: options {given} do not apply")
        return {"action": "recheck", "file": args.spec, **recheck(args.spec)}
    from tmfem.control.linear.deployed_design import DEFAULT_METHOD, deployed_hinf, save_design
    if args.action == "pbh":
        given = [k for k in _HINF_ONLY if getattr(args, k) is not None]
        if given:
            raise InputError(f"pbh: options {['--' + k.replace('_', '-') for k in given]} apply to "
                             "`tmfem control hinf` only")
    if args.solver == "EIGOPT":
        raise InputError("--solver EIGOPT: applies to `tmfem control lpv` only")
    if args.method in ("riccati", "central") and args.solver is not None:
        raise InputError(f"--solver {args.solver}: applies to --method lmi only (or to the LMI fallback "
                         f"of --method auto), found --method {args.method}")
    output_file(args.save, option="--save", suffixes=(".npz",))
    output_file(args.plot, option="--plot", suffixes=(".png",))
    system = system_from_args(args)
    check_control_modes(system, args.membrane_modes)
    say(f"control {args.action}", f"{system.name}: building the plant")
    res = deployed_hinf(system, alpha=args.alpha, u_m=args.u_m, membrane_modes=args.membrane_modes,
                        solver=args.solver, synthesize=args.action == "hinf",
                        pbh_tol=args.pbh_tol,
                        method=args.method or ("lmi" if args.solver else DEFAULT_METHOD),
                        uncontrollable="exclude" if args.exclude_uncontrollable else None)
    out = {"action": args.action, **res.summary()}
    if args.action == "hinf":
        from tmfem.control.linear.loop_plots import damping_table
        out["closed_loop_slowest"] = [list(r) for r in
                                      sorted(damping_table(res.design.closed_loop), key=lambda r: -r[2])[:3]]
        if args.save:
            save_design(res.design, args.save)
            out["saved"] = args.save
        if args.plot:
            from tmfem.control.linear.loop_plots import plot_design
            plot_design(res.design, open_loop=res.generalized, path=args.plot,
                        title=f"{system.name}: H-infinity design, gamma = {res.design.gamma:.4g}, "
                              f"alpha_1 = {res.design.alpha:g} 1/s")
            out["plot"] = args.plot
    return out


def format_text(r: dict) -> str:
    if r["action"] == "lpv":
        return control_lpv.format_text(r)
    if r["action"] == "recheck":
        return (f"{r['file']}: gamma = {r['gamma']:.6g}, ||T_pw||_inf = {r['closed_loop_hinf_norm']:.6g}, "
                f"max Re(closed-loop poles) = {r['closed_loop_max_real_part']:.4g} 1/s "
                f"(alpha_1 = {r['alpha']:g} 1/s): ok")
    p = r["pbh"]
    from tmfem.models.com.mode_count import MembraneModeChoice
    lines = [f"system {r['system']}: {r['n_states']} states, {r['n_inputs']} inputs",
             "COM: " + MembraneModeChoice(**r["membrane_mode_choice"]).text + "; measured membrane points "
             + ", ".join(f"({x:.3f}, {y:.3f})" for x, y in r["membrane_points"]) + " m",
             f"open-loop f_max = {r['open_loop_f_max_hz']:.4f} Hz" + (
                 "" if r["open_loop_f_max_printed_hz"] is None
                 else f" (printed {r['open_loop_f_max_printed_hz']})"),
             f"PBH (tol {p['tol']:g}): controllable {p['controllable']} (least margin "
             f"{p['least_controllable']['margin']:.3g} at {p['least_controllable']['frequency_hz']:.3f} Hz), "
             f"observable {p['observable']} (least margin {p['least_observable']['margin']:.3g})"]
    if r["action"] == "hinf":
        s = r["solver"]
        lines += [f"gamma = {r['gamma']:.6g} (||T_pw||_inf = {r['closed_loop_hinf_norm']:.6g}), "
                  f"alpha_1 = {r['alpha']:g} 1/s, max Re(closed-loop poles) = {r['closed_loop_max_real_part']:.4g} 1/s",
                  f"{r['method']}, controller order {r['controller_order']}"
                  + ("" if r["cond_I_minus_RS"] is None else
                     f", cond(I - RS) = {r['cond_I_minus_RS']:.3g}"),
                  f"solver {s['solver']}: {s['status']}, {s['solve_time_s']:.1f} s, "
                  f"{s['n_variables']} variables, LMI sizes {s['lmi_sizes']}"]
        if "saved" in r:
            lines.append(f"saved {r['saved']}")
        if "plot" in r:
            lines.append(f"plot {r['plot']}")
    lines += [f"note: {n}" for n in r.get("notes", [])]
    return "\n".join(lines)
