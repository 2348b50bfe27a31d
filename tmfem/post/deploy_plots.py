"""Plots and animation of a deployment run (dissertation Figures 7.2-7.5).

``result`` is a :class:`tmfem.control.deployment.run.DeploymentResult` (read by attribute: t, z, q_d,
w, u, lengths, switch_time, names).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tmfem.post.plots import new_figure, save_figure


def plot_deployment(png, result, *, title: str = "") -> Path:
    """Three panels: bar attitudes theta_1j, psi_1j against their references (Fig. 7.2), the
    membrane deflections w_1..w_3 (Fig. 7.3), rest lengths against their limits (the tendon
    lengths, Fig. 7.4); the switching time as a dashed line."""
    r = result
    fig = new_figure(figsize=(8, 10))
    ax = fig.subplots(3, 1, sharex=True)
    names = r.names["q"]
    sel = [k for k, n in enumerate(names) if n.startswith(("theta_1", "psi_1"))][:4]
    # bars 1 and 2 of a symmetric deployment move alike: bar 1 wide and pale under bar 2
    for i, k in enumerate(sel):
        first = i < 2
        ln, = ax[0].plot(r.t, np.degrees(r.z[:, k]), lw=4.0 if first else 1.4,
                         alpha=0.45 if first else 1.0, label=names[k])
        ax[0].plot(r.t, np.degrees(r.q_d[:, k]), ":", color="k", lw=0.9,
                   label="references (eq. 5.68)" if i == 0 else None)
    ax[0].set_ylabel("bar attitude [deg]")
    ax[0].legend(fontsize=7, ncol=3)
    _deflections(ax[1], r)
    _rest_lengths(ax[2], r)
    if r.switch_time is not None:
        for a in ax:
            a.axvline(r.switch_time, color="k", ls="--", lw=0.8)
        ax[0].annotate(f"switch {r.switch_time:.2f} s", (r.switch_time, ax[0].get_ylim()[1]),
                       fontsize=8, va="top")
    for a in ax:
        a.grid(alpha=0.3)
    if title:
        ax[0].set_title(title)
    return save_figure(fig, Path(png))


def _deflections(ax, r) -> None:
    """w_1..w_3 [mm] against time (Figures 7.3, 8.3)."""
    for k, n in enumerate(r.names["w"]):
        ax.plot(r.t, 1e3 * r.w[:, k], label=n)
    ax.set_ylabel("membrane deflection w [mm]")
    ax.legend(fontsize=8)


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
    """Figures 8.2-8.4: the attitudes (theta, psi) of bars b_11 and b_21 and the position
    (x, y, z) of b_21's lower end A_21 against their references (eq. 5.100), the membrane
    deflections w_1..w_3, rest lengths against their limits (the tendon lengths)."""
    r = result
    fig = new_figure(figsize=(8, 12))
    ax = fig.subplots(4, 1, sharex=True)
    names = r.names["q"]
    for a, keys, scale, unit in ((ax[0], ("theta_11", "psi_11", "theta_21", "psi_21"), np.degrees, "deg"),
                                 (ax[1], ("x_21", "y_21", "z_21"), lambda v: v, "m")):
        for i, n in enumerate(keys):
            k = names.index(n)
            a.plot(r.t, scale(r.z[:, k]), label=n)
            a.plot(r.t, scale(r.q_d[:, k]), ":", color="k", lw=0.9,
                   label="references (eq. 5.100)" if i == 0 else None)
        a.set_ylabel(f"bars b_11, b_21 [{unit}]")
        a.legend(fontsize=7, ncol=3)
    _deflections(ax[2], r)
    _rest_lengths(ax[3], r)
    for a in ax:
        a.grid(alpha=0.3)
    if title:
        ax[0].set_title(title)
    return save_figure(fig, Path(png))


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
