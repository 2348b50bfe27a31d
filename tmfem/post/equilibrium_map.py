"""The map of symmetric equilibria in (theta, psi) (eq. 5.97) as a picture."""
from __future__ import annotations

import numpy as np

from tmfem.equilibrium.symmetric_map import EquilibriumMap
from tmfem.post.plots import new_figure, save_figure


def plot_equilibrium_map(png, emap: EquilibriumMap, *, mark=None, title=None):
    """Plot the map: feasible region shaded, Delta = 0 and margin = 0 contours.

    ``mark`` = (theta, psi) [rad] of a point to mark (e.g. the design).
    """
    th, ps = np.degrees(emap.theta), np.degrees(emap.psi)
    fig = new_figure(figsize=(6.4, 4.8))
    ax = fig.subplots()
    ax.contourf(ps, th, emap.feasible.astype(float), levels=[0.5, 1.5], colors=["#9fd49f"])
    if emap.theta.size > 1 and emap.psi.size > 1:
        m = np.where(np.isfinite(emap.margin), emap.margin, -1.0)
        ax.contour(ps, th, m, levels=[0.0], colors="C0", linewidths=1.2)
        ax.contour(ps, th, emap.Delta, levels=[0.0], colors="C3", linewidths=1.2, linestyles="--")
    if mark is not None:
        ax.plot(np.degrees(mark[1]), np.degrees(mark[0]), "k*", ms=12, label="design")
        ax.legend(loc="best")
    ax.set_xlabel("psi [deg] (azimuth relative to the stage base, eq. 5.97)")
    ax.set_ylabel("theta [deg]")
    ax.set_title(title or "symmetric equilibria (green); blue: null vector positive "
                 "boundary, red dashed: Delta = 0", fontsize=9)
    return save_figure(fig, png)
