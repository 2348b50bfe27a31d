"""``tmfem report``: the complete analysis of one system as a report directory.

Design (ch. 3), statics, modes and free vibration of the membrane-truss-cable, shell-beam-cable
and control-oriented models beside the dissertation's tables, at the designed prestress and at
the prestress the dissertation's results imply, and the deployment (7.4); every table, plot,
animation and ParaView file linked from ``index.md``
(:func:`tmfem.reference.report.write_report`). ``make demo`` is
``tmfem report --preset 1-4 --out out/1-4``.
"""
from __future__ import annotations

import textwrap

from tmfem.cli.common import (Progress, add_system_args, check_com_modes, check_model_budget,
                              check_time_steps, output_dir, positive_float, positive_int,
                              say, system_from_args)
from tmfem.cli.uncontrollable import add_uncontrollable_arg, excluded_text, with_uncontrollable
from tmfem.errors import InputError

NAME = "report"
HELP = ("complete analysis of a system (design, FE statics, 12 modes of the MTC, SBC and COM "
        "models beside the printed ones when the file has them, free vibration, deployment) as a "
        "report directory with index.md")


def configure(parser) -> None:
    add_system_args(parser)
    parser.add_argument("--out", required=True,
                        help="output directory (created; checked writable before any work)")
    parser.add_argument("--mesh", type=positive_int, default=10, metavar="n",
                        help="membrane mesh n x n per quadrilateral patch (default 10, as in 6.2)")
    parser.add_argument("--modes", type=positive_int, default=None,
                        help="number of modes (default 12, as in Table 6.6, or all the "
                             "coordinates of the control-oriented model when it has fewer)")
    parser.add_argument("--t-end", type=positive_float, default=10.0,
                        help="free-vibration duration [s] (default 10)")
    parser.add_argument("--dt", type=positive_float, default=0.01,
                        help="time step [s] (default 0.01, as in 6.5)")
    parser.add_argument("--no-render", action="store_true",
                        help="skip the pyvista renders (default: render)")
    parser.add_argument("--no-deploy", action="store_true",
                        help="skip the deployment of 7.4 (default: run it when the system file "
                             "declares one: [report] deployment, or [packaged] with [deployment]; "
                             "the preset 1-4 runs 1-4D)")
    add_uncontrollable_arg(parser, what="the deployment's switch")


def run(args) -> dict:
    from tmfem.reference.deployments import CONTROLLERS
    from tmfem.reference.report import STEPS, report_deployment, write_report

    system = system_from_args(args)
    if args.modes is None:
        args.modes = min(12, com_coordinates(system))
        if args.modes < 12:
            say("report", f"{args.modes} modes: the control-oriented model of {system.name} "
                f"has {args.modes} coordinates")
    check_model_budget(system, mesh=args.mesh, tendon_elements=3, modes=args.modes,
                       backend="scipy")         # the report's FE models solve with scipy
    check_com_modes(system, modes=args.modes)
    check_time_steps(t_end=args.t_end, dt=args.dt)
    deployment = report_deployment(system)
    if deployment is None and args.no_deploy:
        raise InputError(f"--no-deploy: option does not apply: system {system.name!r} has no "
                         "deployment in the report (its file has no [report] deployment and no "
                         "[packaged] with [deployment])")
    if deployment is not None and not args.no_deploy:
        where = "[report] deployment"
        check_time_steps(t_end=deployment["t_end"], dt=args.dt, given=f"{where} t_end")
        if deployment["controller"] not in CONTROLLERS:
            raise InputError(f"{where}: expected 'controller' one of {sorted(CONTROLLERS)}, found "
                             f"{deployment['controller']!r}")
    if args.exclude_uncontrollable:
        if deployment is None or args.no_deploy:
            raise InputError("--exclude-uncontrollable: option does not apply: the report of "
                             f"{system.name!r} runs no deployment")
        # refused for a deployment controller without the H-infinity switch
        with_uncontrollable(deployment["system"], exclude=True, controller=deployment["controller"])
    out = output_dir(args.out, option="--out")
    with Progress(total=len(STEPS), desc=f"report {system.name}") as bar:
        bar.note(STEPS[0])
        nxt = iter(STEPS[1:])
        result = write_report(system, out, mesh_n=args.mesh, modes=args.modes, t_end=args.t_end,
                              dt=args.dt, render=not args.no_render, deploy=not args.no_deploy,
                              progress=lambda done: bar.step(next(nxt, "done")),
                              run_progress=lambda label: bar.callback(label),
                              uncontrollable="exclude" if args.exclude_uncontrollable else None)
    say("report", f"done: {out / 'index.md'}, web page {out / 'report.html'}")
    return result


def com_coordinates(system) -> int:
    """n_q + K: the coordinates of the system's control-oriented model (K of ``[models.com]``)."""
    from tmfem.models.com.model import default_membrane_modes
    return len(system.q_names) + default_membrane_modes(system)


def format_text(r: dict) -> str:
    from tabulate import tabulate

    f = r["frequencies_hz"]
    pr = r.get("printed_frequencies_hz") or {}
    printed_cols = ("MTC", "SBC", "COM")
    head = ["mode"] + [f"{k} [Hz]" for k in f] + ([f"{m} printed" for m in printed_cols] if pr else [])
    rows = []
    for i in range(r["modes"]):
        row = [i + 1] + [("unstable" if v[i] < 0 else f"{v[i]:.4f}") if i < len(v) else "-"
                         for v in f.values()]
        if pr:
            row += [f"{pr[m][i]:.4f}" if i < len(pr[m]) else "-" for m in printed_cols]
        rows.append(row)
    st = r["statics"]
    srows = [[k, f"{v['tendon_stress_max_MPa']:.2f}", f"{v['bar_load_max_N']:.3f}",
              f"{v['membrane_max_von_mises_MPa']:.3f}"] for k, v in st.items()]
    unstable = r.get("unstable_modes") or {}
    lines = [f"report of {r['system']}: checks "
             + ("passed" if not r["failed_checks"] else "FAILED: " + ", ".join(r["failed_checks"])), "",
             tabulate(srows, headers=[f"{r.get('fe_model', 'MTC')} statics", "tendon stress [MPa]", "bar load [N]",
                                      "membrane von Mises [MPa]"], disable_numparse=True), "",
             tabulate(rows, headers=head, disable_numparse=True), "",
             f"index: {r['out']}/index.md ({len(r['files'])} files)"]
    if r.get("com_membrane_modes"):
        from tmfem.models.com.mode_count import MembraneModeChoice
        lines.insert(-1, "COM: " + MembraneModeChoice(**r["com_membrane_modes"]).text)
    if r.get("com_disagreement"):
        lines.insert(-1, f"warning: {r['com_disagreement']['message']}")
    for k, m in unstable.items():
        lines.insert(-1, f"{k}: the equilibrium is unstable in mode(s) {m} (omega^2 < 0, eq. 5.32)")
    d = r.get("deployment")
    if d and "not_run" in d:
        lines.insert(-1, f"deployment {d['system']} not run: {d['not_run']}")
        lines.insert(-1, "")
    elif d:
        lines.insert(-1, f"deployment {d['system']} ({d['controller']}, uncertainty "
                         f"{d['uncertainty']}): " + ("no switch before t_end" if d['switch_time_s'] is None
                                                     else f"switch at {d['switch_time_s']:.4g} s") + ", max w "
                         f"{1e3 * d['max_membrane_deflection_m']:.2f} mm, final tracking error "
                         f"{d['final_tracking_error']:.2g}")
        if d.get("excluded_modes_hz"):
            lines.insert(-1, "  " + excluded_text(d["excluded_modes_hz"]))
        lines.insert(-1, "")
    if r.get("notes"):
        lines += ["", "notes of the system file:"]
        lines += [textwrap.fill(n, width=96, initial_indent="- ", subsequent_indent="  ")
                  for n in r["notes"]]
    return "\n".join(lines)
