"""Fields, cells and pictures of the membrane-truss-cable model's results (ParaView, PNG)."""
from __future__ import annotations

import numpy as np

from tmfem.io.fields import DISPLACEMENT_FIELD, MembraneField

from tmfem.io.paths import check_path
from tmfem.models.mtc.topology import to_floating
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
