"""The history plot of an optimisation (:func:`tmfem.design.optimize`)."""
from __future__ import annotations

import numpy as np
from matplotlib.ticker import MaxNLocator

from tmfem.post.plots import new_figure, save_figure


def plot_history(history, png, *, objective: str):
    """Objective (log scale when positive and changing more than tenfold), largest scaled
    constraint violation and step length per iteration, one panel each, written to ``png``;
    returns the path."""
    h = np.array([row for row in history], dtype=float).reshape(-1, 4)
    fig = new_figure(figsize=(7.0, 6.0))
    axes = fig.subplots(3, 1, sharex=True)
    f = h[:, 1]
    wide = bool(np.all(f > 0) and f.max() > 10 * f.min())         # a mass falling tenfold: log scale
    (axes[0].semilogy if wide else axes[0].plot)(h[:, 0], f, "o-")
    axes[0].set_ylabel(objective)
    for ax, col, lab in ((axes[1], 2, "max violation (scaled)"), (axes[2], 3, "step |dp| (SI)")):
        v = h[:, col]
        positive = v > 0
        floor = min(0.1 * v[positive].min(), 1e-12) if positive.any() else 1e-12
        ax.semilogy(h[:, 0], np.where(positive, v, floor), "o-", color="C0")
        if not positive.all():                  # zeros drawn at a floor, marked, not dropped
            ax.semilogy(h[~positive, 0], np.full((~positive).sum(), floor), "v", color="C3",
                        label=f"exactly 0 (drawn at {floor:.1e})")
            ax.legend(loc="best", fontsize="small")
        ax.set_ylabel(lab)
    axes[2].set_xlabel("iteration")
    axes[2].xaxis.set_major_locator(MaxNLocator(integer=True))
    return save_figure(fig, png)
