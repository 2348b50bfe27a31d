"""The 1-4(D) deployment (7.4, adaptive PFL without the switch, dt = 0.01 s) on the SBC plant:
the experiments of docs/guides/fe-plant.md, "What was tried". Prints one line per experiment.

    .venv/bin/python demos/sbc_1_4d_diagnosis.py [--mesh 4] [--t-end 3]
        [--only response,open-loop,closed,weak,deploy] [--actuation rest-length|force]
        [--bar-E-factor F] [--beta BETA] [--plot cmp.png]

``response``: psi_11 after a 1 mm step of the four SL rest lengths, COM and the SBC measured
at the chords and by the rigid fit of the bars. ``open-loop``: the rest lengths of the COM's
own closed-loop run (uncertainty ``exact``) applied to the SBC plant, undamped and with
Rayleigh damping. ``closed``: the closed loop for combinations of the uncertainty model, the
bar measurement, the PFL's feedback damping mu, the plant damping beta and the gain growth
omega_e of eq. 5.69: where it stopped, its largest bar error, its deviation from the COM run
of the same controller, the smallest rest-length margin and the tendon forces of SL_1, SU_1
at the end of the record (the COM law k (|d| - u) at the measured q and the FE tendons' own).
``weak`` (not in the default list): the symmetric deployment's input-response map
[theta_11, psi_11] per N of every SL_j / every SU_j, COM against SBC, after a tension step
and at 2, 6 and 12.5 Hz, and G_COM^-1 G_SBC (identity where the SBC answers as the COM).
``deploy`` (not in the default list): the 7.4 deployment with its switch (``adaptive-hinf``,
uncertainty ``initial``, the PFL at the reference) over ``--t-end`` on the SBC plant (plant
damping ``--beta``, default 0) and on the COM: record, switch, final error, the FE report and
the deviation; ``--plot`` writes the comparison figure.
``--actuation force``: the SBC tendons tension-servoed (:mod:`tmfem.control.fe_plant.tension_actuation`)
in ``closed`` and ``weak``; ``--bar-E-factor F``: the SBC plant of ``closed`` and ``weak`` built
with the bars' Young's modulus times F (the COM, of rigid bars, unchanged).
"""
from __future__ import annotations

import argparse
import contextlib
from dataclasses import replace

import numpy as np

from tmfem.control.deployment.run import StatePlant, run_deployment
from tmfem.control.fe_plant.state_estimate import FEStatePlant, sbc_deployment_plant, start_rest_lengths
from tmfem.reference.deployments import setup
from tmfem.simulation.controllers import OpenLoop
from tmfem.simulation.driver import simulate
from tmfem.system import load_preset

INITIAL = load_preset("1-4D-initial")
#: (uncertainty, bars, feedback damping mu, plant damping beta [s], omega_e [rad/s] of eq. 5.69
#: or None for Table 7.1's 150); the PFL at the reference
CLOSED = [("initial", "chord", 0.0, 0.0, None), ("initial", "rigid", 0.0, 0.0, None),
          ("initial", "rigid", 0.0, 1e-3, None), ("initial", "rigid", 1 / 30, 0.0, None),
          ("exact", "rigid", 0.0, 0.0, None), ("exact", "rigid", 1 / 30, 0.0, None),
          ("exact", "rigid", 1 / 30, 1e-3, None), ("initial", "rigid", 0.0, 1e-3, 24.0),
          ("initial", "rigid", 0.0, 0.0, 24.0), ("initial", "rigid", 0.0, 1e-3, 0.0),
          ("exact", "rigid", 0.0, 1e-3, 24.0)]


@contextlib.contextmanager
def bar_modulus(system, factor):
    """The system's bars with E scaled by ``factor`` inside the block (the SBC plant is built
    there; the COM's bars are rigid)."""
    bar = system.bar
    object.__setattr__(system, "bar", replace(bar, E=bar.E * factor))
    try:
        yield
    finally:
        object.__setattr__(system, "bar", bar)


def response(mesh):
    s = setup("1-4D", controller="adaptive")
    r0 = start_rest_lengths(INITIAL, "cable", s.model.u0)
    sbc = sbc_deployment_plant(s.model, INITIAL, mesh_n=mesh, bars="chord")
    u = r0.copy()
    u[:4] += 1e-3
    for name, p in (("COM", StatePlant(s.model, z0=s.z0)), ("SBC chord", sbc),
                    ("SBC rigid", FEStatePlant(sbc.dyn, s.model, bars="rigid"))):
        d = [simulate(p, t_end=0.1, dt=0.01, controller=c, jacobian="step").y[:, 1]
             for c in (r0, u)]
        print(f"response {name:10s} psi_11 at 10, 20, 50, 100 ms [mrad]:",
              np.round(1e3 * (d[1] - d[0])[[1, 2, 5, 10]], 3), flush=True)


def open_loop(mesh, t_end):
    s = setup("1-4D", controller="adaptive", uncertainty="exact")
    U = run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                       t_end=t_end).u
    for beta in (0.0, 1e-4, 1e-3):
        p = sbc_deployment_plant(s.model, INITIAL, mesh_n=mesh, beta=beta)
        r = run_deployment(model=s.model, reference=s.reference, partial=True, plant=p,
                           controller=OpenLoop(lambda t: U[min(int(t / 0.01 + 1e-9), len(U) - 1)]),
                           z0=s.z0, t_end=t_end, jacobian="step")
        print(f"open-loop COM inputs, beta = {beta:g} s: reached {r.t[-1]:.2f} s, min tendon force "
              f"{r.plant_report['min_tendon_force_N']:.2f} N, failure: {r.failure}", flush=True)


def closed(mesh, t_end, actuation="rest-length", bar_factor=1.0):
    for unc, bars, mu, beta, omega_e in CLOSED:
        runs = []
        for plant in ("sbc", "com"):
            s = setup("1-4D", controller="adaptive", uncertainty=unc, evaluation="reference")
            s.adaptive.feedback_damping = mu
            if omega_e is not None:
                s.adaptive.gains = replace(s.adaptive.gains, omega_e=omega_e)
            p = None
            if plant == "sbc":
                with bar_modulus(s.model.system, bar_factor):
                    p = sbc_deployment_plant(s.model, INITIAL, mesh_n=mesh, bars=bars, beta=beta,
                                             actuation=actuation)
            runs.append(run_deployment(model=s.model, reference=s.reference, controller=s.controller,
                                       z0=s.z0, t_end=t_end, plant=p, partial=True,
                                       jacobian="step" if p else "reuse"))
        r, rc = runs
        n, nq = r.t.size, s.model.nq
        err = np.max(np.abs(r.z[:, :nq] - r.q_d))
        dev = np.max(np.abs(r.z[:, :nq] - rc.z[:n, :nq]), axis=1)
        k = s.model.k
        T = k * (r.lengths[-1] - r.u[-1])
        late = r.t >= 0.3 - 1e-9
        print(f"closed {unc:7s} bars={bars:5s} mu={mu:.3g} beta={beta:g} omega_e="
              f"{150.0 if omega_e is None else omega_e:g}: reached {r.t[-1]:.2f} s, "
              f"bar error max {1e3 * err:.2f} mrad (COM {1e3 * np.max(np.abs(rc.z[:n, :nq] - rc.q_d[:n])):.2f}), "
              f"deviation from COM max {1e3 * dev.max():.2f} mrad at {r.t[np.argmax(dev)]:.2f} s, "
              f"margin {1e3 * r.min_margin:.2f} mm, model tendon forces SL_1, SU_1 at the end "
              f"{T[0]:.2f}, {T[4]:.2f} N (COM run {(k * (rc.lengths[n - 1] - rc.u[n - 1]))[[0, 4]].round(2)}), "
              f"FE {r.tendon_force[-1, 0]:.2f}, {r.tendon_force[-1, 4]:.2f} N; deviation at 0.1, 0.3, "
              f"0.5 s: {np.round(1e3 * dev[[i for i in (10, 30, 50) if i < n]], 2)} mrad, after 0.3 s "
              f"at most {1e3 * np.max(dev[late], initial=0.0):.2f} mrad; smallest FE SU_1 force after "
              f"0.3 s {np.min(r.tendon_force[late, 4], initial=np.inf):.2f} N", flush=True)


def weak(mesh, actuation, bar_factor=1.0):
    """The symmetric deployment's input-response map, COM against SBC: theta_11, psi_11 [mrad]
    after a 1 N step of the tension of every SL_j (every SU_j), from rest in each plant's
    packaged equilibrium, minus the unperturbed response, at 10, 20, 50, 100 ms: the 2 x 2
    matrices G(t) of each plant, and G_COM^-1 G_SBC, the loop the PFL closes on the SBC with
    the COM's inversion (identity where the SBC answers as the COM). Its eigenvalues far from
    1 are the directions the inversion gets wrong; the singular values of B_q [1_SL, 1_SU]
    (the COM at the packaged state) say which is weak."""
    from tmfem.control.deployment.pfl import partition
    s = setup("1-4D", controller="adaptive")
    com, nq = s.model, s.model.nq
    terms = partition(*com.matrices(s.z0, np.zeros(com.nz)), nq=nq)
    n = len(com.u0) // 2
    S = np.kron(np.eye(2), np.ones((n, 1)))                 # (8, 2): all SL, all SU
    _, sv, Vt = np.linalg.svd(terms.B_q @ S)
    r0 = start_rest_lengths(INITIAL, "cable", com.u0)
    with bar_modulus(com.system, bar_factor):
        sbc = sbc_deployment_plant(com, INITIAL, mesh_n=mesh, actuation=actuation)
    idx = [com.state_names.index("theta_11"), com.state_names.index("psi_11")]
    # statics: the SBC's own tendon forces at its packaged equilibrium (rigid-fit q_s) against
    # the forces that hold the COM at q_s (eq. 5.46 at rest: B_q u = -F_q)
    zs = sbc.outputs(sbc.x0, sbc.v0)[:com.nz]
    sbc.dyn.model.set_tendon_lengths(r0)
    T_sbc = sbc.dyn.member_forces(sbc.x0)["tendon_force"]
    ts = partition(*com.matrices(zs, np.zeros(com.nz)), nq=nq)
    T_com = com.tendon_forces(zs, np.linalg.solve(ts.B_q, -ts.F_q))
    print(f"weak: statics at the SBC's packaged rigid-fit q_s: SBC tendon forces SL_1, SU_1 "
          f"{T_sbc[[0, n]].round(2)} N, the COM held at q_s by {T_com[[0, n]].round(2)} N")
    print(f"weak: B_q [1_SL, 1_SU] at the packaged state: singular values {np.round(sv, 3)} "
          f"(rad/s^2 per m), ratio {sv[0] / sv[-1]:.0f}; weakest input (SL, SU) "
          f"{np.round(Vt[-1] / np.max(np.abs(Vt[-1])), 3)}")
    G = {}
    for pname, p in (("COM", StatePlant(com, z0=s.z0)), (f"SBC {actuation}", sbc)):
        base = simulate(p, t_end=0.1, dt=0.01, controller=r0, jacobian="step").y[:, idx]
        cols = []
        for j in range(2):
            du = -S[:, j] / com.k                           # a 1 N tension step of a family
            cols.append(1e3 * (simulate(p, t_end=0.1, dt=0.01, controller=r0 + du,
                                        jacobian="step").y[:, idx] - base))
        G[pname] = np.stack(cols, axis=2)                   # (n_t, 2 outputs, 2 inputs)
        for k in (1, 2, 5, 10):
            print(f"weak {pname:18s} {10 * k:3d} ms: [theta_11, psi_11] per N of SL / SU "
                  f"{np.round(G[pname][k].T, 4).tolist()} mrad", flush=True)
    gc, gs = G.values()
    for k in (1, 2, 5, 10):
        L = np.linalg.solve(gc[k], gs[k])
        print(f"weak G_COM^-1 G_SBC at {10 * k:3d} ms: {np.round(L, 3).tolist()}, eigenvalues "
              f"{np.round(np.linalg.eigvals(L), 3)}", flush=True)
    # the same map at the frequency of the swing: tensions sin(2 pi f t) [N] of every SL_j
    # (every SU_j), the responses' complex amplitudes fitted over the last three periods
    t_end = 0.5
    for f in (2.0, 6.0, 12.5):
        H = {}
        for pname, p in (("COM", StatePlant(com, z0=s.z0)), (f"SBC {actuation}", sbc)):
            base = simulate(p, t_end=t_end, dt=0.01, controller=r0, jacobian="step")
            cols = []
            for j in range(2):
                def u(t, j=j):
                    return r0 - S[:, j] / com.k * np.sin(2 * np.pi * f * t)
                r = simulate(p, t_end=t_end, dt=0.01, controller=OpenLoop(u), jacobian="step")
                m = r.t >= t_end - 3.0 / f - 1e-9
                X = np.column_stack([np.sin(2 * np.pi * f * r.t[m]), np.cos(2 * np.pi * f * r.t[m]),
                                     np.ones(m.sum()), r.t[m]])
                c = np.linalg.lstsq(X, 1e3 * (r.y[m][:, idx] - base.y[m][:, idx]), rcond=None)[0]
                cols.append(c[0] + 1j * c[1])               # in phase - i quadrature [mrad/N]
            H[pname] = np.stack(cols, axis=1)
        lam, vec = np.linalg.eig(np.linalg.solve(*H.values()))
        vec = vec / vec[np.argmax(np.abs(vec), axis=0), np.arange(2)]
        print(f"weak {f:4.1f} Hz: COM [theta_11, psi_11] per N of SL / SU "
              f"{np.round(H['COM'].T, 4).tolist()}; G_COM^-1 G_SBC eigenvalues {np.round(lam, 3)} "
              f"(|.| {np.round(np.abs(lam), 3)}, phase {np.round(np.degrees(np.angle(lam)), 1)} deg), "
              f"eigenvectors (SL, SU tension) {np.round(vec.T, 3).tolist()}", flush=True)


def deploy(mesh, t_end, actuation, bar_factor, beta, plot):
    from tmfem.control.fe_plant.compare import deviation_summary, plant_deviation
    runs = {}
    for plant in ("sbc", "com"):
        s = setup("1-4D", controller="adaptive-hinf", evaluation="reference")
        p = None
        if plant == "sbc":
            with bar_modulus(s.model.system, bar_factor):
                p = sbc_deployment_plant(s.model, INITIAL, mesh_n=mesh, beta=beta,
                                         actuation=actuation)
        r = runs[plant] = run_deployment(model=s.model, reference=s.reference,
                                         controller=s.controller, z0=s.z0, t_end=t_end, plant=p,
                                         partial=True, jacobian="step" if p else "reuse")
        rep = {k: v for k, v in (r.plant_report or {}).items() if not isinstance(v, np.ndarray)}
        print(f"deploy {plant}: reached {r.t[-1]:.2f} s, switch {r.switch_time}, final error "
              f"{r.relative_error[-1]:.4g}, margin {1e3 * r.min_margin:.2f} mm, failure "
              f"{r.failure}; {rep}", flush=True)
    dev = plant_deviation(runs["sbc"], runs["com"])
    print(f"deploy deviation: {deviation_summary(dev)}", flush=True)
    if plot:
        from tmfem.post.plant_compare_plot import plot_plant_comparison
        plot_plant_comparison(plot, runs["sbc"], runs["com"], dev, labels=("sbc", "com"),
                              title=f"1-4D deployment, adaptive-hinf (PFL at the reference, "
                                    f"fixed-rate tendon model, uncertainty initial) on both "
                                    f"plants\nsbc plant (solid): mesh {mesh}, bars E x "
                                    f"{bar_factor:g}, actuation {actuation}, damping {beta:g} s; "
                                    f"com plant (dashed)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=int, default=4)
    ap.add_argument("--t-end", type=float, default=3.0)
    ap.add_argument("--only", default="response,open-loop,closed")
    ap.add_argument("--actuation", default="rest-length", choices=["rest-length", "force"])
    ap.add_argument("--bar-E-factor", type=float, default=1.0)
    ap.add_argument("--beta", type=float, default=0.0)
    ap.add_argument("--plot")
    a = ap.parse_args()
    only = a.only.split(",")
    if "response" in only:
        response(a.mesh)
    if "open-loop" in only:
        open_loop(a.mesh, a.t_end)
    if "closed" in only:
        closed(a.mesh, a.t_end, a.actuation, a.bar_E_factor)
    if "weak" in only:
        weak(a.mesh, a.actuation, a.bar_E_factor)
    if "deploy" in only:
        deploy(a.mesh, a.t_end, a.actuation, a.bar_E_factor, a.beta, a.plot)


if __name__ == "__main__":
    main()
