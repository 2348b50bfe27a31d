"""Line plots for studies (matplotlib's object-oriented API: a ``Figure`` rendered by the Agg
canvas; no pyplot state, no backend switch, no display needed).

Small and generic: histories over time, convergence over mesh size, a computed-vs-printed
comparison. Each function writes one PNG and returns its path.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from tmfem.errors import InputError
from tmfem.io.paths import check_path


def new_figure(*, figsize=(7.0, 4.5)):
    """A matplotlib ``Figure`` (object-oriented API; it is not registered with pyplot, so
    nothing needs closing and the caller's backend is left alone)."""
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout="constrained")


def save_figure(fig, png) -> Path:
    """Write ``fig`` to ``png`` (120 dpi, atomically) and return the path."""
    from tmfem.io.atomic import atomic_path
    with atomic_path(png) as tmp:
        fig.savefig(tmp, dpi=120)
    return Path(png)


def mode_styles(k: int) -> list[dict]:
    """``k`` distinct line styles (colour x dash x marker) for mode-by-mode plots: 12 modes
    get 12 different combinations (tab20 colours, four dash patterns, markers)."""
    from matplotlib import colormaps

    colors = colormaps["tab20"].colors
    dashes = ["-", "--", "-.", ":"]
    markers = ["o", "s", "^", "D", "v", "P"]
    return [{"color": colors[(2 * i) % 20 + (i // 10) % 2], "linestyle": dashes[i % 4],
             "marker": markers[i % 6]} for i in range(k)]


def _finite_1d(name: str, v, n: int | None = None) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.ndim != 1 or (n is not None and a.shape[0] != n):
        raise InputError(f"{name}: expected a 1-D array" + (f" of length {n}" if n is not None else "")
                         + f", found shape {a.shape}")
    return a


def plot_histories(png, t, series: dict, *, ylabel: str, title: str | None = None,
                   xlabel: str = "t [s]", subplots: bool = False) -> Path:
    """Plot time histories ``series = {label: values (len(t),)}`` against t.

    With ``subplots=True`` each series gets its own axes (shared t), as in the stacked
    history figures of 6.5; otherwise all share one axes.
    """
    png = check_path(png, suffixes=(".png",))
    t = _finite_1d("t", t)
    if not series:
        raise InputError("series: expected at least one history")
    data = {k: _finite_1d(f"series {k!r}", v, t.size) for k, v in series.items()}
    if subplots:
        fig = new_figure(figsize=(7, 1.8 * len(data) + 0.8))
        axes = fig.subplots(len(data), 1, sharex=True, squeeze=False)
        for ax, (k, v) in zip(axes[:, 0], data.items()):
            ax.plot(t, v, lw=1.2)
            ax.set_ylabel(k)
            ax.grid(True, alpha=0.3)
        axes[-1, 0].set_xlabel(xlabel)
        axes[0, 0].set_title(title or "")
        fig.supylabel(ylabel)
    else:
        fig = new_figure(figsize=(7, 4.2))
        ax = fig.subplots()
        for k, v in data.items():
            ax.plot(t, v, lw=1.2, label=k)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if title:
            ax.set_title(title)
        ax.grid(True, alpha=0.3)
        if len(data) > 1:
            ax.legend(fontsize=8)
    return save_figure(fig, png)


def fit_rates(h, values, reference) -> np.ndarray:
    """Convergence rates p of |v - ref| ~ C h^p per column, least squares on log h
    (``np.polyfit``); NaN where fewer than two errors are non-zero."""
    h = _finite_1d("h", h)
    V = np.asarray(values, dtype=float).reshape(h.size, -1)
    ref = _finite_1d("reference", reference, V.shape[1])
    err = np.abs(V - ref) / np.where(ref == 0, 1.0, np.abs(ref))
    rates = np.full(V.shape[1], np.nan)
    for c in range(V.shape[1]):
        ok = err[:, c] > 0
        if ok.sum() >= 2:
            rates[c] = np.polyfit(np.log(h[ok]), np.log(err[ok, c]), 1)[0]
    return rates


def plot_convergence(png, h, values, *, labels, xlabel: str = "h", ylabel: str = "value",
                     title: str | None = None, reference=None, loglog: bool = False) -> Path:
    """Plot quantities against a mesh parameter h.

    Parameters
    ----------
    h : array (m,)
        Mesh sizes (or numbers of elements).
    values : array (m, k)
        Column c is the quantity ``labels[c]`` on each mesh.
    reference : array (k,), optional
        Values to converge to; then the relative error |v - ref| / |ref| is plotted on
        log-log axes with the fitted rate (``np.polyfit`` on log h) in the legend.
    loglog : bool
        Log-log axes for the values themselves.
    """
    png = check_path(png, suffixes=(".png",))
    h = _finite_1d("h", h)
    V = np.asarray(values, dtype=float)
    if V.ndim == 1:
        V = V[:, None]
    if V.shape[0] != h.size:
        raise InputError(f"values: expected {h.size} rows (one per h), found shape {V.shape}")
    labels = list(labels)
    if len(labels) != V.shape[1]:
        raise InputError(f"labels: expected {V.shape[1]} labels, found {len(labels)}")
    fig = new_figure(figsize=(7, 4.5))
    ax = fig.subplots()
    styles = mode_styles(len(labels))
    if reference is not None:
        ref = _finite_1d("reference", reference, V.shape[1])
        err = np.abs(V - ref) / np.where(ref == 0, 1.0, np.abs(ref))
        rates = fit_rates(h, V, ref)
        for c, lab in enumerate(labels):
            ok = err[:, c] > 0
            ax.loglog(h[ok], err[ok, c], label=f"{lab} (rate {rates[c]:.2f})", **styles[c])
        ax.set_ylabel("relative error")
    else:
        for c, lab in enumerate(labels):
            ax.plot(h, V[:, c], label=lab, **styles[c])
        if loglog:
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.set_ylabel(ylabel)
    ax.set_xlabel(xlabel)
    if title:
        ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, ncol=2 if len(labels) > 6 else 1)
    return save_figure(fig, png)


def plot_table_comparison(png, names, computed, printed, *, ylabel: str,
                          title: str | None = None, labels=("tmfem", "dissertation")) -> Path:
    """Grouped bars of computed vs printed values per row, with the relative difference
    printed above each pair (printed NaN = not given)."""
    png = check_path(png, suffixes=(".png",))
    names = list(names)
    a = _finite_1d("computed", computed, len(names))
    b = np.asarray(printed, dtype=float)
    if b.shape != a.shape:
        raise InputError(f"printed: expected shape {a.shape}, found {b.shape}")
    fig = new_figure(figsize=(max(6.0, 0.7 * len(names) + 2), 4.5))
    ax = fig.subplots()
    x = np.arange(len(names))
    ax.bar(x - 0.2, a, 0.4, label=labels[0], color="#2171b5")
    ax.bar(x + 0.2, np.nan_to_num(b), 0.4, label=labels[1], color="#bbbbbb")
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = (a - b) / np.abs(b)
    top = np.nanmax(np.abs(np.concatenate([a, b]))) or 1.0
    for k in range(len(names)):
        if np.isfinite(rel[k]):
            ax.text(x[k], max(a[k], np.nan_to_num(b[k])) + 0.02 * top, f"{100 * rel[k]:+.1f}%",
                    ha="center", va="bottom", fontsize=7)
    ax.set_xticks(x, names, rotation=45 if len(names) > 6 else 0)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(True, axis="y", alpha=0.3)
    return save_figure(fig, png)


def plot_xy(png, curves: dict, *, xlabel: str, ylabel: str, title: str | None = None) -> Path:
    """Plot curves ``{label: (x, y)}`` on one axes with a legend (load-displacement paths,
    benchmark results against their references)."""
    png = check_path(png, suffixes=(".png",))
    if not curves:
        raise InputError("curves: expected at least one (x, y) curve")
    fig = new_figure(figsize=(6.5, 4.5))
    ax = fig.subplots()
    styles = ["-", "--", ":", "-."]
    for k, (label, (x, y)) in enumerate(curves.items()):
        x = _finite_1d(f"{label!r} x", x)
        ax.plot(x, _finite_1d(f"{label!r} y", y, x.size), styles[k % 4], lw=1.4, label=label,
                marker="o" if x.size < 30 else None, ms=3)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    return save_figure(fig, png)


def plot_free_vibration(result, path, *, title: str = "") -> str:
    """Monitored node coordinates and membrane deflections vs time (Figs. 6.21-6.28) of a
    free-vibration result (``nodes``: label -> (nt, 3), ``w`` (nt, k), ``t``).

    A panel per monitored node and one for the membrane deflections w, each only where the
    system has them; a system with neither gets the bar coordinates instead (angles
    theta, psi in mrad, positions in mm, from t = 0), and the title says so."""
    panels = [("node", name, X) for name, X in result.nodes.items()]
    if result.w.shape[1]:
        panels.append(("w", None, result.w))
    note = ""
    if not panels:
        q = getattr(result, "q", None)
        q = result.z if q is None else q
        names = list(result.columns[1:1 + q.shape[1]])
        for fam, test, f, unit in (("angles", lambda n: n.startswith(("theta", "psi")), 1e3, "mrad"),
                                   ("positions", lambda n: n.split("_")[0] in ("x", "y", "z"), 1e3, "mm")):
            cols = [k for k, n in enumerate(names) if test(n)]
            if cols:
                panels.append(("q", (fam, unit, [names[k] for k in cols]), f * (q[:, cols] - q[0, cols])))
        note = "\n(no monitored nodes or membrane points in the system: its bar coordinates)"
    if not panels:
        raise InputError("free vibration plot: expected monitored nodes, membrane points or bar "
                         "coordinates in the result, found none")
    fig = new_figure(figsize=(8, 2.4 * len(panels) + 0.8))
    axes = np.atleast_1d(fig.subplots(len(panels), 1, sharex=True))
    for ax, (kind, name, X) in zip(axes, panels):
        if kind == "node":
            for c, lab in enumerate("xyz"):
                ax.plot(result.t, 1e3 * (X[:, c] - X[0, c]), label=f"{lab} - {lab}(0)")
            ax.set_ylabel(f"{name} [mm]")
        elif kind == "w":
            for k in range(X.shape[1]):
                ax.plot(result.t, 1e3 * X[:, k], label=f"w_{k + 1}")
            ax.set_ylabel("w [mm]")
        else:
            fam, unit, labels = name
            for k, (lab, style) in enumerate(zip(labels, mode_styles(len(labels)))):
                ax.plot(result.t, X[:, k], label=f"{lab} - {lab}(0)", ms=3,
                        markevery=max(1, len(result.t) // 12), **style)
            ax.set_ylabel(f"{fam} [{unit}]")
        many = len(ax.get_lines()) > 6     # beside the panel, so that it hides no history
        ax.legend(fontsize=7, ncol=2 if many and len(ax.get_lines()) > 16 else (1 if many else 2),
                  **({"loc": "upper left", "bbox_to_anchor": (1.01, 1.0)} if many else {"loc": "upper right"}))
    axes[-1].set_xlabel("t [s]")
    if title or note:
        axes[0].set_title(textwrap.fill(title, 80) + note, fontsize=10)
    return str(save_figure(fig, path))
