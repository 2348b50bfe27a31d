"""Figures of the three-model comparisons (6.4, 6.5): frequencies beside Tables 6.6/6.7 and
free-vibration histories overlaid (:mod:`tmfem.reference.model_compare`,
:mod:`tmfem.reference.vibration_compare`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tmfem.post.plots import new_figure, save_figure

#: colour per model (the SBC reference drawn first and thickest)
MODEL_COLORS = {"SBC": "black", "MTC": "tab:blue", "COM": "tab:orange"}


def plot_model_frequencies(png, r: dict) -> Path:
    """Top: the frequencies of the models compared (``r["ours"]``: all three, or the SBC and
    COM models of a 1-N(D) system, the model left out named in the title) per mode (ours:
    filled, printed: open markers); bottom: each model against the SBC model [%] (ours solid,
    printed dashed) with the bound 6.4 states. A system without printed frequencies gets its
    own models only.
    With ``r["mode_pairs"]`` (:func:`tmfem.reference.model_compare.paired_modes`) ours are the
    differences of the modes paired by shape, at the SBC mode's number (a gap where it has no
    counterpart); the printed ones are by order, as the tables."""
    fig = new_figure(figsize=(8.0, 6.5))
    ax, bx = fig.subplots(2, 1, sharex=True)
    printed = r.get("printed")
    n = len(printed["SBC"]) if printed else len(r["ours"]["SBC"])
    k = np.arange(1, n + 1)
    models = [m for m in MODEL_COLORS if m in r["ours"]]
    for m in models:
        c = MODEL_COLORS[m]
        ax.plot(k, r["ours"][m][:n], "o-", color=c, ms=5, lw=1, label=f"{m} ours" if printed else m)
        if printed:
            ax.plot(k, printed[m], "s", mfc="none", color=c, ms=8, label=f"{m} printed")
    ax.set_ylabel("natural frequency [Hz]")
    left_out = r.get("left_out") or {}
    ax.set_title(f"{r['system']}: " + (" and ".join(models) if left_out else "three") + " models"
                 + (f" beside {r['source']}" if printed else "")
                 + "".join(f" ({m} left out: it cannot represent this system)" for m in left_out), fontsize=10)
    ax.legend(fontsize=7, ncol=3, loc="upper left")
    ax.grid(True, alpha=0.3)
    pairs = r.get("mode_pairs")
    for m in models[1:]:
        c = MODEL_COLORS[m]
        ours = pairs[m]["vs_SBC"] if pairs else r["vs_SBC"]["ours"][m]
        bx.plot(k, 100 * np.asarray(ours[:n], dtype=float), "o-", color=c, ms=5, lw=1,
                label=f"{m} / SBC - 1" + (", ours" if printed else "") + (", paired by shape" if pairs else ""))
        if printed:
            bx.plot(k, 100 * np.asarray(r["vs_SBC"]["printed"][m]), "s--", mfc="none", color=c, ms=7,
                    lw=1, label=f"{m} / SBC - 1, printed")
    if r.get("stated_bound") is not None:
        b = 100 * r["stated_bound"]
        for s in (-b, b):
            bx.axhline(s, color="red", lw=0.8, ls=":")
        bx.text(1, -b, f"stated bound ({r['stated']})", color="red", fontsize=7, va="bottom")
    bx.set_xlabel("mode number")
    bx.set_ylabel("relative to SBC [%]")
    bx.set_xticks(k)
    bx.grid(True, alpha=0.3)
    bx.legend(fontsize=7, ncol=2, loc="lower right")
    return save_figure(fig, png)


def plot_vibration_overlay(png, t, signals: dict, names: list, *, title: str = "") -> Path:
    """The histories ``names`` (displacements from the start) of every model in ``signals``
    ({model: {name: (nt,)}}) overlaid, one panel per name; angles in mrad, lengths in mm."""
    fig = new_figure(figsize=(9.0, 1.9 * len(names) + 0.6))
    axes = np.atleast_1d(fig.subplots(len(names), 1, sharex=True))
    for ax, s in zip(axes, names):
        angle = s.startswith(("theta", "psi"))
        for m, c in MODEL_COLORS.items():
            if s in signals.get(m, {}):
                ax.plot(t, 1e3 * signals[m][s], color=c, lw=1.6 if m == "SBC" else 1.0,
                        ls="-" if m == "SBC" else "--", label=m)
        ax.set_ylabel(f"{s} [{'mrad' if angle else 'mm'}]", fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7, loc="upper left", ncol=3)
    axes[-1].set_xlabel("t [s]")
    if title:
        axes[0].set_title(title, fontsize=10)
    return save_figure(fig, png)
