"""Why the LPV deployment of 8.4 (2-3, scheduled state feedback of 8.3) diverges on the SBC
plant measured through the bar chords: the experiments of docs/fe-plant.md ("The LPV deployment on the SBC plant"), dt = 0.01 s,
the FE plants started in their own packaged equilibrium as `tmfem deploy --plant` starts them.

    .venv/bin/python demos/lpv_sbc_diagnosis.py --lpv-controller c61.npz [--mesh 4] [--t-end 1]
        [--only start,open-loop,loop,runs]

* ``start``: the estimated start state of each FE plant against the COM's (z - z0) and the
  controller's first rest lengths against the packaged ones;
* ``open-loop``: the rest lengths u(t) of the COM closed-loop run applied to each FE plant
  (zero-order hold): the largest bar deviation from the COM run;
* ``loop``: the spectral radius of the linear sampled loop at the start
  (:func:`tmfem.control.fe_plant.sampled_loop.lpv_start_loop`) on the SBC plant (bars as designed,
  E x 10, E x 100, q from the bar chords), the MTC plant and the SBC plant with q from the
  bars' rigid fit (the default of the FE plants);
* ``runs``: the closed loops over --t-end: record, failure, largest bar deviation from the COM
  run, FE tendon slack.
"""
from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from tmfem.control.deployment.run import run_deployment
from tmfem.control.fe_plant.sampled_loop import dominant_eigenvalues, lpv_start_loop
from tmfem.control.lpv.deployment import state_feedback_controller
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.control.lpv.workflow import saved_design_plant
from tmfem.reference.tables import deployment_bases
from tmfem.control.fe_plant.state_estimate import deployment_plant
from tmfem.errors import ConvergenceError
from tmfem.reference.deployments import lpv_setup
from tmfem.simulation.driver import simulate
from tmfem.system import load_preset

#: the SBC plant measured through the bar chords, as diagnosed here (the plants' default is
#: their rigid fit, which runs: docs/fe-plant.md)
CHORD = {"sbc": "chord"}


def deployment(pl, d, bar_factor=1.0):
    """The LPV deployment and its controller set-up, the bars' E x ``bar_factor``."""
    s = load_preset("2-3-lpv")
    if bar_factor != 1.0:
        s = s.replace(bar=dataclasses.replace(s.bar, E=s.bar.E * bar_factor))
    dep = lpv_setup("2-3-lpv", pl, system=s)
    return dep, dep.setup(state_feedback_controller(dep, d))


def run(s, plant, t_end):
    return run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                          t_end=t_end, dt=0.01, plant=plant, jacobian="reuse" if plant is None else "step",
                          partial=plant is not None)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lpv-controller", required=True, help="a design saved by `tmfem control lpv --save`")
    ap.add_argument("--mesh", type=int, default=4)
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--only", default="start,open-loop,loop,runs")
    a = ap.parse_args()
    todo = a.only.split(",")
    d, system = LPVStateFeedback.load(a.lpv_controller), load_preset("2-3-lpv")
    pl = saved_design_plant(d, system, bases=deployment_bases(system))
    dep, s = deployment(pl, d)
    nq, nz = s.model.nq, s.model.nz
    com = run(s, None, a.t_end)
    if "start" in todo:
        u_p = dep.packaged().rest_lengths
        for kind in ("mtc", "sbc"):
            p = deployment_plant(kind, s.model, dep.packaged(), mesh_n=a.mesh, bars=CHORD.get(kind))
            y0 = p.outputs(p.x0, p.v0)
            u0 = s.controller.output(0.0, y0, s.controller.reset(0.0, y0, 0.01))
            print(f"start {kind} 3x{a.mesh}x{a.mesh}: max |z - z0| {1e3 * np.max(np.abs(y0[:nz] - s.z0)):.3f} "
                  f"mrad/mm, u(0) - u_packaged in [{1e3 * np.min(u0 - u_p):.1f}, {1e3 * np.max(u0 - u_p):.1f}] mm")
    if "open-loop" in todo:
        for kind in ("mtc", "sbc"):
            p = deployment_plant(kind, s.model, dep.packaged(), mesh_n=a.mesh, bars=CHORD.get(kind))
            Z = []

            def record(t, x, v, acc, u, y):
                Z.append(p.outputs(x, v)[:nq])
                return False
            try:
                simulate(p, t_end=a.t_end, dt=0.01, controller=lambda t: com.u[min(int(round(t / 0.01)), len(com.u) - 1)],
                         record=record, outputs=False)
            except ConvergenceError as exc:
                print(f"open loop {kind}: failed: {exc}")
            dev = np.max(np.abs(np.array(Z) - com.z[:len(Z), :nq]), axis=1)
            print(f"open loop {kind} under the COM run's u(t): bar deviation from the COM run "
                  + ", ".join(f"{1e3 * dev[min(k, len(dev) - 1)]:.2f}" for k in range(0, len(dev), 10)) + " mrad/mm every 0.1 s")
    if "loop" in todo:
        for kind, f, bars in (("sbc", 1.0, "chord"), ("sbc", 10.0, "chord"), ("sbc", 100.0, "chord"),
                              ("mtc", 1.0, None), ("sbc", 1.0, "rigid")):
            dp, sp = deployment(pl, d, f)
            p = deployment_plant(kind, sp.model, dp.packaged(), mesh_n=a.mesh, bars=bars)
            ev = dominant_eigenvalues(lpv_start_loop(dp, d, p, dt=0.01), 0.01, k=1)[0]
            print(f"linear sampled loop at the start, {kind} bars E x {f:g}{', ' + bars if bars else ''}: spectral radius {ev[0]:.5f} at {ev[1]:.2f} Hz")
    if "runs" in todo:
        for kind, f in (("sbc", 1.0), ("sbc", 100.0), ("mtc", 1.0)):
            dp, sp = deployment(pl, d, f)
            r = run(sp, deployment_plant(kind, sp.model, dp.packaged(), mesh_n=a.mesh, bars=CHORD.get(kind)), a.t_end)
            dev = np.max(np.abs(r.z[:, :nq] - com.z[:len(r.t), :nq]))
            rep = r.plant_report
            print(f"closed loop {kind} bars E x {f:g}: record {r.t[-1]:.2f} s ({'failed: ' + r.failure[:60] if r.failure else 'ran'}), "
                  f"bar deviation from the COM run <= {1e3 * dev:.2f} mrad/mm, FE slack {rep['tendon_slack_samples']} samples "
                  f"(up to {rep['tendon_slack_elements_max']} elements)")


if __name__ == "__main__":
    main()
