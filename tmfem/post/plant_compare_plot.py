"""Plot of the same deployment on two plants (deviations from
:func:`tmfem.control.fe_plant.compare.plant_deviation`)."""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from tmfem.post.plots import new_figure, save_figure


def _bar_signals(names) -> list:
    """Indices of the first bar of every stage's theta and psi (the deployments are
    symmetric: the other bars of a stage move alike)."""
    return [k for k, n in enumerate(names) if n.startswith(("theta_", "psi_")) and n.endswith("1")]


def switch_label_places(times, t_span: float, *, close: float = 0.2) -> list:
    """(height in axes fraction, horizontal alignment) of the labels of the switch times
    ``times`` on an axis from 0 to ``t_span``: a label reads to the left of its line in the
    right half of the axis (and to the right in the left half), so that it stays inside the
    axes; labels of switches less than ``close`` x the span apart go one above the other (two
    switches 0.1 s apart over 20 s would otherwise print over each other)."""
    places, used = [], []
    for t in times:
        ha = "right" if t > 0.5 * t_span else "left"
        level = sum(1 for tu, hu in used if hu == ha and abs(tu - t) < close * t_span)
        places.append((0.02 + 0.09 * level, ha))
        used.append((t, ha))
    return places


def plot_plant_comparison(png, a, b, dev, *, labels=("A", "B"), title: str = "",
                          reference: str = "eq. 5.68") -> Path:
    """:func:`comparison_figure` written to ``png``."""
    return save_figure(comparison_figure(a, b, dev, labels=labels, title=title, reference=reference),
                       Path(png))


def _legend_outside(ax, entries, labels) -> None:
    """The legend of panel ``ax`` to the right of the axes, where it hides no data: one entry
    per signal in its colour (``entries``: (label, colour, line style)), then the line style of
    each plant (``labels``: run A solid, run B dashed)."""
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=c, ls=ls, label=n) for n, c, ls in entries]
    handles += [Line2D([], [], color="k", ls=ls, label=f"{lab} plant")
                for lab, ls in zip(labels, ("-", "--"))]
    ax.legend(handles=handles, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0),
              borderaxespad=0.0)


def comparison_figure(a, b, dev, *, labels=("A", "B"), title: str = "", reference: str = "eq. 5.68"):
    """Seven panels over time: the bar attitudes of both runs against the reference
    (``reference``: its equation), their tracking errors q - q_ref, the membrane deflections
    w_k, the commanded rest lengths and each plant's own tendon forces (one tendon of each
    family; ``tendon_force``: the COM's k (|d| - u), an FE plant's elements), the deviation
    between the plants of the bar angles [mrad] and of the base positions [mm] and that of w
    [mm] (both logarithmic). Colour: the signal; run A solid, run B dashed and drawn above every run-A
    line (a signal of A does not hide another's B); the legends right of the panels (they
    hide no data); a run that stopped early is marked."""
    fig = new_figure(figsize=(10.5, 18))
    ax = fig.subplots(7, 1, sharex=True, height_ratios=[1, 1, 1, 1, 1, 0.7, 0.7])
    names = a.names["q"]
    colors = [f"C{i}" for i in range(10)]
    bars = []
    for i, k in enumerate(_bar_signals(names)):
        c = colors[i % 10]
        bars.append((names[k], c, "-"))
        for r, ls, z in ((a, "-", 2.0), (b, "--", 2.1)):
            ax[0].plot(r.t, np.degrees(r.z[:, k]), ls, color=c, zorder=z)
            ax[1].plot(r.t, 1e3 * (r.z[:, k] - r.q_d[:, k]), ls, color=c, zorder=z)
        ax[0].plot(a.t, np.degrees(a.q_d[:, k]), ":", color="k", lw=0.9)
    _legend_outside(ax[0], bars + [(f"references ({reference})", "k", ":")], labels)
    _legend_outside(ax[1], bars, labels)
    ax[0].set_ylabel("bar attitude [deg]")
    ax[1].set_ylabel("tracking error q - q_ref [mrad]")
    for i, n in enumerate(a.names["w"]):
        for r, ls, z in ((a, "-", 2.0), (b, "--", 2.1)):
            ax[2].plot(r.t, 1e3 * r.w[:, i], ls, color=colors[i % 10], zorder=z)
    _legend_outside(ax[2], [(n, colors[i % 10], "-") for i, n in enumerate(a.names["w"])], labels)
    ax[2].set_ylabel("membrane deflection w [mm]")
    seen = {}
    for j, n in enumerate(a.names["tendons"]):
        seen.setdefault(n.rsplit("_", 1)[0], j)
    for i, j in enumerate(seen.values()):
        for r, ls, z in ((a, "-", 2.0), (b, "--", 2.1)):
            ax[3].plot(r.t, r.u[:, j], ls, color=colors[i % 10], zorder=z)
            tf = getattr(r, "tendon_force", None)       # a record without forces: no curve
            if tf is not None and tf.size:
                ax[4].plot(r.t, tf[:, j], ls, color=colors[i % 10], zorder=z)
    for x, what in ((ax[3], "rest length"), (ax[4], "tendon force")):
        if x.get_lines():                               # the force panel of a record without forces
            _legend_outside(x, [(f"{what} {a.names['tendons'][j]}", colors[i % 10], "-")
                                for i, j in enumerate(seen.values())], labels)
    ax[3].set_ylabel("commanded rest length [m]")
    ax[4].set_ylabel("tendon force [N]")
    vs = f"|{labels[1]} - {labels[0]}|"
    devs = [(ax[5], 1e3 * dev["q"], "C0", f"bar angles: max {vs} [mrad]")]
    if np.isfinite(dev["bases"]).all():
        devs.append((ax[5], 1e3 * dev["bases"], "C1", f"stage bases: max {vs} [mm]"))
    devs.append((ax[6], 1e3 * dev["w"], "C3", f"w_k: max {vs} [mm]"))
    for x in ax[5:]:
        x.set_yscale("log")
    for x, d, c, lab in devs:
        x.plot(dev["t"], d, "-", color=c, label=lab)
    for x in ax[5:]:
        d = np.concatenate([line.get_ydata() for line in x.get_lines()])
        d = d[np.isfinite(d) & (d > 0)]
        if d.size:            # down to the smallest deviation, at most four decades below the
            top = float(d.max())                       # largest (the start is exact: zero)
            x.set_ylim(max(1e-4 * top, 0.5 * float(d.min())), 2.0 * top)
        x.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax[5].set_ylabel("bar deviation\n[mrad, mm]")
    ax[6].set_ylabel("membrane deviation\n[mm]")
    ax[6].set_xlabel("time [s]")
    t_span = max(a.t[-1], b.t[-1])
    switches = [(r.switch_time, lab, ls) for r, lab, ls in ((a, labels[0], "-"), (b, labels[1], "--"))
                if r.switch_time is not None]
    for (t_s, lab, ls), (y, ha) in zip(switches, switch_label_places([t for t, _, _ in switches], t_span)):
        for x in ax:
            x.axvline(t_s, color="k", ls=ls, lw=0.7)
        ax[0].annotate(f"switch {lab} {t_s:.2f} s", (t_s, y), xycoords=("data", "axes fraction"),
                       xytext=(-3 if ha == "right" else 3, 0), textcoords="offset points",
                       fontsize=7, ha=ha, va="bottom",
                       bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 0.5})
    for r, lab, ls in ((a, labels[0], "-"), (b, labels[1], "--")):
        if r.failure:
            for x in ax:
                x.axvline(r.t[-1], color="r", ls=ls, lw=0.9)
            early = r.t[-1] < 0.5 * max(a.t[-1], b.t[-1])
            ax[0].annotate(f" {lab} stopped at {r.t[-1]:.2f} s (Newton failed) ", (r.t[-1], 0.5),
                           xycoords=("data", "axes fraction"), fontsize=7, color="r",
                           ha="left" if early else "right",
                           bbox={"fc": "white", "ec": "none", "alpha": 0.8}, zorder=10)
    for x in ax:
        x.grid(alpha=0.3)
    if title:                 # wrapped to the figure's width: a long title is not cropped
        fig.suptitle("\n".join(textwrap.fill(line, 130) for line in title.split("\n")),
                     fontsize=9)
    return fig
