"""The history plot of an optimisation (:func:`tmfem.design.optimize`)."""
from __future__ import annotations

import numpy as np

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
        ax.semilogy(h[:, 0], np.where(v > 0, v, np.nan), "o-")
        ax.set_ylabel(lab)
    axes[2].set_xlabel("iteration")
    return save_figure(fig, png)
