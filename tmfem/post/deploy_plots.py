"""Plots and animation of a deployment run (dissertation Figures 7.2-7.5).

``result`` is a :class:`tmfem.control.deployment.run.DeploymentResult` (read by attribute: t, z, q_d,
w, u, lengths, switch_time, names).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tmfem.post.plots import new_figure, save_figure


def _family(name: str) -> str:
    """The coordinate family of a bar coordinate: ``theta_12`` -> ``theta``, ``x_21`` -> ``x``."""
    return name.rsplit("_", 1)[0]


def _is_angle(family: str) -> bool:
    return family in ("theta", "psi", "phi")


def plot_deployment(png, result, *, title: str = "", coordinates=None) -> Path:
    """The deployment run, one panel per coordinate family and one for the tracking error.

    Panels: each family of the tracked bar coordinates (theta_ij, psi_ij in degrees; x, y, z
    in metres) against its reference (Figures 7.2, 8.2; eqs. 5.68, 5.100); the tracking error
    q - q_d of every tracked coordinate; the membrane deflections w_k (Figures 7.3, 8.3) with
    their largest excursion marked; rest lengths against their limits, the tendon lengths
    (Figures 7.4, 8.4). The switch to the linear controller is a dashed line in every panel.

    Parameters
    ----------
    png : str or Path
    result : DeploymentResult
    title : str
    coordinates : list of str, optional
        The bar coordinates to draw (default every coordinate whose reference moves).
    """
    r = result
    names = list(r.names["q"])
    if coordinates is None:
        moving = np.ptp(r.q_d[:, :len(names)], axis=0) > 1e-9
        coordinates = [n for n, m in zip(names, moving) if m] or names
    idx = [names.index(n) for n in coordinates]
    families = list(dict.fromkeys(_family(names[k]) for k in idx))
    n_panels = len(families) + 3
    fig = new_figure(figsize=(8, 2.4 * n_panels + 0.6))
    ax = fig.subplots(n_panels, 1, sharex=True)
    for a, fam in zip(ax, families):
        conv, unit = (np.degrees, "deg") if _is_angle(fam) else ((lambda v: v), "m")
        first = True
        for k in idx:
            if _family(names[k]) != fam:
                continue
            a.plot(r.t, conv(r.z[:, k]), lw=1.4, label=names[k])
            a.plot(r.t, conv(r.q_d[:, k]), ":", color="k", lw=0.9,
                   label="reference" if first else None)
            first = False
        a.set_ylabel(f"{fam} [{unit}]")
        a.legend(fontsize=7, ncol=min(4, len(idx) + 1), loc="best")
    _tracking_error(ax[len(families)], r, idx, names)
    _deflections(ax[-2], r)
    _rest_lengths(ax[-1], r)
    if r.switch_time is not None:
        for a in ax:
            a.axvline(r.switch_time, color="k", ls="--", lw=0.8)
        ax[0].text(r.switch_time, 0.97, f" switch to the linear controller, {r.switch_time:.2f} s",
                   transform=ax[0].get_xaxis_transform(), fontsize=8, va="top", ha="left",
                   bbox=dict(facecolor="white", edgecolor="none", alpha=0.8, pad=1))
    for a in ax:
        a.grid(alpha=0.3)
    if title:
        ax[0].set_title(title)
    return save_figure(fig, Path(png))


def _tracking_error(ax, r, idx, names) -> None:
    """q - q_d of the tracked coordinates: degrees for angles, millimetres for positions."""
    for k in idx:
        fam = _family(names[k])
        e = r.z[:, k] - r.q_d[:, k]
        if _is_angle(fam):
            ax.plot(r.t, np.degrees(e), lw=1.0, label=f"{names[k]} [deg]")
        else:
            ax.plot(r.t, 1e3 * e, lw=1.0, ls="--", label=f"{names[k]} [mm]")
    ax.set_ylabel("tracking error q - q_d")
    ax.legend(fontsize=7, ncol=4, loc="lower right")


def _deflections(ax, r) -> None:
    """w_k [mm] against time (Figures 7.3, 8.3), the largest excursion marked and, where it
    follows the switch to the linear controller within 2 s, said to be its transient."""
    for k, n in enumerate(r.names["w"]):
        ax.plot(r.t, 1e3 * r.w[:, k], label=n)
    ax.set_ylabel("membrane deflection w [mm]")
    if r.w.size:
        i, k = np.unravel_index(np.argmax(np.abs(r.w)), r.w.shape)
        t_peak, w_peak = float(r.t[i]), 1e3 * float(r.w[i, k])
        text = f"largest |w|: {abs(w_peak):.3g} mm ({r.names['w'][k]}) at {t_peak:.2f} s"
        if r.switch_time is not None and 0.0 <= t_peak - r.switch_time <= 2.0:
            text += f",\n{t_peak - r.switch_time:.2f} s after the switch: its transient"
        ax.annotate(text, (t_peak, w_peak), xytext=(0.02, 0.95), textcoords="axes fraction",
                    fontsize=8, va="top", arrowprops=dict(arrowstyle="->", lw=0.7),
                    bbox=dict(facecolor="white", edgecolor="none", alpha=0.8, pad=1))
        ax.legend(fontsize=8, loc="lower right")


def _rest_lengths(ax, r) -> None:
    """One tendon of each family: rest length and its limit, the tendon length (Figures 7.4, 8.4)."""
    seen = set()
    for k, n in enumerate(r.names["tendons"]):
        fam = n.rsplit("_", 1)[0]
        if fam in seen:
            continue
        seen.add(fam)
        ln, = ax.plot(r.t, r.u[:, k], label=f"rest length {n}")
        ax.plot(r.t, r.lengths[:, k], ":", color=ln.get_color(), label=f"limit |{n}|")
    ax.set_ylabel("length [m]")
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=7, ncol=2)


def plot_lpv_deployment(png, result, *, title: str = "") -> Path:
    """Figures 8.2-8.4: :func:`plot_deployment` on the attitudes of bars b_11, b_21 and the
    position of b_21's lower end A_21, tracked against the references of eq. 5.100."""
    return plot_deployment(png, result, title=title,
                           coordinates=["theta_11", "psi_11", "theta_21", "psi_21", "x_21", "y_21", "z_21"])


def membrane_frames(model, result, idx) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The deflected membrane of the run at samples ``idx`` from the recorded state z through
    the control-oriented model's field (eqs. 5.1, 5.3,
    :meth:`~tmfem.models.com.model.ControlOrientedModel.membrane_positions`): static corner
    shapes and the K relative modes at the modal coordinates eta of z. On a finite-element
    plant z is its measured state, so this is the FE membrane projected on the model's basis.

    Returns
    -------
    x : ndarray (n, 3, n_nodes)
        Node positions of the membrane's FE mesh in the inertial frame.
    d : ndarray (n, 3, n_nodes)
        Deflections u, v, w in O_f.
    normal : ndarray (n, 3)
        The z axis of O_f in the inertial frame (the rotation that carries the O_f positions
        onto x, a least-squares fit that is exact for this rigid placement).
    """
    P0 = model.membrane.shapes[0]
    xs, ds, ns = [], [], []
    for k in idx:
        x, d = model.membrane_positions(result.z[k])
        xs.append(x)
        ds.append(d)
        ns.append(_rotation(P0 + d, x)[:, 2])
    return np.array(xs), np.array(ds), np.array(ns)


def deflection_scale(system, w_max: float) -> float:
    """Drawing factor of the transverse membrane deflection: the largest |w| drawn as 4 % of
    the plan size of the membrane (at least 1, a power of ten times 1, 2 or 5)."""
    c = system.membrane_corners_inertial(system.q)
    plan = float(np.max(np.ptp(c[:2], axis=1)))
    if not w_max > 0:
        return 1.0
    f = max(1.0, 0.04 * plan / w_max)
    e = 10.0 ** np.floor(np.log10(f))
    return float(max(m * e for m in (1, 2, 5) if m * e <= f))


def animate_deployment(gif, model, result, *, frames: int = 40) -> Path:
    """GIF of the bars (thick), tendons (thin) and the deflected membrane over the run
    (Figures 7.5, 7.9, 7.14), with matplotlib's pillow writer.

    The membrane is the control-oriented model's field (:func:`membrane_frames`, eqs. 5.1,
    5.3) on its FE mesh, coloured by the transverse deflection w in O_f [mm] (one colour bar
    over the run), its deflection drawn enlarged by the factor of :func:`deflection_scale`
    (stated in the legend). Equal x/y scales, the z axis at least 30 % of the plan size.

    Parameters
    ----------
    gif : str or Path
    model : ControlOrientedModel
        The controller's model of the run (its system, membrane basis and coordinates z).
    result : DeploymentResult
    frames : int
    """
    from matplotlib import colormaps
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D
    r = result
    system = model.system
    nq = len(r.names["q"])
    idx = np.linspace(0, r.t.size - 1, frames).astype(int)
    Xs = [system.nodes(r.z[k, :nq]) for k in idx]
    XM, D, normals = membrane_frames(model, r, idx)
    w = D[:, 2, :]
    scale = deflection_scale(system, float(np.max(np.abs(w))))
    # the drawn membrane: its transverse deflection enlarged along the z axis of O_f
    XM = XM + (scale - 1.0) * w[:, None, :] * normals[:, :, None]
    tri = _triangles(model.membrane.mesh.t)
    allX = np.concatenate(Xs + list(XM), axis=1)
    lo, hi = allX.min(axis=1), allX.max(axis=1)
    box = hi - lo
    box[2] = max(box[2], 0.3 * box[:2].max())      # a flat system keeps a readable z axis
    wmm = 1e3 * w
    lim = float(np.max(np.abs(wmm))) or 1.0
    norm, cmap = Normalize(-lim, lim), colormaps["coolwarm"]
    fig = new_figure(figsize=(6.4, 5.6))
    ax = fig.add_subplot(projection="3d")
    from matplotlib.cm import ScalarMappable
    fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.6, pad=0.12,
                 label="membrane deflection w in O_f [mm]")
    bars, tends = system.bar_connectivity, system.tendon_connectivity
    legend = [Line2D([], [], color="saddlebrown", lw=3, label="bar"),
              Line2D([], [], color="tab:blue", lw=0.8, label="tendon"),
              Line2D([], [], color="0.5", lw=0, marker="s", ms=8,
                     label=f"membrane, deflection x {scale:g}")]

    # the axes, lines, legend and layout are made once; a frame moves the lines and redraws
    # the membrane and the title (the limits are those of the whole run)
    X0 = Xs[0]
    bar_lines = [ax.plot(*X0[:, [a, b]], color="saddlebrown", lw=3)[0] for a, b in bars.T]
    tendon_lines = [ax.plot(*X0[:, [a, b]], color="tab:blue", lw=0.8)[0] for a, b in tends.T]
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_autoscale_on(False)
    ax.set_box_aspect(box, zoom=0.8)
    ax.locator_params(axis="z", nbins=3)
    for axis, lab in ((ax.xaxis, "x [m]"), (ax.yaxis, "y [m]"), (ax.zaxis, "z [m]")):
        axis.set_label_text(lab)
        axis.labelpad = 10
    ax.tick_params(labelsize=7, pad=2)
    ax.legend(handles=legend, loc="upper left", fontsize=7, frameon=False)
    surface = []

    def draw(i):
        if i == 1:
            # the first frame was saved with the constrained layout (at the writer's dpi):
            # the later ones keep it
            fig.set_layout_engine("none")
        X = Xs[i]
        for line, (a, b) in zip(bar_lines, bars.T):
            line.set_data_3d(*X[:, [a, b]])
        for line, (a, b) in zip(tendon_lines, tends.T):
            line.set_data_3d(*X[:, [a, b]])
        if surface:
            surface.pop().remove()
        surf = ax.plot_trisurf(XM[i, 0], XM[i, 1], XM[i, 2], triangles=tri, linewidth=0,
                               antialiased=False, shade=False)
        surf.set_facecolor(cmap(norm(wmm[i][tri].mean(axis=1))))
        surface.append(surf)
        ax.set_title(f"{system.name} deployment, t = {r.t[idx[i]]:.2f} s\ncontroller: "
                     f"{r.controller[min(idx[i], len(r.controller) - 1)]}", fontsize=10)

    anim = FuncAnimation(fig, draw, frames=len(idx))
    anim.save(str(gif), writer=PillowWriter(fps=8))
    return Path(gif)


def _triangles(quads) -> np.ndarray:
    """Two triangles per quadrilateral (4, n_el) of the membrane mesh: (2 n_el, 3)."""
    q = np.asarray(quads).T
    return np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])


def _rotation(a, b) -> np.ndarray:
    """The rotation R (3, 3) with b - mean(b) ~ R (a - mean(a)) in least squares (Kabsch)."""
    H = (a - a.mean(axis=1, keepdims=True)) @ (b - b.mean(axis=1, keepdims=True)).T
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0
    return Vt.T @ np.diag([1.0, 1.0, d]) @ U.T
