"""The control-oriented model of your own system as a python-control state-space model.

The control-oriented model (COM, dissertation ch. 5) describes the bars by their angles and
the membrane by a few modes; linearised about the designed equilibrium (eq. 5.33) it is a
python-control ``StateSpace`` whose inputs are the tendon rest lengths and whose outputs are
the bar angles and the membrane deflections at the points of the file's ``[monitor]``. This
script builds it for ``examples/pentagon.toml``, designs an LQR state feedback on it with
python-control, and simulates the nonlinear model in closed loop with tmfem's time driver.

    .venv/bin/python examples/control_model.py
"""
import control as ct
import numpy as np

from pathlib import Path

from tmfem.control.deployment.run import StatePlant
from tmfem.models.com.linearize import linearize
from tmfem.models.com.model import ControlOrientedModel
from tmfem.simulation import LinearController, simulate
from tmfem.system import load_system

HERE = Path(__file__).resolve().parent


def main():
    system = load_system(HERE / "pentagon.toml")
    com = ControlOrientedModel(system, membrane_modes=2)

    # The linear model: named states, inputs r_<tendon> and outputs (bar angles, w_k).
    lin = linearize(com)
    G = lin.to_ss()
    print(f"{G.nstates} states, inputs {G.input_labels}")
    print(f"undamped: max Re(pole) = {G.poles().real.max():.1e}, "
          f"lowest frequency {np.sort(np.abs(G.poles().imag))[0] / (2 * np.pi):.4f} Hz")

    # python-control designs on it like on any StateSpace: LQR with Q = 100 I, R = I / (1 cm)^2.
    K, _, cl_poles = ct.lqr(G.A, G.B, 100 * np.eye(G.nstates), np.eye(G.ninputs) / 0.01**2)
    slow = np.sort(cl_poles.real)[::-1]
    # One pole pair stays slow whatever the weights: five rest lengths act on that mode only
    # weakly (check it with the PBH tests of tmfem.control.linear.pbh).
    print(f"closed loop (linear): slowest poles {slow[0]:.2e}, next {slow[2]:.2f} 1/s")

    # The same gain on the nonlinear model: its plant outputs the full state y = [z, z'],
    # the controller acts on y - y_e and adds u_e (zero-order hold at dt).
    z_e = com.equilibrium(com.u0).state
    plant = StatePlant(com, z0=z_e)
    i = list(com.z_names).index("theta_11")
    plant.v0 = np.zeros(com.nz)
    plant.v0[i] = 0.02                                  # a push: theta_11' = 0.02 rad/s
    controller = LinearController(-K, u_e=lin.u_e, y_e=np.concatenate([lin.z_e, np.zeros(com.nz)]))
    for name, ctrl in (("open loop", None), ("LQR", controller)):
        run = simulate(plant, t_end=4.0, dt=0.01, controller=ctrl)
        d = run.y[:, i] - z_e[i]
        print(f"{name:9s}: theta_11 deviation, first second {np.abs(d[:100]).max():.2e} rad, "
              f"last second {np.abs(d[-100:]).max():.2e} rad")
    return G, cl_poles


if __name__ == "__main__":
    main()
