"""The map of symmetric equilibria in (theta, psi) (eq. 5.97) as a picture."""
from __future__ import annotations

import numpy as np
from matplotlib.patches import Rectangle

from tmfem.equilibrium.symmetric_map import EquilibriumMap
from tmfem.post.plots import new_figure, save_figure


def plot_equilibrium_map(png, emap: EquilibriumMap, *, mark=None, title=None,
                         detail: EquilibriumMap | None = None):
    """Plot the map: feasible region shaded, Delta = 0 and margin = 0 contours.

    Parameters
    ----------
    png : str or Path
    emap : EquilibriumMap
        The whole map.
    mark : (theta, psi) [rad], optional
        A point to mark (e.g. the design).
    title : str, optional
    detail : EquilibriumMap, optional
        A finer map around ``mark``, drawn in a second panel (its window outlined in the
        first), so that a thin feasible region is resolved where the design lies.
    """
    fig = new_figure(figsize=(12.0, 4.8) if detail is not None else (6.4, 4.8))
    axes = fig.subplots(1, 2 if detail is not None else 1, squeeze=False)[0]
    _draw(axes[0], emap, mark)
    if detail is not None:
        _draw(axes[1], detail, mark)
        th, ps = np.degrees(detail.theta), np.degrees(detail.psi)
        axes[0].add_patch(Rectangle((ps[0], th[0]), ps[-1] - ps[0], th[-1] - th[0], fill=False,
                                    ec="k", lw=0.8, ls=":"))
        axes[1].set_title("around the design", fontsize=9)
    fig.suptitle(title or "symmetric equilibria (green); blue: null vector positive "
                 "boundary, red dashed: Delta = 0", fontsize=10)
    return save_figure(fig, png)


def _draw(ax, emap: EquilibriumMap, mark) -> None:
    th, ps = np.degrees(emap.theta), np.degrees(emap.psi)
    if emap.theta.size > 1 and emap.psi.size > 1:
        fps, fth, inside = _feasible_region(emap)
        ax.contourf(fps, fth, inside, levels=[0.5, 1.5], colors=["#9fd49f"])
        m = np.where(np.isfinite(emap.margin), emap.margin, -1.0)
        ax.contour(ps, th, m, levels=[0.0], colors="C0", linewidths=1.2)
        ax.contour(ps, th, emap.Delta, levels=[0.0], colors="C3", linewidths=1.2, linestyles="--")
    if mark is not None:
        ax.plot(np.degrees(mark[1]), np.degrees(mark[0]), "k*", ms=12, label="design")
        ax.legend(loc="best")
    ax.set_xlabel("psi [deg] (azimuth relative to the stage base, eq. 5.97)")
    ax.set_ylabel("theta [deg]")


def _feasible_region(emap: EquilibriumMap, *, refine: int = 8):
    """The feasible region (margin > 0 and Delta > 0, the map's ``feasible``) on a grid
    ``refine`` times finer than the map's, each field interpolated bilinearly before the two
    conditions are combined, so that the drawn boundary follows both zero lines instead of
    the staircase of the sampled booleans; points that could not be evaluated stay out.

    Returns
    -------
    psi_deg, theta_deg : ndarray
        The fine grid's axes.
    inside : ndarray (n_theta_fine, n_psi_fine) of float, 1 inside and 0 outside.
    """
    from scipy.interpolate import RegularGridInterpolator

    th, ps = emap.theta, emap.psi
    fine_th = np.linspace(th[0], th[-1], refine * (th.size - 1) + 1)
    fine_ps = np.linspace(ps[0], ps[-1], refine * (ps.size - 1) + 1)
    pts = np.stack(np.meshgrid(fine_th, fine_ps, indexing="ij"), axis=-1)
    inside = np.ones(pts.shape[:2], dtype=bool)
    for field in (emap.margin, emap.Delta):
        known = np.isfinite(field)
        interp = RegularGridInterpolator((th, ps), np.where(known, field, -1.0))
        reach = RegularGridInterpolator((th, ps), known.astype(float))
        inside &= (interp(pts) > 0) & (reach(pts) > 0.999)
    return np.degrees(fine_ps), np.degrees(fine_th), inside.astype(float)
