"""Closed-loop linear analysis plots of an H-infinity design (7.3-7.4).

One PNG with four panels:

* poles of the open and the closed loop, with the line Re s = -alpha_1;
* singular values: sigma_max of the closed loop T_pw and of each group of performance
  channels (outputs named ``<group>_<signal>``, e.g. ``ed_`` tracking errors and ``eu_``
  control efforts), of the open-loop channel w -> p (u = 0) and of the plant u -> y, with
  gamma and, where the feedthrough bound max(||Pi_12 D11||, ||D11 Pi_21||) sets gamma (no
  controller can go below it), that bound drawn and named;
* regulation: each tracked coordinate (a reference input ``ref_<s>`` with a tracking error
  ``ed_<s> = W (ref - s)``) released from a unit offset, the controller at rest, beside the
  envelope e^(-alpha_1 t) (otherwise the performance outputs for a step of the first exogenous
  input). The reference's step response is not drawn: in Fig. 7.1 the controller regulates
  about the deployed equilibrium and gamma is set by the feedthrough ||D11||, so the
  designs leave the coordinates at rest for a reference step (a panel of zeros);
* the level gamma and the verified closed-loop norm of each synthesis route on the same
  plant (or the reason a route refused it).
"""
from __future__ import annotations

import numpy as np

from tmfem.control.linear.hinf_riccati import gamma_lower_bound
from tmfem.control.linear.hinf_synthesis import hinfsyn
from tmfem.errors import TmfemError


def damping_table(sys) -> list:
    """(frequency_hz, damping ratio, real part) of each pole with Im >= 0, ascending
    frequency (python-control ``damp`` without printing)."""
    wn, zeta, poles = sys.damp()
    rows = [(float(w / (2 * np.pi)), float(z), float(p.real)) for w, z, p in zip(wn, zeta, poles)
            if p.imag >= 0]
    return sorted(rows)


#: longest estimated synthesis [CPU s] (:func:`tmfem.resources.synthesis_seconds`) that the
#: figure's comparison of routes runs; a longer route is left out of the figure, said so in its panel
ROUTE_PLOT_BUDGET_S = 10.0


def route_levels(plant, *, alpha: float, routes=("riccati", "lmi", "slicot"),
                 budget_s: float = ROUTE_PLOT_BUDGET_S, known: dict | None = None) -> dict:
    """gamma and verified norm of each route of :func:`tmfem.control.linear.hinf_synthesis.hinfsyn`
    on ``plant`` (GeneralizedPlant): name -> (gamma, norm) or the refusal's message. A route
    whose estimated time exceeds ``budget_s`` CPU seconds is not run (the LMI route grows as
    n^5.5: about a minute at 36 states): its entry says so. ``known``: route -> (gamma, norm)
    already computed on this plant (the design's own route), taken as they are."""
    from tmfem.resources import synthesis_seconds
    out = {}
    n = plant.A.shape[0]
    for r in routes:
        if known and r in known:
            out[r] = known[r]
            continue
        t = synthesis_seconds(route=r, n=n)
        if t > budget_s:
            out[r] = (f"not run for this figure: about {t:.0f} s of CPU for {n} states "
                      f"(`tmfem.control.hinfsyn(..., method='{r}')` runs it)")
            continue
        try:
            res = hinfsyn(plant, plant.C2.shape[0], plant.B2.shape[1], method=r, alpha=alpha)
            out[r] = (res.gamma, res.info["verified_norm"])
        except TmfemError as exc:
            out[r] = str(exc)
    return out


def _sigma_max(sys, w):
    H = np.asarray(sys(1j * w)).reshape(sys.noutputs, sys.ninputs, w.size)
    return np.linalg.svd(np.moveaxis(H, 2, 0), compute_uv=False)


def _poles(a, pol, pcl, alpha) -> None:
    """The poles panel: open-loop ``pol`` and closed-loop ``pcl`` in the s-plane with the line
    Re s = -alpha_1 of eq. 5.66. The real axis is symmetric-logarithmic (linear within 1 1/s)
    only when the real parts reach beyond 10 1/s; otherwise linear, since a symlog axis over its
    linear part alone carries only its two end ticks."""
    a.plot(pol.real, pol.imag, "x", color="0.5", label="open loop")
    a.plot(pcl.real, pcl.imag, ".", color="C0", label="closed loop")
    a.axvline(-alpha, color="C3", ls="--", label=f"Re s = -alpha_1 = {-alpha:g} 1/s"
              if alpha else "Re s = 0")
    a.set_xlabel("Re s [1/s]")
    a.set_ylabel("Im s [rad/s]")
    if np.max(np.abs(np.concatenate([pol.real, pcl.real, [alpha or 0.0]]))) > 10.0:
        a.set_xscale("symlog", linthresh=1.0)
    a.legend(loc="best", fontsize=8)
    a.set_title("poles")


def _own_route(design) -> dict:
    """{route: (gamma, verified norm)} of the :func:`hinfsyn` route that made ``design`` (its
    ``info["route"]``, set by ``tmfem control hinf --method auto``), so the comparison of
    routes does not synthesise it again; {} for a design of another origin."""
    route = (design.info or {}).get("route") or {}
    if "method" not in route:
        return {}
    norm = float(design.closed_loop_norm)
    return {route["method"]: (max(float(design.gamma), norm), norm)}


def plot_design(design, *, open_loop=None, path, title: str = "", routes=None) -> None:
    """Write the four-panel closed-loop analysis figure of ``design`` (HinfDesign) to ``path``.

    ``open_loop``: the GeneralizedPlant (open-loop poles and singular values); ``routes``:
    the result of :func:`route_levels` (computed here when None and ``open_loop`` is given).
    """
    import control
    from tmfem.post.plots import new_figure, save_figure
    T = design.closed_loop
    P = open_loop if open_loop is not None else design.plant
    if routes is None and open_loop is not None:
        routes = route_levels(P, alpha=design.alpha, known=_own_route(design))
    fig = new_figure(figsize=(13, 9.5))
    ax = fig.subplots(2, 2)
    pol = np.linalg.eigvals(P.A)
    pcl = T.poles()
    _poles(ax[0, 0], pol, pcl, design.alpha)
    # singular values
    a = ax[0, 1]
    lam = np.abs(np.concatenate([pol, pcl]))
    lam = lam[lam > 0]
    w = np.logspace(np.log10(max(lam.min() / 30, 1e-4)), np.log10(lam.max() * 30), 500)
    f = w / (2 * np.pi)
    sv = _sigma_max(T, w)
    a.loglog(f, sv[:, 0], color="C0", lw=2, label="closed loop T_pw: sigma_max")
    outs = list(T.output_labels)
    groups = {}
    for i, s in enumerate(outs):
        groups.setdefault(s.split("_")[0] if "_" in s else s, []).append(i)
    if 1 < len(groups) <= 6:
        for k, (g, idx) in enumerate(groups.items()):
            a.loglog(f, _sigma_max(T[idx, :], w)[:, 0], color=f"C{k + 2}", lw=1, ls="--",
                     label=f"T_pw, outputs {g}_*" if len(idx) > 1 else f"T_pw, output {outs[idx[0]]}")
    P11 = control.ss(P.A, P.B1, P.C1, P.D11)
    if np.any(P.B1) or np.any(P.D11):
        a.loglog(f, np.maximum(_sigma_max(P11, w)[:, 0], 1e-300), color="0.5", ls="--",
                 label="open loop w -> p (u = 0)")
    P22 = control.ss(P.A, P.B2, P.C2, P.D22)
    a.loglog(f, _sigma_max(P22, w)[:, 0], color="0.7", ls=":", label="plant u -> y")
    a.axhline(design.gamma, color="C3", ls="--", label=f"gamma = {design.gamma:.5g}")
    bound = gamma_lower_bound(P)
    sets = bound > 0 and design.gamma <= bound * (1 + 2e-2)
    if sets:
        a.axhline(bound, color="k", ls="-.", lw=1,
                  label=f"feedthrough bound ||D11|| part = {bound:.4g}")
        a.text(0.02, 0.02, f"gamma is set by the feedthrough w -> p (||Pi D11|| = {bound:.4g}):\n"
               "no controller can lower it; the dynamics stay below it", transform=a.transAxes,
               fontsize=8, va="bottom", bbox=dict(fc="w", ec="k", alpha=0.85))
    a.set_xlabel("frequency [Hz]")
    a.set_ylabel("singular value [-]")
    a.set_title(f"singular values: ||T_pw||_inf = {design.closed_loop_norm:.5g}")
    a.legend(loc="upper right", fontsize=7)
    # regulation of the tracked coordinates from an offset
    _regulation(ax[1, 0], T, design)
    # gamma of each route
    a = ax[1, 1]
    _routes(a, routes or {}, design, bound, sets)
    fig.suptitle(title)
    save_figure(fig, path)


def _regulation(a, T, design) -> None:
    """The regulation panel: each tracked coordinate s (a reference input ``ref_<s>`` with a
    tracking error ``ed_<s> = W (ref - s)``, so s = -ed_s / W at ref = 0) released from a unit
    offset of the measured y_s (plant state x_0 = C2^+ e_s: e_s for C2 = I of Fig. 7.1, its
    projection Z_r^T e_s on the reachable part), the controller at rest, with the envelope
    e^(-alpha_1 t) that the closed-loop poles (Re s < -alpha_1) impose on its decay. Without
    such pairs: the performance outputs for a step of the first exogenous input."""
    import control
    tf = 8.0 / max(design.alpha, max(-np.max(T.poles().real), 0.1))
    t = np.linspace(0, tf, 1500)
    ins, outs = list(T.input_labels), list(T.output_labels)
    D = np.asarray(T.D)
    P = design.plant
    ys = list(P.y_names)
    pairs = []
    for j, s in enumerate(ins):
        if s.startswith("ref_") and f"ed_{s[4:]}" in outs and f"y_{s[4:]}" in ys:
            i = outs.index(f"ed_{s[4:]}")
            if D[i, j] != 0:
                pairs.append((i, D[i, j], s[4:]))
    if not pairs:
        r = control.step_response(T[: min(4, T.noutputs), 0], T=t)
        y = np.atleast_2d(np.squeeze(r.outputs))
        for k in range(y.shape[0]):
            a.plot(r.time, y[k], label=outs[k])
        a.set_ylabel("performance output per unit step [-]")
        a.set_title(f"step responses from {ins[0]}")
        a.set_xlabel("t [s]")
        a.legend(loc="best", fontsize=7)
        return
    offsets = np.linalg.pinv(P.C2)
    n = P.A.shape[0]
    kinds = {}
    for i, w, name in pairs:                  # the first coordinate of each kind (theta, psi, v, ...)
        kinds.setdefault(name.split("_")[0], (i, w, name))
    peak = np.zeros(t.size)
    for i, w, name in pairs:
        x0 = np.zeros(T.nstates)
        x0[:n] = offsets[:, ys.index(f"y_{name}")]
        s_t = -np.squeeze(control.initial_response(T[i, :], T=t, X0=x0).outputs) / w
        peak = np.maximum(peak, np.abs(s_t))
        if (i, w, name) in kinds.values():
            a.plot(t, s_t, lw=1.5, label=f"{name} released from {name}(0) = 1")
    a.plot(t, peak, color="k", lw=0.8, label=f"largest |s(t)| of all {len(pairs)} coordinates")
    env = np.exp(-design.alpha * t)
    a.plot(t, env, color="C3", ls="--", label=f"+- exp(-alpha_1 t), alpha_1 = {design.alpha:g} 1/s")
    a.plot(t, -env, color="C3", ls="--")
    a.axhline(0.0, color="0.5", lw=0.5)
    if n < len(ys):
        a.text(0.02, 0.02, f"designed on the reachable part ({n} of {len(ys)} states): each offset is "
               "projected onto it;\nits part along the modes no tendon reaches stays open loop, "
               "not drawn", transform=a.transAxes, fontsize=7, va="bottom",
               bbox=dict(fc="w", ec="k", alpha=0.85))
    a.set_xlabel("t [s]")
    a.set_ylabel("coordinate / its initial offset [-]")
    a.set_title("regulation: each tracked coordinate released from an offset\n"
                "(linear closed loop, controller at rest)")
    a.legend(loc="upper right", fontsize=7)


def _wrapped(text: str, *, width: int = 30, lines: int = 6) -> str:
    """``text`` broken at word boundaries into at most ``lines`` lines of ``width`` characters,
    the last ending in "..." when the text is longer (a refusal's message inside a bar panel)."""
    import textwrap
    return "\n".join(textwrap.wrap(text, width=width, max_lines=lines, placeholder=" ..."))


def _routes(a, routes: dict, design, bound: float, sets: bool) -> None:
    names = list(routes)
    ok = [(k, v) for k, v in routes.items() if not isinstance(v, str)]
    x = np.arange(len(names))
    for k, name in enumerate(names):
        v = routes[name]
        if isinstance(v, str):
            # at the foot of the panel whatever the gamma scale (x in data, y in axes units)
            text = ("" if v.startswith("not run") else "refused:\n") + _wrapped(v)
            a.text(k, 0.02, text, ha="center", va="bottom", fontsize=6, rotation=0,
                   transform=a.get_xaxis_transform(), bbox=dict(facecolor="white", edgecolor="0.7", pad=2))
            continue
        a.bar(k - 0.18, v[0], width=0.36, color="C0", label="gamma" if k == 0 else None)
        a.bar(k + 0.18, v[1], width=0.36, color="C1", label="verified ||T_pw||_inf" if k == 0 else None)
        a.text(k, v[0], f"{v[0]:.5g}", ha="center", va="bottom", fontsize=7)
    a.axhline(design.gamma, color="C3", ls="--", lw=1, label=f"this design: {design.gamma:.5g}")
    if bound > 0:
        a.axhline(bound, color="k", ls="-.", lw=1, label=f"feedthrough bound {bound:.4g}"
                  + (" (sets gamma)" if sets else ""))
    if ok:
        top = max(max(v) for _, v in ok)
        lo = min(min(v) for _, v in ok)
        a.set_ylim(max(0.0, lo - 0.6 * (top - lo) - 0.02 * top), top + 0.3 * (top - lo) + 0.02 * top)
    a.set_xticks(x, names)
    a.set_ylabel("level [-]")
    a.set_title("gamma of each synthesis route (same plant, same alpha_1)")
    a.legend(loc="best", fontsize=7)
