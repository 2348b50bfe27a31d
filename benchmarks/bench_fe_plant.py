"""Speed of a COM-designed controller on the MTC finite-element plant (issue 15).

The deployed 2-3 system (preset 2-3-deploy, Table 7.7) on the MTC model with N x n x n
membrane elements, in closed loop with the LQR state feedback of the COM linearisation
(:func:`tmfem.control.deploy.lqr_state_feedback`) through the COM-state estimate
(:class:`tmfem.control.state_estimate.FEStatePlant`), from theta_11' = 0.02 rad/s, dt = 0.01 s.
Target (issue 15): a 20 s 2-3 deployment on the 3x10x10 MTC model in under 10 minutes, i.e.
under 0.3 s per step. Prints the time per step and where it goes.

``--deploy cable|fixed-rate``: instead, the 2-3 deployment itself (the adaptive PFL of 7.4 at
the reference with the plant's tendon law, docs/fe-plant.md) on the MTC plant with that
tendon law, from its packaged equilibrium, through :func:`run_deployment`.

    .venv/bin/python benchmarks/bench_fe_plant.py [--mesh 10] [--t-end 2] [--jacobian step]
        [--deploy cable]
"""
from __future__ import annotations

import argparse
import os
import time

from tmfem.control.deploy import lqr_state_feedback
from tmfem.control.state_estimate import FEStatePlant
from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes
from tmfem.models.mtc.dynamics import MTCDynamics
from tmfem.models.mtc.model import MTCModel
from tmfem.simulation.driver import simulate
from tmfem.system import load_preset
from timing import print_breakdown


class Timed:
    """Proxy that times the plant calls the driver and the integrator make."""

    KEYS = ("residual", "newton_matrix", "factorize", "outputs")

    def __init__(self, plant):
        self.plant = plant
        self.t = dict.fromkeys(self.KEYS, 0.0)
        self.n = dict.fromkeys(self.KEYS, 0)

    def __getattr__(self, name):
        fn = getattr(self.plant, name)
        if name not in self.KEYS:
            return fn

        def timed(*a, **kw):
            t0 = time.perf_counter()
            out = fn(*a, **kw)
            self.t[name] += time.perf_counter() - t0
            self.n[name] += 1
            return out
        return timed


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=int, default=10)
    ap.add_argument("--t-end", type=float, default=2.0)
    ap.add_argument("--jacobian", default="step", choices=["iteration", "step", "reuse"])
    ap.add_argument("--deploy", choices=["cable", "fixed-rate"])
    a = ap.parse_args()
    if a.deploy:
        return deployment(a)
    s = load_preset("2-3-deploy")
    t0 = time.perf_counter()
    com = ControlOrientedModel(s, membrane_modes=default_membrane_modes(s), rest_lengths="system")
    z_e = com.equilibrium(com.u0, z0=com.z0)
    ctrl, _ = lqr_state_feedback(com, u_e=com.u0, z_e=z_e, u_m=0.01)
    t_com = time.perf_counter() - t0
    t0 = time.perf_counter()
    fe = MTCModel(s, mesh_n=a.mesh, rest_lengths="system")
    x_eq = fe.solve_static().x
    plant = Timed(FEStatePlant(MTCDynamics(fe, x_eq, perturb={"theta_11_dot": 0.02}), com))
    t_fe = time.perf_counter() - t0
    print(f"2-3 on MTC {s.N}x{a.mesh}x{a.mesh}: {plant.x0.size} free DOFs; COM + LQR {t_com:.2f} s, "
          f"MTC build + static {t_fe:.2f} s")
    c0, w0 = time.process_time(), time.perf_counter()
    sim = simulate(plant, t_end=a.t_end, dt=0.01, controller=ctrl, jacobian=a.jacobian)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    steps = sim.stats["steps"]
    print(f"{a.t_end:g} s closed loop, dt = 0.01 s, jacobian={a.jacobian}: wall {wall:.2f} s, "
          f"CPU {cpu:.2f} s, {cpu / steps * 1e3:.1f} ms CPU per step (target < 300 ms: "
          f"{'met' if cpu / steps < 0.3 else 'NOT met'}); load average {os.getloadavg()[0]:.1f} "
          f"on {os.cpu_count()} cores")
    print(f"  {steps} steps, {sim.stats['newton_iterations']} Newton iterations, "
          f"{sim.stats['jacobian_evaluations']} Newton matrices")
    print_breakdown(plant.t, plant.n, wall, "Park loop, solves, controller")


def deployment(a):
    """The 2-3 deployment on the MTC plant (``--deploy``), timed as :func:`main`."""
    from tmfem.control.deploy import run_deployment
    from tmfem.control.state_estimate import mtc_deployment_plant
    from tmfem.reference.deployments import setup
    t0 = time.perf_counter()
    s = setup("2-3-deploy", controller="adaptive", evaluation="reference", tendon_law=a.deploy)
    plant = Timed(mtc_deployment_plant(s.model, load_preset("2-3-deploy-initial"),
                                       mesh_n=a.mesh, tendon_law=a.deploy))
    print(f"2-3 deployment on MTC 3x{a.mesh}x{a.mesh} ({a.deploy} tendons): {plant.x0.size} free "
          f"DOFs; set-up (COM, PFL, FE start equilibrium) {time.perf_counter() - t0:.2f} s")
    c0, w0 = time.process_time(), time.perf_counter()
    r = run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                       t_end=a.t_end, dt=0.01, plant=plant, jacobian=a.jacobian)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    steps = r.t.size - 1
    print(f"{a.t_end:g} s deployment (and its recovery), dt = 0.01 s: wall {wall:.2f} s, CPU "
          f"{cpu:.2f} s, {cpu / steps * 1e3:.1f} ms CPU per step (target < 300 ms: "
          f"{'met' if cpu / steps < 0.3 else 'NOT met'}); load average {os.getloadavg()[0]:.1f} "
          f"on {os.cpu_count()} cores")
    print_breakdown(plant.t, plant.n, wall, "PFL, Park loop, solves, recovery")


if __name__ == "__main__":
    main()
