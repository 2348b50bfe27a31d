"""A controller designed on the control-oriented model, run on the finite-element model.

A controller is only credible on a model it was not designed on. This script designs an LQR
state feedback on the linearised control-oriented model (COM) of ``examples/pentagon.toml``
and closes it around the membrane-truss-cable (MTC) finite-element model: the FE plant's
outputs are the COM state estimated from the FE nodes (bar coordinates from the bars, the
membrane projected on the COM's modes), so the same ``LinearController`` runs on both plants.
Both runs start from the same push of one bar; the script prints how the push decays on each.
More: docs/guides/fe-plant.md.

    .venv/bin/python examples/controller_on_fe_plant.py [--mesh 6] [--t-end 3]
"""
import argparse
from pathlib import Path

import control as ct
import numpy as np

from tmfem.control.deployment.run import StatePlant
from tmfem.control.fe_plant.state_estimate import FEStatePlant
from tmfem.models.com.linearize import linearize
from tmfem.models.com.model import ControlOrientedModel
from tmfem.models.mtc.dynamics import MTCDynamics
from tmfem.models.mtc.model import MTCModel
from tmfem.simulation import LinearController, simulate
from tmfem.system import load_system

HERE = Path(__file__).resolve().parent


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=int, default=6, help="FE membrane elements per patch edge")
    ap.add_argument("--t-end", type=float, default=3.0)
    args = ap.parse_args(argv)
    system = load_system(HERE / "pentagon.toml")

    # The design model and its equilibrium, and the LQR gain on its linearisation.
    com = ControlOrientedModel(system, membrane_modes=2)
    z_e = com.equilibrium(com.u0).state
    lin = linearize(com, z_e=z_e, u_e=com.u0)
    K, _, _ = ct.lqr(lin.A, lin.B, 100 * np.eye(lin.A.shape[0]), np.eye(lin.B.shape[1]) / 0.01**2)
    y_e = np.concatenate([lin.z_e, np.zeros(com.nz)])        # the plants output y = [z, z']

    # The FE model in its own static equilibrium under the same rest lengths.
    fe = MTCModel(system, mesh_n=args.mesh)
    x_eq = fe.equilibrium().state

    push = "theta_11"
    i = list(com.z_names).index(push)
    com_plant = StatePlant(com, z0=z_e)
    com_plant.v0 = np.zeros(com.nz)
    com_plant.v0[i] = 0.02
    fe_plant = FEStatePlant(MTCDynamics(fe, x_eq, perturb={f"{push}_dot": 0.02}), com)

    runs = {}
    for name, plant in (("COM", com_plant), ("MTC", fe_plant)):
        for label, ctrl in (("open loop", None),
                            ("LQR", LinearController(-K, u_e=lin.u_e, y_e=y_e, name="lqr"))):
            run = simulate(plant, t_end=args.t_end, dt=0.01, controller=ctrl, jacobian="iteration")
            d = run.y[:, i] - run.y[0, i]
            runs[name, label] = d
            print(f"{name} plant, {label:9s}: {push} peak {np.abs(d).max():.2e} rad, "
                  f"last second {np.abs(d[-100:]).max():.2e} rad")
    gap = np.abs(runs["MTC", "LQR"] - runs["COM", "LQR"]).max()
    print(f"closed loops differ by at most {gap:.2e} rad")
    return runs


if __name__ == "__main__":
    main()
