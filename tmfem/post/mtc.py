"""Fields, cells and pictures of the membrane-truss-cable model's results (ParaView, PNG)."""
from __future__ import annotations

import numpy as np

from tmfem.io.vtk import MembraneField, check_path
from tmfem.models.mtc.topology import to_floating
from tmfem.post.plots import _plt, _save


def membrane_field(model, x: np.ndarray):
    """The membrane of positions x as a :class:`tmfem.io.vtk.MembraneField` with displacement
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
    return MembraneField(mesh=topo.mesh, x=xm, point_data={"displacement_floating": xf - ref},
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
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    verts = np.stack([xf[0, topo.mesh.t].T, xf[1, topo.mesh.t].T], axis=-1)    # (ne, 4, 2)
    for ax, (name, v) in zip(axes, fields):
        pc = PolyCollection(verts, array=v / 1e6, cmap="viridis", edgecolors="none")
        ax.add_collection(pc)
        ax.autoscale_view()
        ax.set_aspect("equal")
        ax.set_xlabel("x_f [m]")
        ax.set_ylabel("y_f [m]")
        ax.set_title(f"{name}: max {v.max() / 1e6:.3f} MPa")
        fig.colorbar(pc, ax=ax, label="MPa", shrink=0.8)
    if title:
        fig.suptitle(title)
    return _save(fig, png)
