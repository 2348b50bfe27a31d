"""Cost of the plant damping on the current tangent (docs/guides/fe-plant.md, "Plant damping"):
the per-sample tangent ``FEPlant.sample`` (C_n = beta K_T(x_n)) on the 1-4(D) SBC
deployment plant (N x n x n shell, rigid fit, beta = 1e-3 s), and the CPU per step of a
closed loop (the adaptive PFL of 7.4 at the reference, no switch, dt = 0.01 s) with
``damping_tangent="initial"`` and ``"current"``. Process (CPU) times.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_damping_tangent.py [--mesh 4]
        [--t-end 0.5]
"""
from __future__ import annotations

import argparse
import time


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=int, default=4)
    ap.add_argument("--t-end", type=float, default=0.5)
    args = ap.parse_args()
    from tmfem.control.deployment.run import run_deployment
    from tmfem.control.fe_plant.state_estimate import sbc_deployment_plant
    from tmfem.reference.deployments import setup
    from tmfem.system import load_preset
    init = load_preset("1-4D-initial")
    for tangent in ("initial", "current"):
        s = setup("1-4D", controller="adaptive", evaluation="reference")
        plant = sbc_deployment_plant(s.model, init, mesh_n=args.mesh, beta=1e-3,
                                     damping_tangent=tangent)
        t0 = time.process_time()
        for _ in range(20):
            plant.dyn.sample(plant.x0, plant.dyn.u0)
        per_sample = (time.process_time() - t0) / 20
        t0 = time.process_time()
        r = run_deployment(model=s.model, reference=s.reference, controller=s.controller,
                           z0=s.z0, t_end=args.t_end, dt=0.01, plant=plant, jacobian="step",
                           partial=True)
        cpu = time.process_time() - t0
        steps = len(r.t) - 1
        print(f"{tangent:8s} sample() {1e3 * per_sample:6.1f} ms CPU; closed loop {cpu:6.2f} s CPU "
              f"for {steps} steps = {1e3 * cpu / steps:6.1f} ms/step ({plant.x0.size} free dofs)")


if __name__ == "__main__":
    main()
