"""Tension-controlled tendon actuators on the FE plants (docs/guides/fe-plant.md "A
tension-controlled actuator"): the command u_c of the COM-designed controller becomes the COM's
tendon tension T_d = max(0, k (|d(q)| - u_c)) at the measured q, realised on the FE tendons
(:mod:`tmfem.control.fe_plant.tension_actuation`)."""
import numpy as np
import pytest

from tmfem.cli import build_parser
from tmfem.cli.deploy import check_plant
from tmfem.control.deployment.run import run_deployment
from tmfem.control.deployment.limits import RestLengthLimits
from tmfem.control.fe_plant.state_estimate import (FEStatePlant, deployment_plant, mtc_deployment_plant,
                                          sbc_deployment_plant)
from tmfem.control.fe_plant.tension_actuation import fe_element_lengths, rest_length_for_tension
from tmfem.errors import InputError
from tmfem.reference.deployments import setup
from tmfem.simulation.driver import simulate
from tmfem.system import load_preset


@pytest.fixture(scope="module")
def dep():
    """The 1-4(D) deployment (adaptive PFL at the reference, uncertainty 'initial' of 7.4, no
    switch) and its force-actuated 4 x 4 x 4 SBC plant (rigid-fit bars, beta = 1e-3 s)."""
    s = setup("1-4D", controller="adaptive", evaluation="reference")
    init = load_preset("1-4D-initial")
    return s, init, sbc_deployment_plant(s.model, init, mesh_n=4, beta=1e-3, actuation="force")


def _svk_tendon_forces(dyn, x, r):
    """The FE tendon forces [N] at state x under rest lengths r, written out here from the
    positions: the mean of each tendon's k St.Venant-Kirchhoff truss elements (eqs. 4.9,
    4.23; rest length r / k, cable EA), N = EA (l^2 - L^2) l / (2 L^3), zero when slack."""
    topo = dyn.model.topology
    xf = dyn.positions(x)
    a, b = topo.tendon_conn
    l = np.linalg.norm(xf[:, b] - xf[:, a], axis=0)
    e, k = topo.tendon_of_element, topo.tendon_elements
    L = r[e] / k
    EA = dyn.model.tendon_EA[e]
    N = np.where(l > L, EA * (l**2 - L**2) * l / (2 * L**3), 0.0)
    return np.bincount(e, weights=N) / k, np.bincount(e, weights=l)


def test_actuator_holds_the_com_tension_at_the_start_of_every_step(dep):
    """Over 0.3 s of the closed loop: at the start of every step the rest lengths the FE model
    is integrated with (those of every residual evaluation of the step, captured on the plant)
    are the actuator's for the sampled state, the FE tendon force they give there (written out
    from the node positions, :func:`_svk_tendon_forces`) equals T_d = max(0, k (|d(q)| - u_c))
    computed from the COM's own tendon forces (``ControlOrientedModel.tendon_forces``, eq. 3.8)
    at the measured z to 1e-8 N, T_d >= 0, and the FE rest length never exceeds the FE tendon
    length. Where T_d = 0 (SU at its limit) r = L: the force left is the spread of the element
    lengths (below 0.05 N)."""
    s, _, plant = dep
    com = s.model
    lim = RestLengthLimits(s.controller, model=com)
    seen, samples = [set()], []          # residual calls before the first sample, then per step
    residual = plant.dyn.residual

    def spy(x, v, a, t, u=None):
        seen[-1].add(np.asarray(u).tobytes())
        return residual(x, v, a, t, u)

    def record(t, x, v, a, u, y):
        samples.append((x.copy(), u.copy(), y[:com.nz].copy()))
        seen.append(set())

    plant.dyn.residual = spy
    try:
        simulate(plant, t_end=0.3, dt=0.01, controller=lim, record=record, jacobian="step")
    finally:
        plant.dyn.residual = residual
    assert len(samples) == 31
    Td_all = []
    for (x, uc, z), used in zip(samples[:-1], seen[1:-1]):
        r = plant.actuate(x, uc)
        assert used == {r.tobytes()}
        Td = np.maximum(0.0, com.tendon_forces(z, uc))
        T, L = _svk_tendon_forces(plant.dyn, x, r)
        taut = Td > 0
        assert np.all(np.abs(T - Td)[taut] < 1e-8)
        assert np.all(T[~taut] < 0.05)
        assert np.all(r <= L + 1e-15)
        Td_all.append(Td)
    Td_all = np.array(Td_all)
    assert np.all(Td_all >= 0) and np.max(Td_all) > 10.0 and np.any(Td_all == 0.0)


@pytest.mark.parametrize("law", ["cable", "fixed-rate"])
def test_rest_length_for_tension_against_the_mtc_elements(law):
    """On an MTC plant of either tendon law (2-3, 3 x 2 x 2), from a perturbed state: the
    rest lengths of :func:`rest_length_for_tension` give, through the MTC model's own tension-
    only truss elements (``member_forces``), the tendon forces asked for (2, 5, 20, 50 N ...)
    to 1e-9 N, a zero demand gives r = L, and a negative one is refused."""
    s = setup("2-3-deploy", controller="adaptive")
    plant = mtc_deployment_plant(s.model, load_preset("2-3-deploy-initial"), mesh_n=2,
                                 tendon_law=law, actuation="force")
    dyn = plant.dyn
    x = plant.x0 + 1e-4 * np.random.default_rng(5).standard_normal(plant.x0.size)
    n_t = len(dyn.model.system.tendons)
    T = np.resize([2.0, 5.0, 20.0, 50.0, 0.0], n_t)
    le = fe_element_lengths(dyn, x)
    r = rest_length_for_tension(dyn.model, le, T)
    dyn.model.set_tendon_lengths(r)
    got = dyn.member_forces(x)["tendon_force"]
    dyn.model.set_tendon_lengths(dyn.u0)
    L = np.bincount(dyn.model.topology.tendon_of_element, weights=le)
    assert np.all(np.abs(got - T)[T > 0] < 1e-9)
    assert np.all(r[T == 0] == L[T == 0]) and np.all(r <= L)
    with pytest.raises(InputError, match="cannot push"):
        rest_length_for_tension(dyn.model, le, -T - 1.0)


@pytest.mark.slow
def test_force_actuated_run_follows_the_com_run(dep):
    """The 7.4 1-4(D) controller on the force-actuated 4 x 4 x 4 SBC plant against the same
    controller on the COM plant, 0.5 s: no divergence, no commanded rest length above the
    COM tendon length (the limits on u_c) nor an FE rest length above the FE tendon length,
    the bars within the start offset of the COM run (3.71 mrad: the SBC's rigid-fit q_0 of
    bars bent at H_1j, the same on either actuation) and from 0.3 s within 0.5 mrad of it
    (measured 0.16 / 0.14 mrad at 0.3 / 0.5 s), where the rest-length actuated plant stays
    3.3-3.8 mrad off (the SBC's tendons hold other forces than the COM's at the same q).
    The bound: the force actuator gives the SBC the COM's tendon forces at the measured q,
    so what is left is the bars' and membrane's dynamics, an order below the offset."""
    s, init, _ = dep
    runs = {}
    for act in ("force", "rest-length"):
        sf = setup("1-4D", controller="adaptive", evaluation="reference")
        p = sbc_deployment_plant(sf.model, init, mesh_n=4, beta=1e-3, actuation=act)
        runs[act] = run_deployment(model=sf.model, reference=sf.reference,
                                   controller=sf.controller, z0=sf.z0, t_end=0.5, plant=p,
                                   partial=True, jacobian="step")
    sc = setup("1-4D", controller="adaptive", evaluation="reference")
    rc = run_deployment(model=sc.model, reference=sc.reference, controller=sc.controller,
                        z0=sc.z0, t_end=0.5)
    r = runs["force"]
    assert r.failure is None and r.t[-1] == pytest.approx(0.5)
    assert np.all(r.u <= r.lengths + 1e-12)
    assert r.plant_report["min_fe_rest_length_margin_m"] >= 0.0
    assert np.all(r.actuator["fe_rest_lengths"] > 0)
    nq = s.model.nq
    dev = {a: np.max(np.abs(x.z[:, :nq] - rc.z[:, :nq]), axis=1) for a, x in runs.items()}
    late = r.t >= 0.3 - 1e-9
    assert np.max(dev["force"]) < 3.8e-3
    assert np.max(dev["force"][late]) < 5e-4
    assert np.min(dev["rest-length"][late]) > 2e-3


def test_force_actuation_refused_without_an_fe_plant(dep):
    """--plant-actuation belongs to an FE plant: refused with --plant com alone (the COM is
    the design model, whose tendon forces the actuator reproduces), accepted with an FE plant
    of the comparison and with the MTC plant; the library refuses it for the COM and refuses
    an unknown actuation."""
    s, init, plant = dep
    parse = build_parser().parse_args
    with pytest.raises(InputError, match="COM is the design model"):
        check_plant(parse(["deploy", "--preset", "1-4D", "--plant-actuation", "force"]))
    with pytest.raises(InputError, match="belongs to --plant mtc|sbc"):
        check_plant(parse(["deploy", "--preset", "1-4D", "--plant-actuation", "rest-length"]))
    assert check_plant(parse(["deploy", "--preset", "1-4D", "--compare-plant", "sbc",
                              "--plant-actuation", "force", "--plant-mesh", "4"])) == 4
    assert check_plant(parse(["deploy", "--preset", "2-3-deploy", "--plant", "mtc",
                              "--plant-actuation", "force", "--plant-mesh", "2"])) == 2
    with pytest.raises(InputError, match="expected an FE plant"):
        deployment_plant("com", s.model, init, actuation="force")
    with pytest.raises(InputError, match="plant actuation"):
        FEStatePlant(plant.dyn, s.model, actuation="winch")


def test_force_actuation_sets_the_pfl_tendon_model_and_the_json():
    """With force actuation the FE plant's tendons follow the COM's law at the measured q, so
    the PFL's tendon model is the COM's fixed rates (no model-error warning for either plant
    of a comparison), and the JSON names the actuation."""
    from tmfem.reference.deployment_plants import FEPlantOptions
    parse = build_parser().parse_args
    a = parse(["deploy", "--preset", "2-3-deploy", "--plant", "mtc", "--plant-actuation", "force",
               "--compare-plant", "com"])
    assert FEPlantOptions.of(a).fe_tendon_model() == "fixed-rate"
    o = FEPlantOptions.of(a)
    assert o.controlled_tendon_law("mtc") == o.controlled_tendon_law("com") == "fixed-rate"
    assert FEPlantOptions.of(a).summary("mtc", 2)["plant_actuation"] == "force"
    b = parse(["deploy", "--preset", "2-3-deploy", "--plant", "mtc"])
    assert FEPlantOptions.of(b).fe_tendon_model() == "cable"
