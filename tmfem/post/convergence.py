"""The picture of a mesh / tendon-subdivision convergence study (dissertation 6.3)."""
from __future__ import annotations

import numpy as np

from tmfem.io.paths import check_path
from tmfem.post.plots import new_figure, save_figure


def plot_convergence_study(path, rows, modes, name, attachment, *, by_tendons: bool,
                           model: str = "MTC"):
    """Frequencies (left) and peak membrane stresses (right) of the rows of a convergence
    study (6.3, Figs. 6.11-6.14) against the membrane elements (log axis) or the elements
    per tendon."""
    path = check_path(path, suffixes=(".png",))
    x = np.array([r["tendon_elements"] if by_tendons else r["elements"] for r in rows], float)
    F = np.array([[r[f"f{i + 1}"] for i in range(modes)] for r in rows])
    fig = new_figure(figsize=(12, 4.5))
    ax = fig.subplots(1, 2)
    for i in range(modes):
        ax[0].plot(x, F[:, i], "o-", ms=3, label=f"mode {i + 1}")
    ax[0].set_xlabel("elements per tendon" if by_tendons else "membrane elements")
    ax[0].set_ylabel("frequency [Hz]")
    law = rows[0].get("membrane_law", "svk") if rows else "svk"
    ax[0].set_title(f"{name} {model}, {attachment} attachment, {law} membrane")
    ax[0].legend(fontsize=6, ncol=2)
    for key, lab in (("sigma_p1_max_MPa", "max sigma_p1 (Gauss pt)"),
                     ("von_mises_max_MPa", "max von Mises (Gauss pt)"),
                     ("sigma_p1_elem_max_MPa", "max sigma_p1 (element mean"
                                               + (", SBC: centre)" if model == "SBC" else ")"))):
        ax[1].plot(x, [r[key] for r in rows], "o-", label=lab)
    ax[1].set_xlabel(ax[0].get_xlabel())
    ax[1].set_ylabel("stress [MPa]")
    if not by_tendons:
        ax[0].set_xscale("log")
        ax[1].set_xscale("log")
    ax[1].legend(fontsize=8)
    return save_figure(fig, path)
