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


def animate_deployment(gif, system, result, *, frames: int = 40) -> Path:
    """GIF of the bars (thick), tendons (thin) and the membrane polygon (flat, its corners)
    over the run (Figures 7.5, 7.9, 7.14), with matplotlib's pillow writer; equal x/y scales,
    the z axis at least 30 % of the plan size."""
    from matplotlib.animation import FuncAnimation, PillowWriter
    r = result
    nq = len(r.names["q"])
    idx = np.linspace(0, r.t.size - 1, frames).astype(int)
    Xs = [system.nodes(r.z[k, :nq]) for k in idx]
    Cs = [system.membrane_corners_inertial(r.z[k, :nq]) for k in idx]
    allX = np.concatenate(Xs, axis=1)
    lo, hi = allX.min(axis=1), allX.max(axis=1)
    box = hi - lo
    box[2] = max(box[2], 0.3 * box[:2].max())      # a flat system keeps a readable z axis
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    fig = new_figure(figsize=(6.0, 5.5))
    ax = fig.add_subplot(projection="3d")
    bars, tends = system.bar_connectivity, system.tendon_connectivity
    legend = [Line2D([], [], color="saddlebrown", lw=3, label="bar"),
              Line2D([], [], color="tab:blue", lw=0.8, label="tendon"),
              Patch(color="gold", alpha=0.4, label="membrane (corner polygon)")]

    def draw(i):
        ax.cla()
        X = Xs[i]
        for a, b in bars.T:
            ax.plot(*X[:, [a, b]], color="saddlebrown", lw=3)
        for a, b in tends.T:
            ax.plot(*X[:, [a, b]], color="tab:blue", lw=0.8)
        C = Cs[i]
        ax.plot_trisurf(C[0], C[1], C[2], color="gold", alpha=0.4)
        ax.set_xlim(lo[0], hi[0]); ax.set_ylim(lo[1], hi[1]); ax.set_zlim(lo[2], hi[2])
        ax.set_box_aspect(box, zoom=0.85)
        ax.locator_params(axis="z", nbins=3)
        ax.set_xlabel("x [m]"); ax.set_ylabel("y [m]"); ax.set_zlabel("z [m]")
        ax.legend(handles=legend, loc="upper left", fontsize=7, frameon=False)
        ax.set_title(f"{system.name} deployment, t = {r.t[idx[i]]:.2f} s\ncontroller: "
                     f"{r.controller[min(idx[i], len(r.controller) - 1)]}", fontsize=10)
    anim = FuncAnimation(fig, draw, frames=len(idx))
    anim.save(str(gif), writer=PillowWriter(fps=8))
    return Path(gif)
