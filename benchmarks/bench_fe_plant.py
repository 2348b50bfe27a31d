"""Speed of a COM-designed controller on a finite-element plant.

The deployed 2-3 system (preset 2-3-deploy, Table 7.7) or 1-4(D) (``--preset 1-4D``, SBC
only) on the MTC (``--plant mtc``, default) or SBC model (``--plant sbc``) with N x n x n
membrane elements, in closed loop with the LQR state feedback of the COM linearisation
(:func:`tmfem.control.deployment.run.lqr_state_feedback`) through the COM-state estimate
(:class:`tmfem.control.fe_plant.state_estimate.FEStatePlant`), from theta_11' = 0.02 rad/s, dt = 0.01 s.
Target: a 20 s 2-3 deployment on the 3x10x10 MTC model in under 10 minutes, i.e.
under 0.3 s per step. Prints the time per step and where it goes (for the SBC plant also
inside its Newton matrix: element assembly, the exponential map's tangent operator, the
constraint products T^T K dexp T).

``--deploy cable|fixed-rate``: instead, the 2-3 deployment itself (the adaptive PFL of 7.4 at
the reference with the plant's tendon law, docs/guides/fe-plant.md) on the MTC plant with that
tendon law, from its packaged equilibrium, through :func:`run_deployment`; with
``--lpv-controller FILE`` the LPV deployment of 8.4 (preset 2-3-lpv) with that saved design
(``tmfem control lpv ... --save FILE``, rebuilt and checked on its grid as ``tmfem deploy``
does) instead of the adaptive PFL. The controller's calls (its measurement included) are
timed apart from the plant's.

    .venv/bin/python benchmarks/bench_fe_plant.py [--plant mtc|sbc] [--preset 2-3-deploy|1-4D]
        [--mesh 10] [--t-end 2] [--jacobian step] [--deploy cable|fixed-rate
        [--lpv-controller FILE]]
"""
from __future__ import annotations

import argparse
import os
import time

from tmfem.control.deployment.run import lqr_state_feedback
from tmfem.control.fe_plant.state_estimate import FEStatePlant
from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes
from tmfem.models.mtc.dynamics import MTCDynamics
from tmfem.models.mtc.model import MTCModel
from tmfem.models.sbc import dynamics as sbc_dynamics
from tmfem.models.sbc.model import SBCModel
from tmfem.simulation.driver import simulate
from tmfem.system import load_preset
from timing import print_breakdown


class Timed:
    """Proxy that times the calls ``keys`` (default: those of a plant the driver and the
    integrator make) of ``plant`` (a plant or a controller)."""

    KEYS = ("residual", "newton_matrix", "jacobians", "factorize", "outputs")

    def __init__(self, plant, keys=KEYS):
        self.plant, self.keys = plant, tuple(keys)
        self.t = dict.fromkeys(self.keys, 0.0)
        self.n = dict.fromkeys(self.keys, 0)

    def __getattr__(self, name):
        fn = getattr(self.plant, name)
        if name not in self.keys:
            return fn

        def timed(*a, **kw):
            t0 = time.perf_counter()
            out = fn(*a, **kw)
            self.t[name] += time.perf_counter() - t0
            self.n[name] += 1
            return out
        return timed


class TimedFunction:
    """A module attribute (function) replaced by a timed wrapper for the rest of the run."""

    def __init__(self, owner, name):
        self.owner, self.name, self.fn = owner, name, getattr(owner, name)
        self.t, self.n = 0.0, 0

        def timed(*a, **kw):
            t0 = time.perf_counter()
            out = self.fn(*a, **kw)
            self.t += time.perf_counter() - t0
            self.n += 1
            return out
        setattr(owner, name, timed)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plant", default="mtc", choices=["mtc", "sbc"])
    ap.add_argument("--preset", default="2-3-deploy", choices=["2-3-deploy", "1-4D"])
    ap.add_argument("--mesh", type=int, default=10)
    ap.add_argument("--t-end", type=float, default=2.0)
    ap.add_argument("--jacobian", default="step", choices=["iteration", "step", "reuse"])
    ap.add_argument("--deploy", choices=["cable", "fixed-rate"])
    ap.add_argument("--lpv-controller", metavar="FILE")
    a = ap.parse_args()
    if a.lpv_controller and not a.deploy:
        ap.error("--lpv-controller: the LPV deployment on the MTC plant, expected --deploy cable|fixed-rate")
    if a.plant == "mtc" and a.preset == "1-4D":
        ap.error("--plant mtc: 1-4D has H_1j nodes along the bars (the SBC model only)")
    if a.deploy:
        if (a.plant, a.preset) != ("mtc", "2-3-deploy"):
            ap.error("--deploy: the 2-3 deployment on the MTC plant (--plant mtc --preset 2-3-deploy)")
        return deployment(a)
    s = load_preset(a.preset)
    t0 = time.perf_counter()
    com = ControlOrientedModel(s, membrane_modes=default_membrane_modes(s), rest_lengths="system")
    z_e = com.equilibrium(com.u0, z0=com.z0).state
    ctrl, _ = lqr_state_feedback(com, u_e=com.u0, z_e=z_e, u_m=0.01)
    t_com = time.perf_counter() - t0
    t0 = time.perf_counter()
    perturb = {"theta_11_dot": 0.02}
    if a.plant == "mtc":
        fe = MTCModel(s, mesh_n=a.mesh, rest_lengths="system")
        dyn = MTCDynamics(fe, fe.equilibrium().x, perturb=perturb)
    else:
        fe = SBCModel(s, mesh_n=a.mesh, rest_lengths="system")
        dyn = sbc_dynamics.SBCDynamics(fe, fe.equilibrium().state, perturb=perturb)
    plant = Timed(FEStatePlant(dyn, com, bars="chord"))      # as measured in docs/guides/fe-plant.md
    t_fe = time.perf_counter() - t0
    inner = []
    if a.plant == "sbc":
        inner = [TimedFunction(sbc_dynamics, "assemble"),
                 TimedFunction(sbc_dynamics.SBCDynamics, "_rotation_jacobian")]
    print(f"{a.preset} on {a.plant.upper()} {s.N}x{a.mesh}x{a.mesh}: {plant.x0.size} free DOFs; "
          f"COM + LQR {t_com:.2f} s, FE build + static {t_fe:.2f} s")
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
    if inner:
        print("  inside the SBC tangents (newton_matrix, and jacobians for the starting "
              "accelerations):")
        print_breakdown({f.name: f.t for f in inner}, {f.name: f.n for f in inner},
                        plant.t["newton_matrix"] + plant.t["jacobians"],
                        "products T^T K dexp T, slicing")


def deployment(a):
    """The 2-3 deployment on the MTC plant (``--deploy``; ``--lpv-controller``: the LPV one of
    8.4), timed as :func:`main`, the controller's calls apart."""
    from tmfem.control.deployment.run import run_deployment
    from tmfem.control.fe_plant.state_estimate import deployment_plant
    from tmfem.reference.deployments import setup
    t0 = time.perf_counter()
    if a.lpv_controller:
        from tmfem.control.lpv.deployment import state_feedback_controller
        from tmfem.control.lpv.state_feedback import LPVStateFeedback
        from tmfem.control.lpv.workflow import saved_design_plant
        from tmfem.reference.deployments import lpv_setup
        from tmfem.reference.tables import deployment_bases
        d, system = LPVStateFeedback.load(a.lpv_controller), load_preset("2-3-lpv")
        plant = saved_design_plant(d, system, bases=deployment_bases(system))
        dep = lpv_setup("2-3-lpv", plant)
        s, initial = dep.setup(state_feedback_controller(dep, d)), dep.packaged()
        what = f"LPV deployment (8.4, gamma = {d.gamma:.4g})"
    else:
        s = setup("2-3-deploy", controller="adaptive", evaluation="reference", tendon_law=a.deploy)
        initial, what = load_preset("2-3-deploy-initial"), "deployment (adaptive PFL of 7.4)"
    plant = Timed(deployment_plant("mtc", s.model, initial, mesh_n=a.mesh, tendon_law=a.deploy))
    ctrl = Timed(s.controller, keys=("reset", "output", "update"))
    print(f"2-3 {what} on MTC 3x{a.mesh}x{a.mesh} ({a.deploy} tendons): {plant.x0.size} free "
          f"DOFs; set-up (COM, controller, FE start equilibrium) {time.perf_counter() - t0:.2f} s")
    c0, w0 = time.process_time(), time.perf_counter()
    r = run_deployment(model=s.model, reference=s.reference, controller=ctrl, z0=s.z0,
                       t_end=a.t_end, dt=0.01, plant=plant, jacobian=a.jacobian)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    steps = r.t.size - 1
    print(f"{a.t_end:g} s deployment (and its recovery), dt = 0.01 s: wall {wall:.2f} s, CPU "
          f"{cpu:.2f} s, {cpu / steps * 1e3:.1f} ms CPU per step (target < 300 ms: "
          f"{'met' if cpu / steps < 0.3 else 'NOT met'}); load average {os.getloadavg()[0]:.1f} "
          f"on {os.cpu_count()} cores")
    print_breakdown({**plant.t, **{f"controller {k}": v for k, v in ctrl.t.items()}},
                    {**plant.n, **{f"controller {k}": v for k, v in ctrl.n.items()}}, wall,
                    "limits, Park loop, solves, recovery")


if __name__ == "__main__":
    main()
