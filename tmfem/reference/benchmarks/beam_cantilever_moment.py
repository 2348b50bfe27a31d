"""Cantilever rolled into a full circle by an end moment, 5 four-node beams (dissertation 4.5.2)."""
from __future__ import annotations

import numpy as np

from tmfem.reference.beam_benchmarks import cantilever_end_moment
from tmfem.reference.benchmarks.shell_cantilever_moment import elastica

NAME = "beam-cantilever-moment"
HELP = ("cantilever of 4.5.2 (E = 1.2e6 Pa, nu = 0, L = 12 m, b = 1 m, h = 0.1 m) in 5 four-node "
        "beam elements under an end moment up to 2 pi EI/L, against the elastica "
        "(benchmarks.json elastica_end_moment_closed_form)")
COLUMNS = {"lambda": "1", "u_tip": "m", "w_tip": "m", "u_elastica": "m", "w_elastica": "m",
           "newton_iterations": "1"}


def run(*, reduced: bool = False) -> dict:
    """Load path in 20 equal steps (10 with ``reduced``) of lambda = M L / (2 pi EI); rows
    with the tip displacements along (u) and across (w) the initial axis, the elastica at
    the same lambda, and the Newton iterations of the step."""
    r = cantilever_end_moment(n_elements=5, n_steps=10 if reduced else 20)
    its = [0] + list(r.iterations)
    rows = [{"lambda": round(float(l), 12), "u_tip": float(u), "w_tip": float(w), "u_elastica": float(ue),
             "w_elastica": float(we), "newton_iterations": int(k)}
            for l, u, w, ue, we, k in zip(r.lam, r.u_tip, r.w_tip, r.u_elastica, r.w_elastica, its)]
    err = np.hypot(r.u_tip - r.u_elastica, r.w_tip - r.w_elastica)
    ref = np.hypot(r.u_elastica, r.w_elastica)
    return {"rows": rows, "load_steps": len(r.iterations), "rejected_steps": r.rejected,
            "max_error_over_tip_displacement": float(np.max(err[1:] / ref[1:])),
            "max_error_over_L": float(np.max(err) / r.L), "EI_Nm2": r.EI,
            "shapes": {f"{l:.3f}": s[[0, 2]].tolist() for l, s in zip(r.lam, r.shapes)},
            "source": "elastica: u = L (sin t / t - 1), w = L (1 - cos t) / t, t = 2 pi lambda"}


def plot(result: dict, png):
    """Deformed axes at several lambda (FE, 16 points per element) with the elastica arcs,
    equal axes, and the tip displacements against lambda."""
    from matplotlib import colormaps

    from tmfem.post.plots import new_figure, save_figure
    from tmfem.io.paths import check_path
    png = check_path(png, suffixes=(".png",))
    fig = new_figure(figsize=(12, 4.8))
    ax, bx = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.25, 1]})
    L = 12.0
    shapes = result["shapes"]
    keys = sorted(shapes, key=float)
    pick = [k for k in keys if np.isclose((4 * float(k)) % 1.0, 0.0) or np.isclose((4 * float(k)) % 1.0, 1.0)]
    cmap = colormaps["viridis"]
    s = np.linspace(0.0, 1.0, 200)
    for i, k in enumerate(pick):
        lam = float(k)
        xz = np.asarray(shapes[k])
        c = cmap(i / max(len(pick) - 1, 1))
        ax.plot(xz[0], xz[1], "-", color=c, lw=2.0, label=f"FE, lambda = {lam:.2f}")
        th = 2 * np.pi * lam * s
        kap = 2 * np.pi * lam / L
        if lam > 0:
            ax.plot(np.sin(th) / kap, (1 - np.cos(th)) / kap, "k:", lw=1.0)
    ax.plot([], [], "k:", lw=1.0, label="elastica")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title("5 four-node beams: deformed axis")
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(True, alpha=0.3)
    rows = result["rows"]
    lam = np.array([r["lambda"] for r in rows])
    lf = np.linspace(0.0, 1.0, 201)
    ue, we = elastica(lf, L)
    bx.plot(lf, -ue, "k-", lw=1.0, label="-u elastica")
    bx.plot(lf, we, "k--", lw=1.0, label="w elastica")
    bx.plot(lam, [-r["u_tip"] for r in rows], "o", ms=4, label="-u FE")
    bx.plot(lam, [r["w_tip"] for r in rows], "s", ms=4, label="w FE")
    bx.set_xlabel("lambda = M L / (2 pi EI)")
    bx.set_ylabel("tip displacement [m]")
    bx.set_title(f"max error {100 * result['max_error_over_tip_displacement']:.2f} % of |tip displacement|")
    bx.legend(fontsize=8)
    bx.grid(True, alpha=0.3)
    return save_figure(fig, png)
