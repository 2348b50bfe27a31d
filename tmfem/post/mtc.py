"""Fields, cells and pictures of the membrane-truss-cable model's results (ParaView, PNG)."""
from __future__ import annotations

import numpy as np

from tmfem.errors import shorten

from tmfem.io.fields import DISPLACEMENT_FIELD, MembraneField

from tmfem.io.paths import check_path
from tmfem.models.fe.outputs import to_floating
from tmfem.post.plots import new_figure, save_figure
from tmfem.fem.tension_field import STATE_NAMES, WRINKLED


def membrane_field(model, x: np.ndarray):
    """The membrane of positions x as a :class:`tmfem.io.fields.MembraneField` with displacement
    in the floating frame (point data) and sigma_p1, sigma_p2, von Mises and the floating-frame
    Cauchy components (cell data, element means), the membrane state ``membrane_state``
    (0 taut, 1 wrinkled, 2 slack) and the tension (wrinkle-crest) direction
    ``wrinkle_direction`` in the reference plane (:meth:`MembraneTL.wrinkling`)."""
    topo = model.topology
    nm = topo.n_mesh
    xm = x[:, :nm]
    corners = xm[:, topo.mesh.corners]
    xf = to_floating(xm, corners)
    ref = np.vstack([topo.mesh.p, np.zeros(nm)])
    st = model.membrane.stresses(xm)
    cd = {"sigma_p1": st.principal_elem[0], "sigma_p2": st.principal_elem[1],
          "von_mises": st.von_mises_elem,
          "sigma_xf": st.cauchy[0].mean(axis=-1), "sigma_yf": st.cauchy[1].mean(axis=-1),
          "tau_xfyf": st.cauchy[2].mean(axis=-1)}
    wr = model.membrane.wrinkling(xm)
    cd["membrane_state"] = wr["state"].astype(np.int32)
    cd["wrinkle_direction"] = wr["direction"]
    return MembraneField(mesh=topo.mesh, x=xm, point_data={DISPLACEMENT_FIELD: xf - ref},
                         cell_data=cd)


def model_cells(model) -> list:
    """Cells of the full MTC mesh: bars, tendon elements (lines) and membrane quads."""
    return [("line", model.topology.bar_conn), ("line", model.topology.tendon_conn),
            ("quad", model.topology.mesh.t)]


def plot_membrane_stress(png, model, x: np.ndarray, *, title: str | None = None):
    """Maps of sigma_p1, sigma_p2 and the von Mises stress over the membrane in the floating
    frame O_f-x_f y_f (element means; Figures 6.3-6.4, 6.9-6.10)."""
    from matplotlib.collections import PolyCollection
    png = check_path(png, suffixes=(".png",))
    topo = model.topology
    xm = x[:, :topo.n_mesh]
    xf = to_floating(xm, xm[:, topo.mesh.corners])
    st = model.membrane.stresses(xm)
    fields = [("sigma_p1", st.principal_elem[0]),
              ("sigma_p2 (in-plane minor)", st.principal_elem[1] + st.principal_elem[2]),
              ("von Mises", st.von_mises_elem)]
    fig = new_figure(figsize=(15, 4.6))
    axes = fig.subplots(1, 3)
    verts = np.stack([xf[0, topo.mesh.t].T, xf[1, topo.mesh.t].T], axis=-1)    # (ne, 4, 2)
    for ax, (name, v) in zip(axes, fields):
        pc = PolyCollection(verts, array=v / 1e6, cmap="viridis", edgecolors="none")
        ax.add_collection(pc)
        ax.autoscale_view()
        ax.set_aspect("equal")
        ax.set_xlabel("x_f [m]")
        ax.set_ylabel("y_f [m]")
        ax.set_title(f"{name} (element means): max {v.max() / 1e6:.3f} MPa")
        fig.colorbar(pc, ax=ax, label="MPa", shrink=0.8)
    if title:
        fig.suptitle(title)
    return save_figure(fig, png)


def plot_wrinkling(png, model, x: np.ndarray, *, title: str | None = None):
    """Map of the membrane states (taut / wrinkled / slack, :meth:`MembraneTL.wrinkling`) over
    the membrane in the floating frame, with the tension (wrinkle-crest) direction drawn in
    the wrinkled elements; the legend gives the area fraction of each state (Gauss points)."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.colors import ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    png = check_path(png, suffixes=(".png",))
    topo = model.topology
    xm = x[:, :topo.n_mesh]
    corners = xm[:, topo.mesh.corners]
    xf = to_floating(xm, corners)
    wr = model.membrane.wrinkling(xm)
    t = topo.mesh.t
    verts = np.stack([xf[0, t].T, xf[1, t].T], axis=-1)
    colors = ["#d9d9d9", "#e6550d", "#3182bd"]
    fig = new_figure(figsize=(7.0, 7.6))
    ax = fig.subplots()
    pc = PolyCollection(verts, array=wr["state"].astype(float), cmap=ListedColormap(colors),
                        edgecolors="none")
    pc.set_clim(-0.5, 2.5)
    ax.add_collection(pc)
    w = wr["state"] == WRINKLED
    if w.any():
        # the reference plane is the floating frame O_f (x_f along B_MN -> B_M1)
        d = wr["direction"][:2, w]
        c = verts[w].mean(axis=1)
        size = 0.4 * np.sqrt(np.abs(np.cross(verts[w, 2] - verts[w, 0], verts[w, 3] - verts[w, 1])) / 2)
        seg = np.stack([c - size[:, None] * d.T, c + size[:, None] * d.T], axis=1)
        ax.add_collection(LineCollection(seg, colors="k", linewidths=0.6))
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x_f [m]")
    ax.set_ylabel("y_f [m]")
    fr = wr["fractions"]
    ax.legend(handles=[Patch(color=colors[i], label=f"{n} ({100 * fr[n]:.1f} % of Gauss points)")
                       for i, n in enumerate(STATE_NAMES)]
              + ([Line2D([], [], color="k", lw=0.8, label="tension (wrinkle) direction")]
                 if w.any() else []),
              loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2, fontsize=8)
    ax.set_title(title or f"{model.system.name} MTC membrane states ({model.membrane_law} law)")
    return save_figure(fig, png)


# ---------------------------------------------------------------------------- reports
#: files ``tmfem static`` and ``tmfem modal`` can write for this model
STATIC_FILES = ("vtk", "png", "stress_plot", "wrinkle_plot")
MODE_FILES = ("vtk", "png")


def static_summary(model, result) -> dict:
    """JSON-able summary of an MTC equilibrium ``result``
    (:func:`tmfem.models.mtc.post.static_summary`)."""
    from tmfem.models.mtc.post import static_summary as summary
    return {"model": "mtc", **summary(model, result.x, result=result)}


def write_static_files(model, result, *, vtk=None, png=None, stress_plot=None,
                       wrinkle_plot=None) -> dict:
    """The ParaView file (bars, tendons with forces, membrane with displacement and stresses),
    the PNG, the stress maps (Figs. 6.3-6.4) and the wrinkling map of the equilibrium
    ``result`` that are asked for; returns their paths by kind."""
    from tmfem.models.fe.outputs import q_from_positions
    from tmfem.models.mtc.post import member_state
    out, x, system = {}, result.x, model.system
    if stress_plot:
        out["stress_plot"] = str(plot_membrane_stress(
            stress_plot, model, x, title=f"{system.name} MTC membrane stresses (O_f frame)"))
    if wrinkle_plot:
        out["wrinkle_plot"] = str(plot_wrinkling(wrinkle_plot, model, x))
    if not (vtk or png):
        return out
    q = q_from_positions(system, x[:, model.topology.system_node])
    ms = member_state(model, x)
    mf = membrane_field(model, x)
    if vtk:
        from tmfem.io.writer import write_configuration
        out["vtk"] = str(write_configuration(vtk, system, q=q, tendon_forces=ms["tendon_force"],
                                             rest_lengths=model.rest_lengths, membrane=mf,
                                             bar_forces=ms["bar_force"]))
    if png:
        from tmfem.post.render import render_configuration
        out["png"] = str(render_configuration(png, system, q=q, tendon_forces=ms["tendon_force"],
                                              membrane=mf, membrane_field="von_mises",
                                              title=f"{system.name} MTC equilibrium"))
    return out


def format_static(r: dict) -> str:
    """Text of :func:`static_summary`: landing against the design, the printed rows of Tables
    6.3/6.5, tendon forces and the design checks."""
    from tmfem.models.fe.summary import check_lines, printed_lines
    from tmfem.models.fe.rest_lengths import describe_rule
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
    lines += printed_lines(r, "MTC")
    lines.append("tendon forces [N]: " + ", ".join(f"{k}={v:.3f}" for k, v in
                                                   list(r["tendon_force"].items())[:12]))
    if r["tendon_slack"]:
        lines.append(f"SLACK tendons: {r['tendon_slack']}")
    lines += check_lines(r["checks"])
    for k in ("vtk", "png", "stress_plot", "wrinkle_plot"):
        if k in r:
            lines.append(f"wrote {r[k]}")
    return "\n".join(lines)


def modal_summary(model, result, modes) -> dict:
    """JSON-able summary of the modes ``modes`` about the MTC equilibrium ``result``: the
    model, its prestress and the frequencies (eq. 5.32)."""
    from tmfem.models.fe.rest_lengths import describe_rule
    from tmfem.models.mtc.post import static_summary as summary
    st = summary(model, result.x, result=result)
    return {"system": model.system.name, "model": "mtc", "dofs": model.ndof,
            "mesh_n": st["mesh_n"], "tendon_elements": st["tendon_elements"],
            "attachment": st["attachment"], "membrane_law": model.membrane_law,
            "rest_lengths_source": model.rest_lengths_source,
            "rest_lengths_note": describe_rule(model.rest_lengths_source),
            "rest_lengths": st["rest_lengths"], "static_iterations": result.iterations,
            "tendon_stress_max": st["tendon_stress_max"], "bar_load_max": st["bar_load_max"],
            "Delta_mean": float(np.mean(st["Delta"])), "freq_hz": modes.freq_hz.tolist()}


def write_mode_files(model, result, modes, *, vtk=None, png=None) -> dict:
    """The ParaView file of the mode shapes (point data mode_k) and the PNG of the first six
    that are asked for; returns their paths by kind."""
    from tmfem.post.modes import write_mode_shapes
    return write_mode_shapes(result.x, model_cells(model), model.topology.T @ modes.shapes,
                             modes.freq_hz, vtk=vtk, png=png,
                             title=f"{model.system.name} MTC modes")


def format_modal(r: dict) -> str:
    """Text of :func:`modal_summary`, with the dissertation's columns when present."""
    lines = [f"MTC modes of {r['system']}: mesh n={r['mesh_n']}, {r['tendon_elements']} "
             f"elements/tendon, {r['attachment']} attachment, {r.get('membrane_law', 'svk')} "
             f"membrane, {r['dofs']} free dofs",
             f"rest lengths {r['rest_lengths_source']}: {r['rest_lengths_note']}",
             "prestress: " + shorten(f"{k}={v:.5f} m" for k, v in r["rest_lengths"].items())
             + f"; max tendon stress {r['tendon_stress_max'] / 1e6:.2f} MPa, bar load "
               f"{r['bar_load_max']:.3f} N, Delta {r['Delta_mean'] * 1e3:.4f} mm"]
    d = r.get("dissertation")
    if d:
        lines.append(f"{'mode':>4s} {'ours [Hz]':>10s} {'MTC paper':>10s} {'SBC paper':>10s} {'diff':>8s}"
                     f"   ({d['source']})")
        for i, f in enumerate(r["freq_hz"]):
            if i < len(d["MTC"]):
                lines.append(f"{i + 1:4d} {f:10.4f} {d['MTC'][i]:10.4f} {d['SBC'][i]:10.4f} "
                             f"{100 * r['relative_difference_to_MTC'][i]:7.2f}%")
            else:
                lines.append(f"{i + 1:4d} {f:10.4f}")
    else:
        lines += [f"{i + 1:4d} {f:10.4f} Hz" for i, f in enumerate(r["freq_hz"])]
    for k in ("vtk", "png"):
        if k in r:
            lines.append(f"wrote {r[k]}")
    return "\n".join(lines)
