"""The MTC finite-element model as the plant of controllers designed on the control-oriented
model: the COM-state estimate (tmfem.control.fe_plant.state_estimate) and a closed loop."""
import numpy as np
import pytest

from tmfem.control.deployment.run import StatePlant, lqr_state_feedback
from tmfem.control.fe_plant.state_estimate import COMStateEstimator, FEStatePlant, fe_state_of
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
    x_eq = fe.equilibrium().x
    z_e = com.equilibrium(com.u0, z0=com.z0).state
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
        COMStateEstimator(com, MTCDynamics(other, other.equilibrium().x))


@pytest.mark.slow
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
    com_plant.v0 = np.zeros(com.nz)
    com_plant.v0[iq] = 0.02
    runs = {}
    for name, plant in (("com", com_plant), ("mtc", fe_plant)):
        sim = simulate(plant, t_end=3.0, dt=0.01, controller=ctrl, jacobian="iteration")
        runs[name] = sim.y[:, iq] - sim.y[0, iq]
    for name, d in runs.items():
        peak, late = np.max(np.abs(d[:100])), np.max(np.abs(d[-100:]))
        assert late < 0.5 * peak, (name, peak, late)
    peak = np.max(np.abs(runs["com"]))
    assert np.max(np.abs(runs["mtc"] - runs["com"])) < 0.25 * peak


@pytest.mark.parametrize("law", ["cable", "fixed-rate"])
def test_tendon_law_of_a_changed_rest_length(law):
    """A straight tendon (3 Green-strain trusses, eq. 4.1) of length l at rest length u:
    N = EA' (l^2 - u^2) / (2 u^2) l / u with EA' = EA ("cable", eq. 3.9 at the current rest
    length) or EA u / r_0 ("fixed-rate": the spring rate EA / r_0 of eq. 5.19's B(x) u)."""
    from tmfem.models.mtc.post import member_state
    s = load_preset("2-3-deploy")
    fe = MTCModel(s, mesh_n=4, rest_lengths="system", tendon_law=law)
    x = fe.full(fe.reduce(fe.with_straight_tendons(fe.initial_positions("design"))))
    l = s.tendon_lengths(s.q)
    u = 0.97 * l
    fe.set_tendon_lengths(u)
    N = member_state(fe, x)["tendon_force"]
    EA = s.tendon_EA * (u / fe.nominal_rest_lengths if law == "fixed-rate" else 1.0)
    np.testing.assert_allclose(N, EA * (l**2 - u**2) / (2 * u**2) * l / u, rtol=1e-9)


def test_tendon_law_refused():
    with pytest.raises(InputError, match="tendon_law"):
        MTCModel(load_preset("2-3-deploy"), mesh_n=4, tendon_law="spring")


def test_start_rest_lengths_hold_the_packaged_design():
    """The packaged 2-3 design's tendon forces T = EA (|d| - r) / r (eqs. 3.8-3.9) are what
    each tendon law produces at the start rest lengths (cable: the design's own; fixed rate
    k = EA / r_0: r = |d| - T r_0 / EA)."""
    from tmfem.control.fe_plant.state_estimate import start_rest_lengths
    init, final = load_preset("2-3-deploy-initial"), load_preset("2-3-deploy")
    L = init.tendon_lengths(init.q)
    T = init.tendon_EA * (L - init.rest_lengths) / init.rest_lengths
    r0 = final.rest_lengths
    np.testing.assert_array_equal(start_rest_lengths(init, "cable", r0), init.rest_lengths)
    r = start_rest_lengths(init, "fixed-rate", r0)
    np.testing.assert_allclose(init.tendon_EA / r0 * (L - r), T, rtol=1e-12)


@pytest.mark.parametrize("argv, code, needle", [
    (["deploy", "--preset", "2-3-deploy", "--plant-mesh", "8"], 2, "--plant-mesh belongs to --plant mtc"),
    (["deploy", "--preset", "2-3-deploy", "--plant-tendons", "cable"], 2, "--plant-tendons belongs to --plant mtc"),
    (["deploy", "--preset", "1-4D", "--plant", "mtc"], 2, "1-N(D) system"),
    (["deploy", "--preset", "2-3-deploy", "--plant", "mtc", "--plant-mesh", "1"], 2, "expected an integer >= 2"),
    (["deploy", "--preset", "2-3-deploy", "--plant", "mtc", "--plant-mesh", "4000"], 3, "--plant-mesh 4000"),
])
def test_deploy_plant_options_refused_before_work(argv, code, needle, capsys):
    """Options of the FE plant that do not apply or cannot fit are refused with one line
    before the controller design (exit 2 bad input, 3 resource limit; docs/guides/cli.md)."""
    from tmfem.cli import main
    rc = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == code and needle in err[-1]


def test_deployment_start_on_the_mtc_plant():
    """The first 0.3 s of the 2-3 deployment (adaptive PFL of 7.4) on the MTC plant with the
    COM's fixed-rate tendons, through run_deployment's plant hook: the plant starts at rest in
    its own equilibrium of the packaged design (within 2.5 mrad of the COM's z0), the run
    records the estimated state and the FE report, and the bars follow the reference within
    5 mrad (the COM plant: within 1.7 mrad; docs/guides/fe-plant.md)."""
    from tmfem.reference.deployments import setup
    from tmfem.control.deployment.run import run_deployment
    from tmfem.control.fe_plant.state_estimate import mtc_deployment_plant
    s = setup("2-3-deploy", controller="adaptive")
    plant = mtc_deployment_plant(s.model, load_preset("2-3-deploy-initial"), mesh_n=10,
                                 tendon_law="fixed-rate")
    nq = s.model.nq
    assert np.max(np.abs(plant.outputs(plant.x0)[:nq] - s.z0[:nq])) < 2.5e-3
    r = run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                       t_end=0.3, dt=0.01, plant=plant, jacobian="step")
    assert r.plant_report["model"] == "mtc" and r.w.shape == (31, 3)
    assert np.max(np.abs(r.z[:, :nq] - r.q_d)) < 5e-3
