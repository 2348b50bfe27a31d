"""Off-screen pictures of tensegrity-membrane systems and their mode shapes (pyvista).

Bars are thick black tubes, tendons blue tubes whose colour and width follow the tendon
force (slack tendons thin and red), the membrane a surface coloured by a field when one is
given. Everything renders off screen, so it works on a machine without a display.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from tmfem.errors import InputError
from tmfem.io.codes import KIND_CODES
from tmfem.io.fields import MembraneField
from tmfem.io.meshes import configuration_mesh, modes_mesh
from tmfem.io.paths import check_path

BACKGROUND = "white"


def _pv():
    import pyvista as pv
    import vtk

    vtk.vtkObject.GlobalWarningDisplayOff()
    pv.OFF_SCREEN = True
    return pv


def _tendon_cmap():
    from matplotlib.colors import LinearSegmentedColormap
    return LinearSegmentedColormap.from_list("tendon", ["#9ecae1", "#2171b5", "#08306b"])


def _part(pv, grid, kind: str):
    """The cells of ``grid`` (read from a configuration's meshio.Mesh) whose cell data
    ``kind`` is ``kind`` (bar, tendon, membrane), as a grid of their own."""
    ids = np.flatnonzero(np.asarray(grid.cell_data["kind"]) == KIND_CODES[kind])
    return grid.extract_cells(ids)


def _trim(img: np.ndarray, *, pad: int = 12) -> np.ndarray:
    """``img`` without the rows and columns of background around its content (``pad``
    pixels of it kept), so that no picture has an empty band."""
    ink = np.any(img[..., :3] != img[0, 0, :3], axis=-1)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if rows.size == 0:
        return img
    r0, r1 = max(rows[0] - pad, 0), min(rows[-1] + pad + 1, img.shape[0])
    c0, c1 = max(cols[0] - pad, 0), min(cols[-1] + pad + 1, img.shape[1])
    return img[r0:r1, c0:c1]


def _screenshot(plotter, png_path: Path) -> Path:
    from PIL import Image

    img = plotter.screenshot(return_img=True)
    plotter.close()
    if img is None or img.size == 0:
        raise RuntimeError(f"pyvista rendered no image for {png_path}")
    Image.fromarray(_trim(np.asarray(img))).save(png_path)
    return png_path


def _scalar_bar(title: str, *, position_x: float) -> dict:
    """Arguments of a vertical colour bar at ``position_x`` (tendons right, membrane left)."""
    return {"title": title, "color": "black", "fmt": "%.3g", "vertical": True,
            "position_x": position_x, "position_y": 0.1, "width": 0.05, "height": 0.5,
            "title_font_size": 14, "label_font_size": 12}


def _robust_range(v: np.ndarray) -> list:
    """Colour range of a membrane field: [min, max], or [min, 98th percentile] when a few
    elements (the point-attached corners, where stresses are singular) exceed the
    percentile by more than half of it, so that the rest of the field stays readable."""
    v = v[np.isfinite(v)]
    if v.size == 0:
        return [0.0, 1.0]
    lo, hi, top = float(v.min()), float(np.percentile(v, 98)), float(v.max())
    if top - lo > 1.5 * (hi - lo) and hi > lo:
        return [lo, hi]
    return [lo, top] if top > lo else [lo, lo + 1.0]


_STRESS_NAMES = ("von_mises", "sigma_p1", "sigma_p2", "sigma_xf", "sigma_yf", "tau_xfyf")


def _is_stress(name: str) -> bool:
    """Membrane stress fields (Pa in the data, shown in MPa)."""
    return name.startswith(_STRESS_NAMES)


def _unit_of(name: str) -> str:
    return "m" if "displacement" in name or "deflection" in name else ""


def render_configuration(png_path, system, *, q=None, tendon_forces=None, membrane=None,
                         title=None, window_size=(1200, 900), membrane_field: str | None = None,
                         labels: bool | None = None) -> Path:
    """Render a configuration of ``system`` to a PNG, off screen.

    Parameters
    ----------
    png_path : str or Path
        Output ``.png``.
    system : System
    q : ndarray, optional
        Generalised coordinates (eqs. 3.1-3.2); default ``system.q``.
    tendon_forces : ndarray (n_tendons,), optional
        Tendon forces [N]: colour and width of the tendons, slack (<= 0) ones in red.
    membrane : MembraneField, optional
        The membrane mesh in its current position; without it the membrane polygon
        B_M1..B_MN is drawn.
    title : str, optional
    window_size : (int, int)
    membrane_field : str, optional
        Name of a cell or point array of ``membrane`` to colour the membrane by; default
        the first cell array, if any.
    labels : bool, optional
        Draw node labels A_ij, B_ij, H_1j (default: when there are at most 40 nodes).
    """
    png_path = check_path(png_path, suffixes=(".png",))
    if membrane is not None and not isinstance(membrane, MembraneField):
        raise InputError(f"membrane: expected a MembraneField, found {type(membrane).__name__}")
    pv = _pv()
    X = system.nodes(q)
    # the picture is drawn from the same meshio.Mesh that write_configuration writes
    grid = pv.from_meshio(configuration_mesh(system, q=q, tendon_forces=tendon_forces,
                                             membrane=membrane))
    size = float(np.ptp(X, axis=1).max()) or 1.0
    r_bar = 0.009 * size
    r_ten = 0.0035 * size

    p = pv.Plotter(off_screen=True, window_size=list(window_size))
    p.set_background(BACKGROUND)
    legend = [["bar", "black"]]       # an entry for each part drawn in one colour
    p.add_mesh(_part(pv, grid, "bar").extract_surface(algorithm=None).tube(radius=r_bar, n_sides=16),
               color="black", smooth_shading=True)

    tendons = _part(pv, grid, "tendon")
    if tendon_forces is None:
        p.add_mesh(tendons.extract_surface(algorithm=None).tube(radius=r_ten, n_sides=12), color="#2171b5",
                   smooth_shading=True)
        legend.append(["tendon", "#2171b5"])
    else:
        f = np.asarray(tendons.cell_data["axial_force"], dtype=float)
        taut = f > 0
        fmax = float(f[taut].max()) if np.any(taut) else 1.0
        if np.any(taut):
            # one tube per tendon so that the width follows its force (n_tendons is small)
            tubes = []
            for k in np.nonzero(taut)[0]:
                tube = tendons.extract_cells([k]).extract_surface(algorithm=None).tube(
                    radius=r_ten * (0.5 + 1.0 * f[k] / fmax), n_sides=12)
                tube.point_data["tendon force [N]"] = np.full(tube.n_points, f[k])
                tubes.append(tube)
            merged = tubes[0].merge(tubes[1:]) if len(tubes) > 1 else tubes[0]
            # colour scale from zero: nearly equal forces look equal, not noise-amplified
            p.add_mesh(merged, scalars="tendon force [N]", cmap=_tendon_cmap(),
                       clim=[0.0, fmax], smooth_shading=True,
                       scalar_bar_args=_scalar_bar("tendon force [N]", position_x=0.86))
        if np.any(~taut):
            slack = tendons.extract_cells(np.flatnonzero(~taut)).extract_surface(algorithm=None)
            p.add_mesh(slack.tube(radius=0.8 * r_ten, n_sides=8), color="#e41a1c", ambient=0.6)
            legend.append(["tendon (slack)", "#e41a1c"])

    mem = _part(pv, grid, "membrane")
    if membrane is not None:
        name = membrane_field
        if name is None and membrane.cell_data:
            name = next(iter(membrane.cell_data))
        if name is not None:
            if name not in membrane.cell_data and name not in membrane.point_data:
                raise InputError(f"membrane_field {name!r}: expected one of "
                                 f"{sorted(membrane.cell_data) + sorted(membrane.point_data)}")
            vals = np.asarray(mem[name], dtype=float)
            vals = vals if vals.ndim == 1 else np.linalg.norm(vals, axis=1)
            scale, unit = (1e-6, "MPa") if _is_stress(name) else (1.0, _unit_of(name))
            shown = f"{name} [{unit}]" if unit else name
            if name in membrane.cell_data:
                mem.cell_data[shown] = vals * scale
            else:
                mem.point_data[shown] = vals * scale
            clim = _robust_range(vals * scale)
            bar_title = shown + ("\nelement values" if name in membrane.cell_data else "")
            if clim[1] < np.nanmax(vals * scale):
                # a few corner elements (singular point attachment) lie above the range
                bar_title += f"\n(max {np.nanmax(vals * scale):.3g} at corners)"
            p.add_mesh(mem, scalars=shown, cmap="viridis", opacity=0.9, show_edges=True,
                       edge_color="#555555", line_width=0.5, clim=clim,
                       scalar_bar_args=_scalar_bar(bar_title, position_x=0.04))
        else:
            p.add_mesh(mem, color="#f4c27a", opacity=0.75, show_edges=True,
                       edge_color="#9a6a2a", line_width=0.5)
            legend.append(["membrane", "#f4c27a"])
    else:
        p.add_mesh(mem, color="#f4c27a", opacity=0.6, show_edges=True, edge_color="#9a6a2a")
        legend.append(["membrane", "#f4c27a"])

    p.add_mesh(pv.PolyData(np.ascontiguousarray(X.T)), color="black", point_size=8,
               render_points_as_spheres=True)
    if labels is None:
        labels = X.shape[1] <= 40
    if labels:
        # labels a little above their node, so the node marker does not hide them
        at = X + np.array([[0.0], [0.0], [0.025 * size]])
        p.add_point_labels(np.ascontiguousarray(at.T), system.node_labels, font_size=11,
                           point_size=1, shape="rounded_rect", shape_color="white",
                           shape_opacity=0.7, text_color="#222222", always_visible=True,
                           show_points=False)
    if title:
        p.add_text(title, position="upper_edge", font_size=12, color="black")
    p.add_legend(legend, bcolor="white", border=True, size=(0.2, 0.035 * len(legend)),
                 loc="upper left", face="rectangle")    # text may run past its box: into the picture
    _set_view(p, X)
    p.camera.zoom(1.1)          # reset_camera frames the model; 1.3 cropped the 2-3's lowest node
    return _screenshot(p, png_path)


VIEW_DIRECTION = np.array([0.8, -1.5, 0.75])   # from the focal point toward the camera


def _set_view(plotter, X: np.ndarray) -> None:
    """Oblique view from the front right and above, z up, the whole model in frame."""
    c = 0.5 * (X.min(axis=1) + X.max(axis=1))
    d = VIEW_DIRECTION / np.linalg.norm(VIEW_DIRECTION)
    size = float(np.ptp(X, axis=1).max()) or 1.0
    plotter.camera_position = [tuple(c + 3 * size * d), tuple(c), (0.0, 0.0, 1.0)]
    plotter.reset_camera()


def _mode_scale(points: np.ndarray, shape: np.ndarray) -> float:
    """Scale making the largest displacement 15% of the model's size."""
    size = float(np.ptp(points, axis=1).max()) or 1.0
    amax = float(np.linalg.norm(shape.reshape(-1, 3), axis=1).max())
    return 0.15 * size / amax if amax > 0 else 0.0


def render_modes(png_path, *, points, cells, shapes, freq_hz, k: int = 6,
                 scale: float | None = None, title: str | None = None,
                 window_size=None) -> Path:
    """Render the first ``k`` mode shapes in a grid of views, off screen.

    Each panel is a pyvista view of one mode (the prestressed state in grey, the displaced
    shape coloured by |u| / max |u|); matplotlib lays the panels out with their titles (mode,
    frequency and drawing scale), one shared colour bar and the caption, so that nothing
    overlaps or is cropped.

    Parameters
    ----------
    points : ndarray (3, n)
        Prestressed positions about which the modes are computed.
    cells : dict or list of (type, connectivity (nv, n_cells))
        As for :func:`tmfem.io.write_modes`.
    shapes : ndarray (3 n, kk)
        Node-interleaved mode shapes (dof = 3 node + component), kk >= k.
    freq_hz : ndarray (kk,)
    k : int
        Number of modes drawn.
    scale : float, optional
        Displacement scale; default makes each mode's largest displacement 15% of the
        model size (the factor is printed in each panel's title).
    title : str, optional
        Caption above the panels.
    window_size : (int, int), optional
        Pixel size of the whole picture (default 500 x 420 per panel).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    png_path = check_path(png_path, suffixes=(".png",))
    pv = _pv()
    # drawn from the same meshio.Mesh that write_modes writes (checks included)
    mesh = modes_mesh(points, cells, shapes, freq_hz)
    f = mesh.field_data["frequency_hz"]
    X = mesh.points.T
    if not (isinstance(k, (int, np.integer)) and 1 <= k <= f.size):
        raise InputError(f"k: expected 1 <= k <= {f.size} modes, found {k!r}")
    cols = min(k, 3 if k <= 6 else 4)
    rows = math.ceil(k / cols)
    if window_size is None:
        window_size = (500 * cols, 420 * rows)
    panel = (int(window_size[0] // cols), int(window_size[1] // rows))
    base = pv.from_meshio(mesh)
    dpi = 100
    fig, axes = plt.subplots(rows, cols, figsize=(window_size[0] / dpi, window_size[1] / dpi + 0.9),
                             dpi=dpi, squeeze=False, layout="constrained")
    for m, ax in enumerate(axes.ravel()):
        ax.set_axis_off()
        if m >= k:
            continue
        u = mesh.point_data[f"mode_{m + 1}"].T
        s = _mode_scale(X, u.T.ravel()) if scale is None else float(scale)
        g = base.copy()
        g.points = base.points + s * u.T
        mag = np.linalg.norm(u, axis=0)
        g.point_data["|u| / max |u|"] = mag / (mag.max() or 1.0)
        p = pv.Plotter(off_screen=True, window_size=list(panel), border=False)
        p.set_background(BACKGROUND)
        p.add_mesh(base, color="#bbbbbb", style="wireframe", line_width=1)
        p.add_mesh(g, scalars="|u| / max |u|", cmap="plasma", clim=[0.0, 1.0], line_width=3,
                   show_edges=False, show_scalar_bar=False)
        _set_view(p, X)
        p.camera.zoom(1.25)
        ax.imshow(_trim(np.asarray(p.screenshot(return_img=True))))
        p.close()
        ax.set_title(f"mode {m + 1}: {f[m]:.4g} Hz  (shape x {s:.3g})", fontsize=11)
    fig.colorbar(ScalarMappable(Normalize(0.0, 1.0), "plasma"), ax=axes, location="bottom",
                 shrink=0.4, aspect=40, label="|u| / max |u| of each mode (grey: the prestressed state)")
    caption = "mode shapes drawn with their largest displacement at 15 % of the model size" \
        if scale is None else f"mode shapes drawn at scale {float(scale):.3g}"
    fig.suptitle(f"{title}\n{caption}" if title else caption, fontsize=12)
    fig.savefig(png_path, dpi=dpi, bbox_inches="tight", pad_inches=0.15)   # nothing cropped at the edges
    plt.close(fig)
    if not png_path.is_file() or png_path.stat().st_size == 0:
        raise RuntimeError(f"matplotlib wrote no image to {png_path}")
    return png_path
