"""Why the adaptive PFL of eq. 5.58 (terms at the measured state) diverges on the MTC plant,
and what fixes it: the experiments of docs/guides/fe-plant.md on the 2-3 deployment (7.4, Table
7.7), adaptive PFL without the switch, dt = 0.01 s, 3 x 10 x 10 MTC plant with the COM's
fixed-rate tendons unless stated. Prints one line per experiment: where the closed loop
diverged (Park's Newton failed) or the largest bar error |q - q_d| (angles [mrad], bases [mm]).

    .venv/bin/python demos/fe_deployment_diagnosis.py [--t-end 3] [--only open-loop,gains,...]

Experiments: open-loop, stiffness, gains, adaptation, tendon-elements, membrane-E, mesh, fix.
``membrane-E`` builds the FE plant with the membrane's Young's modulus scaled (the COM keeps
the design value): a perturbation study, the System is swapped only while the plant is built.
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses

import numpy as np

from tmfem.control.deployment.run import StatePlant, run_deployment
from tmfem.control.fe_plant.state_estimate import mtc_deployment_plant
from tmfem.errors import ConvergenceError
from tmfem.reference.deployments import setup
from tmfem.simulation.driver import simulate
from tmfem.system import load_preset

INITIAL = load_preset("2-3-deploy-initial")


@contextlib.contextmanager
def membrane_modulus(system, factor):
    """The system's membrane with E scaled by ``factor`` inside the block."""
    mem = system.membrane
    object.__setattr__(system, "membrane", dataclasses.replace(mem, E=mem.E * factor))
    try:
        yield
    finally:
        object.__setattr__(system, "membrane", mem)


def closed_loop(label, t_end, *, plant="fixed-rate", evaluation="state", tendon_model="fixed-rate",
                omega_e=None, gamma=None, uncertainty=None, mesh=10, tendon_elements=3, E=1.0):
    s = setup("2-3-deploy", controller="adaptive", evaluation=evaluation, tendon_law=tendon_model,
              uncertainty=uncertainty)
    if omega_e is not None:
        s.adaptive.gains = dataclasses.replace(s.adaptive.gains, omega_e=omega_e)
    if gamma is not None:
        s.adaptive.gamma = gamma
    p = None
    if plant != "com":
        with membrane_modulus(s.model.system, E):
            p = mtc_deployment_plant(s.model, INITIAL, mesh_n=mesh, tendon_law=plant,
                                     tendon_elements=tendon_elements)
    last = [0]
    try:
        r = run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                           t_end=t_end, dt=0.01, plant=p, stress_every=100,
                           jacobian="reuse" if p is None else "step",
                           progress=lambda k, n: last.__setitem__(0, k))
    except ConvergenceError:
        print(f"{label}: diverged at {last[0] * 0.01:.2f} s")
        return None
    e = np.abs(r.z[:, :s.model.nq] - r.q_d)
    ang = [i for i, n in enumerate(s.model.system.q_names) if n.startswith(("theta", "psi"))]
    pos = [i for i in range(s.model.nq) if i not in ang]
    print(f"{label}: ran {t_end:g} s, bar error max {1e3 * e[:, ang].max():.1f} mrad, "
          f"{1e3 * e[:, pos].max():.1f} mm, at the end {1e3 * e[-1, ang].max():.2f} mrad")
    return r


def open_loop(t_end):
    """The COM closed loop's u(t) applied to the MTC plant and to the COM plant."""
    s = setup("2-3-deploy", controller="adaptive")
    rc = closed_loop("COM closed loop (eq. 5.58)", t_end, plant="com")
    U = rc.u
    sched = lambda t: U[min(int(round(t / 0.01)), len(U) - 1)]             # noqa: E731
    p = mtc_deployment_plant(s.model, INITIAL, mesh_n=10, tendon_law="fixed-rate")
    for name, plant in (("MTC", p), ("COM", StatePlant(s.model, z0=s.z0))):
        sim = simulate(plant, t_end=t_end, dt=0.01, controller=sched, jacobian="step")
        d = np.max(np.abs(sim.y[:, :s.model.nq] - rc.z[:, :s.model.nq]), axis=1)
        at = ", ".join(f"{tt:g} s {1e3 * d[int(round(tt / 0.01))]:.2f}"
                       for tt in (0.5, 1.0, 1.4, 2.0) if tt <= t_end)
        print(f"open loop, u(t) of the COM closed loop on the {name} plant: largest |q - q_COM| "
              f"[mrad or mm] {at}; max {1e3 * d.max():.2f}")


def stiffness(t_end):
    """Largest omega^2 of the COM's M^-1 K along its closed-loop run against k_q (eq. 5.69)."""
    import scipy.linalg as sl
    s = setup("2-3-deploy", controller="adaptive")
    r = run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                       t_end=min(t_end, 1.4), dt=0.01, stress_every=100)
    m = s.model
    for tt in (0.0, 0.5, 1.0, 1.4):
        k = min(int(round(tt / 0.01)), r.t.size - 1)
        zero = np.zeros(m.nz)
        K, _, M = m.jacobians(r.z[k], zero, zero, 0.0, r.u[k])
        w = np.sort(np.real(sl.eigvals(K, M)))
        kq = s.adaptive.gains(r.t[k])[1]
        print(f"t = {r.t[k]:.1f} s: COM omega^2, largest six {np.round(w[-6:][::-1], 0)} s^-2, k_q "
              f"{kq:.3g} s^-2: the law at the state tolerates a stiffness error of "
              f"{100 * kq / w[-1]:.2g} % in that direction")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=3.0)
    ap.add_argument("--only", default="open-loop,stiffness,gains,adaptation,tendon-elements,"
                                       "membrane-E,mesh,fix")
    a = ap.parse_args()
    T = a.t_end
    todo = a.only.split(",")
    if "open-loop" in todo:
        open_loop(T)
    if "stiffness" in todo:
        stiffness(T)
    if "gains" in todo:
        for we in (24.0, 6.0, 0.0):
            closed_loop(f"PFL at the state, omega_e = {we:g} rad/s", T, omega_e=we)
    if "adaptation" in todo:
        closed_loop("PFL at the state, Gamma = 1e-4", T, gamma=1e-4)
        closed_loop("PFL at the state, uncertainty exact", T, uncertainty="exact")
    if "tendon-elements" in todo:
        closed_loop("PFL at the state, 1 truss per tendon", T, tendon_elements=1)
    if "membrane-E" in todo:
        for f in (0.95, 1.05, 1.2):
            closed_loop(f"PFL at the state, FE membrane E x {f:g}", T, E=f)
    if "mesh" in todo:
        for n in (4, 2):
            closed_loop(f"PFL at the state, 3 x {n} x {n} membrane", T, mesh=n)
    if "fix" in todo:
        closed_loop("COM plant, PFL at the reference", T, plant="com", evaluation="reference")
        closed_loop("fixed-rate plant, PFL at the reference", T, evaluation="reference")
        closed_loop("cable plant, PFL at the reference, fixed-rate tendon model", T, plant="cable",
                    evaluation="reference")
        closed_loop("cable plant, PFL at the state, cable tendon model", T, plant="cable",
                    tendon_model="cable")
        closed_loop("cable plant, PFL at the reference, cable tendon model", T, plant="cable",
                    evaluation="reference", tendon_model="cable")


if __name__ == "__main__":
    main()
