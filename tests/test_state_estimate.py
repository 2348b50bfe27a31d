"""The MTC finite-element model as the plant of controllers designed on the control-oriented
model (issue 15): the COM-state estimate (tmfem.control.state_estimate) and a closed loop."""
import numpy as np
import pytest

from tmfem.control.deploy import StatePlant, lqr_state_feedback
from tmfem.control.state_estimate import COMStateEstimator, FEStatePlant, fe_state_of
from tmfem.errors import InputError
from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes
from tmfem.models.mtc.dynamics import MTCDynamics
from tmfem.models.mtc.model import MTCModel
from tmfem.simulation.driver import simulate
from tmfem.system import load_preset


@pytest.fixture(scope="module")
def models():
    """COM and 3x10x10 MTC of the deployed 2-3 system (Table 7.7, preset 2-3-deploy)."""
    s = load_preset("2-3-deploy")
    com = ControlOrientedModel(s, membrane_modes=default_membrane_modes(s), rest_lengths="system")
    fe = MTCModel(s, mesh_n=10, rest_lengths="system")
    x_eq = fe.solve_static().x
    z_e = com.equilibrium(com.u0, z0=com.z0)
    return s, com, fe, x_eq, z_e


def test_estimate_inverts_the_com_placement(models):
    """An FE state placed on the COM's own field (eqs. 5.1, 5.3: bars at q, membrane at
    P_0 + Psi Delta(q) + Phi eta) is estimated back exactly, rates included."""
    s, com, fe, x_eq, z_e = models
    dyn = MTCDynamics(fe, x_eq)
    est = COMStateEstimator(com, dyn)
    rng = np.random.default_rng(1)
    z = z_e + 1e-3 * rng.standard_normal(com.nz)
    zd = 1e-2 * rng.standard_normal(com.nz)
    x, v = fe_state_of(com, dyn, z, zd)
    z_hat, zd_hat = est.state(x, v)
    np.testing.assert_allclose(z_hat, z, rtol=0, atol=1e-12)
    np.testing.assert_allclose(zd_hat, zd, rtol=0, atol=1e-8)


def test_other_system_refused(models):
    s, com, fe, x_eq, z_e = models
    other = MTCModel(load_preset("2-3-deploy"), mesh_n=4, rest_lengths="system")
    with pytest.raises(InputError, match="same System"):
        COMStateEstimator(com, MTCDynamics(other, other.solve_static().x))


def test_lqr_designed_on_the_com_damps_the_mtc_plant(models):
    """A state feedback designed on the COM linearisation (eq. 5.33, LQR with R = I / u_m^2)
    closed around the MTC plant through the estimate: from theta_11' = 0.02 rad/s (6.5.2
    style) the bar motion decays as it does on the COM plant, and the two closed loops stay
    close (the stated bound: 25 % of the peak deviation)."""
    s, com, fe, x_eq, z_e = models
    ctrl, _ = lqr_state_feedback(com, u_e=com.u0, z_e=z_e, u_m=0.01)
    iq = list(s.q_names).index("theta_11")
    fe_plant = FEStatePlant(MTCDynamics(fe, x_eq, perturb={"theta_11_dot": 0.02}), com)
    com_plant = StatePlant(com, z0=z_e)
    com_plant.v0 = np.zeros(com.nz); com_plant.v0[iq] = 0.02
    runs = {}
    for name, plant in (("com", com_plant), ("mtc", fe_plant)):
        sim = simulate(plant, t_end=3.0, dt=0.01, controller=ctrl, jacobian="iteration")
        runs[name] = sim.y[:, iq] - sim.y[0, iq]
    for name, d in runs.items():
        peak, late = np.max(np.abs(d[:100])), np.max(np.abs(d[-100:]))
        assert late < 0.5 * peak, (name, peak, late)
    peak = np.max(np.abs(runs["com"]))
    assert np.max(np.abs(runs["mtc"] - runs["com"])) < 0.25 * peak
