"""The simulation driver with a controller in the loop.

Independent references: python-control's own responses of the same closed loop --
(1) the exact zero-order-hold discretisation of the linearised plant (``sample_system``)
closed by the same sampled state feedback, which Park's method must match to its O(dt^2)
integration error; (2) the continuous closed loop A - B K, which the sampled loop
approaches as O(dt).
"""
import control
import numpy as np
import pytest

from tmfem.errors import InputError
from tmfem.models.com.linearize import linearize
from tmfem.models.com.model import ControlOrientedModel
from tmfem.simulation import LinearController, OpenLoop, simulate
from tmfem.system import load_preset


@pytest.fixture(scope="module")
def lin14():
    model = ControlOrientedModel(load_preset("1-4"), membrane_modes=2)
    return linearize(model)


def _lqr_gain(lin):
    """A stabilising state feedback of the linearised 1-4 COM (python-control lqr)."""
    A, B = lin.A, lin.B
    K, _, _ = control.lqr(A, B, np.eye(A.shape[0]), 1e3 * np.eye(B.shape[1]))
    return np.asarray(K)


def _closed_loop_runs(lin, K, dt, t_end):
    n = lin.M.shape[0]
    x0 = lin.z_e.copy()
    x0[0] += 1e-3                                         # theta_11 offset [rad]
    # state feedback on the full state [z - z_e; z']: the plant's outputs are the states here
    Cx = np.eye(2 * n)
    plant = lin.plant(x0=x0)
    plant.Cy, plant.y_e = Cx, np.concatenate([lin.z_e, np.zeros(n)])
    plant.output_names = lin.state_names
    ctrl = LinearController(-K, u_e=lin.u_e, y_e=plant.y_e, name="state feedback")
    sim = simulate(plant, t_end=t_end, dt=dt, controller=ctrl, scheme="trapezoidal",
                   jacobian="iteration", tol=1e-13)
    xs0 = np.concatenate([x0 - lin.z_e, np.zeros(n)])
    ss = control.ss(lin.A, lin.B, np.eye(2 * n), 0)
    sd = control.sample_system(ss, dt, method="zoh")
    disc = control.feedback(sd, control.ss([], [], [], K, dt=dt), sign=-1)
    rd = control.initial_response(disc, T=sim.t, X0=xs0)
    cont = control.feedback(ss, K, sign=-1)
    rc = control.initial_response(cont, T=sim.t, X0=xs0)
    ours = sim.y - plant.y_e
    return ours, np.asarray(rd.outputs).T, np.asarray(rc.outputs).T, sim


def test_state_feedback_reproduces_python_control_closed_loop(lin14):
    K = _lqr_gain(lin14)
    errs = []
    for dt in (0.005, 0.0025):
        ours, disc, cont, sim = _closed_loop_runs(lin14, K, dt, t_end=2.0)
        scale = np.abs(disc).max()
        errs.append(np.abs(ours - disc).max() / scale)
        assert np.abs(ours - cont).max() / scale < 0.02          # O(dt) sampling delay
        assert sim.controller[-1] == "state feedback" and len(sim.t) == int(round(2.0 / dt)) + 1
    # Park/trapezoidal is second order: halving dt divides the error by about 4
    assert errs[1] < 3e-3
    assert 3.0 < errs[0] / errs[1] < 5.0


def test_open_loop_schedule_and_bad_input(lin14):
    plant = lin14.plant()
    sim = simulate(plant, t_end=0.1, dt=0.01, controller=OpenLoop(lin14.u_e))
    # at the equilibrium with the nominal input nothing moves
    assert np.abs(sim.y - lin14.y_e).max() < 1e-12
    with pytest.raises(InputError, match="at least one step"):
        simulate(plant, t_end=0.001, dt=0.01)
    with pytest.raises(InputError, match="finite inputs"):
        simulate(plant, t_end=0.1, dt=0.01, controller=lambda t: np.full(lin14.u_e.size, np.nan))


def test_first_step_uses_the_controllers_first_input(lin14):
    # a step of the inputs at t = 0 (the first controller output differs from the plant's
    # nominal u0): Park's trapezoidal start must use the acceleration of that input.
    # Reference: the exact response of the linear plant to the constant input
    # (python-control forced_response of the continuous system). With the start
    # acceleration of u0 instead the error halves only (6.7 % -> 2.9 %).
    plant = lin14.plant()
    du = 1e-4 * np.ones(lin14.u_e.size)
    n = lin14.M.shape[0]
    ss = control.ss(lin14.A, lin14.B, lin14.Cy, 0)
    errs = []
    for dt in (0.01, 0.005):
        sim = simulate(plant, t_end=1.0, dt=dt, controller=OpenLoop(lin14.u_e + du))
        ref = control.forced_response(ss, T=sim.t, U=np.tile(du[:, None], (1, sim.t.size)),
                                      X0=np.zeros(2 * n))
        want = np.asarray(ref.outputs).T
        errs.append(np.abs(sim.y - lin14.y_e - want).max() / np.abs(want).max())
    # second order (Park after the trapezoidal start): halving dt divides the error by ~4
    assert errs[1] < 0.01
    assert 3.0 < errs[0] / errs[1] < 5.0
