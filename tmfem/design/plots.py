"""The history plot of an optimisation (:func:`tmfem.design.optimize`)."""
from __future__ import annotations

import numpy as np

from tmfem.post.plots import new_figure, save_figure


def plot_history(history, png, *, objective: str):
    """Objective, largest scaled constraint violation and step length per iteration, one
    panel each, written to ``png``; returns the path."""
    h = np.array([row for row in history], dtype=float).reshape(-1, 4)
    fig = new_figure(figsize=(7.0, 6.0))
    axes = fig.subplots(3, 1, sharex=True)
    axes[0].plot(h[:, 0], h[:, 1], "o-")
    axes[0].set_ylabel(objective)
    for ax, col, lab in ((axes[1], 2, "max violation (scaled)"), (axes[2], 3, "step |dp|")):
        v = h[:, col]
        ax.semilogy(h[:, 0], np.where(v > 0, v, np.nan), "o-")
        ax.set_ylabel(lab)
    axes[2].set_xlabel("iteration")
    return save_figure(fig, png)
