"""``tmfem static``: equilibrium of a finite-element model reached from the undeformed membrane (6.2)."""
from __future__ import annotations

import sys

import numpy as np

from tmfem.cli.common import add_model_args, add_system_args, model_from_args, with_backend
from tmfem.models.mtc.design import describe_rule
from tmfem.models.mtc.spec import sequence_of

NAME = "static"
HELP = "static equilibrium of the membrane-truss-cable model (dissertation 6.2)"


def configure(parser) -> None:
    add_system_args(parser)
    add_model_args(parser, NAME, default="mtc")
    parser.add_argument("--monitor", default=None,
                        help="comma-separated node labels whose iteration history is reported "
                             "(default B_M1 and, for 1-4, B_14 as in Fig. 6.1)")
    parser.add_argument("--vtk", help="write the equilibrium (bars, tendons with forces, membrane "
                                      "with displacement and stresses) to this .vtu file")
    parser.add_argument("--png", help="render the equilibrium to this PNG")
    parser.add_argument("--stress-plot", help="PNG maps of the membrane stresses in the floating "
                                              "frame (Figs. 6.3-6.4)")
    parser.add_argument("--wrinkle-plot", help="PNG map of the membrane states (taut / wrinkled / "
                                               "slack) and tension directions (docs/guides/wrinkling.md)")
    parser.add_argument("--progress", action="store_true", help="iteration progress on stderr")


def default_monitor(system) -> list[str]:
    """Monitored nodes of Figures 6.1 (B_14 of 1-4) and 6.5-6.7 (B_11, A_21, B_21 of 2-3)."""
    if system.M == 1:
        return [f"B_1{system.N}"] if system.N < 10 else [f"B_1,{system.N}"]
    return ["B_11", "A_21", "B_21"]


def static_progress(enabled: bool):
    """A ``progress(iteration, rnorm, mu, rho)`` callback of the static solve that prints one
    line per iteration on stderr (``--progress``), or None."""
    if not enabled:
        return None

    def show(it, rn, mu, rho):
        print(f"  static it {it:3d}  |r| = {rn:.3e} N  mu = {mu:.3g}  rho = {rho:.3g}",
              file=sys.stderr)
    return show


def solve(args, model, options):
    from tmfem.models.mtc.post import static_summary
    monitor = args.monitor.split(",") if args.monitor else default_monitor(model.system)
    print(f"tmfem static: {model.system.name}, {model.ndof} free dofs, solving from the "
          f"{options['start']} state", file=sys.stderr)
    res = model.solve_static(start=options["start"], monitor=monitor,
                             progress=static_progress(args.progress),
                             sequence=sequence_of(options["mesh"], options["sequence"]))
    return res, static_summary(model, res.x, result=res)


def write_outputs(args, model, x, summary) -> None:
    from tmfem.models.mtc.post import member_state, q_from_positions
    from tmfem.post.mtc import membrane_field
    if args.stress_plot:
        from tmfem.post.mtc import plot_membrane_stress
        summary["stress_plot"] = str(plot_membrane_stress(
            args.stress_plot, model, x, title=f"{model.system.name} MTC membrane stresses (O_f frame)"))
    if args.wrinkle_plot:
        from tmfem.post.mtc import plot_wrinkling
        summary["wrinkle_plot"] = str(plot_wrinkling(args.wrinkle_plot, model, x))
    if not (args.vtk or args.png):
        return
    system = model.system
    X = x[:, model.topology.system_node]
    q = q_from_positions(system, X)
    ms = member_state(model, x)
    mf = membrane_field(model, x)
    if args.vtk:
        from tmfem.io.writer import write_configuration
        p = write_configuration(args.vtk, system, q=q, tendon_forces=ms["tendon_force"],
                                rest_lengths=model.rest_lengths, membrane=mf,
                                bar_forces=ms["bar_force"])
        summary["vtk"] = str(p)
    if args.png:
        from tmfem.post.render import render_configuration
        p = render_configuration(args.png, system, q=q, tendon_forces=ms["tendon_force"],
                                 membrane=mf, membrane_field="von_mises",
                                 title=f"{system.name} MTC equilibrium")
        summary["png"] = str(p)


def sbc_static(args, model) -> dict:
    """``tmfem static --model sbc``: the equilibrium from the undeformed membrane (6.2), its
    summary and the ParaView file / PNG of the shells, beams and tendons."""
    from tmfem.errors import InputError
    from tmfem.models.sbc.post import static_summary as sbc_summary
    if args.stress_plot or args.wrinkle_plot:
        raise InputError("static --model sbc: option does not apply: --stress-plot/--wrinkle-plot "
                         "(maps of the MTC membrane; the SBC shell stresses are in --vtk)")
    monitor = args.monitor.split(",") if args.monitor else default_monitor(model.system)
    res = model.solve_static(monitor=monitor, progress=static_progress(args.progress))
    out = sbc_summary(model, res)
    if args.vtk:
        from tmfem.post.sbc import write_sbc_state
        out["vtk"] = write_sbc_state(args.vtk, model, res.state)
    if args.png:
        from tmfem.models.mtc.post import q_from_positions
        from tmfem.post.render import render_configuration
        from tmfem.post.sbc import shell_field
        st = res.state
        q = q_from_positions(model.system, st.x[:, model.mtc.topology.system_node])
        out["png"] = str(render_configuration(
            args.png, model.system, q=q, tendon_forces=model.member_forces(st)["tendon"],
            membrane=shell_field(model, st), membrane_field="von_mises_top",
            title=f"{model.system.name} SBC equilibrium (shell von Mises, top surface)"))
    return out


def run(args) -> dict:
    model, options = model_from_args(args, NAME)
    if args.model == "sbc":
        return with_backend(sbc_static(args, model), model)
    res, summary = solve(args, model, options)
    write_outputs(args, model, res.x, summary)
    return with_backend(summary, model)


def format_text(r: dict) -> str:
    if r.get("model") == "sbc":
        from tmfem.models.sbc.post import format_static
        return format_static(r)
    lines = [f"MTC equilibrium of {r['system']}: mesh n={r['mesh_n']}, {r['tendon_elements']} "
             f"elements/tendon, {r['attachment']} attachment, {r.get('membrane_law', 'svk')} "
             f"membrane, {r['dofs']} free dofs",
             f"rest lengths {r['rest_lengths_source']} ({describe_rule(r['rest_lengths_source'])}): "
             + ", ".join(f"{k}={v:.5f} m" for k, v in list(r["rest_lengths"].items())[:8])
             + (" ..." if len(r["rest_lengths"]) > 8 else ""),
             f"converged in {r.get('iterations')} iterations ({r.get('static_time_s', 0):.2f} s); "
             f"residual {r['residual_history'][0]:.3e} -> {r['residual_history'][-1]:.3e} N",
             f"max distance of a node from the design: {r['max_deviation_from_design'] * 1e3:.3f} mm",
             "theta [deg] (design): " + ", ".join(f"{a:.3f} ({b:.3f})" for a, b in
                                                   zip(r["theta_deg"], r["theta_design_deg"])),
             "psi   [deg] (design): " + ", ".join(f"{a:.3f} ({b:.3f})" for a, b in
                                                   zip(r["psi_deg"], r["psi_design_deg"])),
             "Delta [mm] (design):  " + ", ".join(f"{a * 1e3:.4f} ({b * 1e3:.4f})" for a, b in
                                                   zip(r["Delta"], r["Delta_design"]))]
    for lab, h in r.get("monitor", {}).items():
        h = np.asarray(h)
        lines.append(f"history of {lab}: start {np.round(h[0], 5).tolist()} -> "
                     f"{np.round(h[-1], 5).tolist()} (design {np.round(r['nodes'][lab]['design'], 5).tolist()})")
    from tmfem.models.mtc.post import check_lines, printed_rows
    rows = printed_rows(r)
    lines.append(f"{'':32s} {'MTC':>12s} {'dissertation':>12s}")
    lines += [f"{a:32s} {b:12.4g} {c:12.4g}" if np.isfinite(c) else f"{a:32s} {b:12.4g}"
              for a, b, c in rows]
    lines.append("tendon forces [N]: " + ", ".join(f"{k}={v:.3f}" for k, v in
                                                   list(r["tendon_force"].items())[:12]))
    if r["tendon_slack"]:
        lines.append(f"SLACK tendons: {r['tendon_slack']}")
    lines += check_lines(r["checks"])
    for k in ("vtk", "png", "stress_plot", "wrinkle_plot"):
        if k in r:
            lines.append(f"wrote {r[k]}")
    return "\n".join(lines)
