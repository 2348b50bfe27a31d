"""Closed-loop linear analysis plots of an H-infinity design (7.3-7.4).

One PNG with four panels: open- and closed-loop poles (with the line Re = -alpha_1),
singular values of T_pw(j omega) with gamma, and the step and impulse responses of the
linear closed loop from the first reference and the first noise channel.
"""
from __future__ import annotations

import numpy as np


def damping_table(sys) -> list:
    """(frequency_hz, damping ratio, real part) of each pole with Im >= 0, ascending
    frequency (python-control ``damp`` without printing)."""
    wn, zeta, poles = sys.damp()
    rows = [(float(w / (2 * np.pi)), float(z), float(p.real)) for w, z, p in zip(wn, zeta, poles)
            if p.imag >= 0]
    return sorted(rows)


def plot_design(design, *, open_loop=None, path, title: str = "") -> None:
    """Write the four-panel closed-loop analysis figure of ``design`` (HinfDesign) to ``path``."""
    import control
    from tmfem.post.plots import new_figure, save_figure
    T = design.closed_loop
    fig = new_figure(figsize=(12, 9))
    ax = fig.subplots(2, 2)
    # poles
    a = ax[0, 0]
    if open_loop is not None:
        pol = np.linalg.eigvals(open_loop.A)
        a.plot(pol.real, pol.imag, "x", color="0.5", label="open loop")
    pcl = T.poles()
    a.plot(pcl.real, pcl.imag, ".", color="C0", label="closed loop")
    a.axvline(-design.alpha, color="C3", ls="--", label=f"Re s = -alpha_1 = {-design.alpha:g}")
    a.set_xlabel("Re s [1/s]")
    a.set_ylabel("Im s [rad/s]")
    a.set_xscale("symlog", linthresh=1.0)
    a.legend(loc="best", fontsize=8)
    a.set_title("poles")
    # sigma plot of T_pw
    a = ax[0, 1]
    w = np.logspace(-2, 3, 400)
    sv = np.linalg.svd(np.moveaxis(T(1j * w), -1, 0), compute_uv=False)
    a.semilogx(w / (2 * np.pi), sv[:, 0], color="C0", label="sigma_max T_pw")
    a.semilogx(w / (2 * np.pi), sv[:, -1], color="C0", ls=":", label="sigma_min T_pw")
    a.axhline(design.gamma, color="C3", ls="--", label=f"gamma = {design.gamma:.4g}")
    a.set_xlabel("frequency [Hz]")
    a.set_ylabel("singular value [-]")
    a.set_title(f"T_pw: ||T_pw||_inf = {design.closed_loop_norm:.4g}")
    a.legend(loc="best", fontsize=8)
    # step / impulse from the first reference and the first noise channel
    tf = 5.0 / max(design.alpha, 0.2)
    t = np.linspace(0, tf, 1500)
    outs = list(T.output_labels)
    wn = list(T.input_labels)
    ied = [i for i, s in enumerate(outs) if s.startswith("ed_")][:4]
    ieu = [i for i, s in enumerate(outs) if s.startswith("eu_")][:2]
    jn = next((i for i, s in enumerate(wn) if s.startswith("n_")), len(wn) - 1)
    for a, kind, j, show in ((ax[1, 0], "step", 0, ied + ieu), (ax[1, 1], "impulse", jn, ied)):
        # impulse: e_d only (no feedthrough from the noise, so no Dirac at t = 0)
        sub = T[show, j]
        r = (control.step_response if kind == "step" else control.impulse_response)(sub, T=t)
        y = np.atleast_2d(np.squeeze(r.outputs))
        for k, i in enumerate(show):
            a.plot(r.time, y[k], label=outs[i])
        a.set_xlabel("t [s]")
        a.set_ylabel("weighted output [-]" + (" per unit step" if kind == "step" else " per unit impulse [1/s]"))
        a.set_title(f"{kind} response from {wn[j]}")
        a.legend(loc="best", fontsize=7)
    fig.suptitle(title)
    save_figure(fig, path)
