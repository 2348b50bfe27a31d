"""Plot of the same deployment on two plants (issue 15; deviations from
:func:`tmfem.control.plant_compare.plant_deviation`)."""
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


def plot_plant_comparison(png, a, b, dev, *, labels=("A", "B"), title: str = "") -> Path:
    """:func:`comparison_figure` written to ``png``."""
    return save_figure(comparison_figure(a, b, dev, labels=labels, title=title), Path(png))


def comparison_figure(a, b, dev, *, labels=("A", "B"), title: str = ""):
    """Six panels over time: the bar attitudes of both runs against the reference, their
    tracking errors q - q_ref, the membrane deflections w_k, the commanded rest lengths and
    each plant's own tendon forces (one tendon of each family; ``tendon_force``: the COM's
    k (|d| - u), an FE plant's elements) and the deviation between the plants (bars [mrad],
    left axis; w [mm], right axis; both logarithmic). Run A solid, run B dashed; a run that
    stopped early is marked."""
    fig = new_figure(figsize=(8.5, 16.5))
    ax = fig.subplots(6, 1, sharex=True)
    names = a.names["q"]
    colours = [f"C{i}" for i in range(10)]
    for i, k in enumerate(_bar_signals(names)):
        c = colours[i % 10]
        ax[0].plot(a.t, np.degrees(a.z[:, k]), "-", color=c, label=f"{names[k]} ({labels[0]})")
        ax[0].plot(b.t, np.degrees(b.z[:, k]), "--", color=c, label=f"{names[k]} ({labels[1]})")
        ax[0].plot(a.t, np.degrees(a.q_d[:, k]), ":", color="k", lw=0.9,
                   label="references (eq. 5.68)" if i == 0 else None)
        ax[1].plot(a.t, 1e3 * (a.z[:, k] - a.q_d[:, k]), "-", color=c, label=f"{names[k]} ({labels[0]})")
        ax[1].plot(b.t, 1e3 * (b.z[:, k] - b.q_d[:, k]), "--", color=c, label=f"{names[k]} ({labels[1]})")
    ax[0].set_ylabel("bar attitude [deg]")
    ax[1].set_ylabel("tracking error q - q_ref [mrad]")
    for i, n in enumerate(a.names["w"]):
        ax[2].plot(a.t, 1e3 * a.w[:, i], "-", color=colours[i], label=f"{n} ({labels[0]})")
        ax[2].plot(b.t, 1e3 * b.w[:, i], "--", color=colours[i], label=f"{n} ({labels[1]})")
    ax[2].set_ylabel("membrane deflection w [mm]")
    seen = {}
    for j, n in enumerate(a.names["tendons"]):
        fam = n.rsplit("_", 1)[0]
        if fam not in seen:
            seen[fam] = j
    for i, (fam, j) in enumerate(seen.items()):
        c = colours[i % 10]
        n = a.names["tendons"][j]
        ax[3].plot(a.t, a.u[:, j], "-", color=c, label=f"rest length {n} ({labels[0]})")
        ax[3].plot(b.t, b.u[:, j], "--", color=c, label=f"rest length {n} ({labels[1]})")
        for r, lab, ls in ((a, labels[0], "-"), (b, labels[1], "--")):
            tf = getattr(r, "tendon_force", None)            # a record without it: no curve
            if tf is not None and tf.size:
                ax[4].plot(r.t, tf[:, j], ls, color=c, label=f"{n} ({lab})")
    ax[3].set_ylabel("commanded rest length [m]")
    ax[4].set_ylabel("tendon force [N]")
    l1, = ax[5].plot(dev["t"], 1e3 * dev["q"], "-", color="C0",
                     label=f"bars: max |q ({labels[1]}) - q ({labels[0]})| [mrad]")
    ax[5].set_ylabel("bar deviation [mrad]", color="C0")
    ax[5].set_yscale("log")
    tw = ax[5].twinx()
    l2, = tw.plot(dev["t"], 1e3 * dev["w"], "-", color="C3",
                  label=f"membrane: max |w ({labels[1]}) - w ({labels[0]})| [mm]")
    tw.set_ylabel("membrane deflection deviation [mm]", color="C3")
    tw.set_yscale("log")
    for x, d in ((ax[5], 1e3 * dev["q"]), (tw, 1e3 * dev["w"])):
        top = float(np.max(d)) if d.size else 0.0
        if top > 0:           # three decades below the largest deviation: the start is exact
            x.set_ylim(1e-3 * top, 2.0 * top)
    tw.legend(handles=[l1, l2], fontsize=7, loc="lower right")   # drawn above both axes
    ax[5].set_xlabel("time [s]")
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
    for x in ax[:5]:
        if x.get_legend_handles_labels()[0]:          # the force panel of a record without forces
            x.legend(fontsize=6, ncol=3)
    for x in ax:
        x.grid(alpha=0.3)
    if title:                 # wrapped to the figure's width: a long title is not cropped
        ax[0].set_title("\n".join(textwrap.fill(line, 105) for line in title.split("\n")),
                        fontsize=9)
    return fig
