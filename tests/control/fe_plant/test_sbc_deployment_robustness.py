"""The 1-4(D) deployment on the SBC plant (docs/guides/fe-plant.md "What was tried"): the
rigid-body measurement of the beam bars, the damped feedback inversion of the PFL and the
Rayleigh damping of the FE plant, each against a closed form or the COM run."""
import os

import numpy as np
import pytest

from tmfem.control.deployment.run import StatePlant, run_deployment
from tmfem.control.deployment.pfl import PFLTerms, bounded_inversion
from tmfem.control.fe_plant.state_estimate import (FEStatePlant, rigid_bar_fit, sbc_deployment_plant,
                                          start_rest_lengths)
from tmfem.errors import InputError
from tmfem.models.fe.outputs import q_from_positions
from tmfem.reference.deployments import setup
from tmfem.simulation.controllers import OpenLoop
from tmfem.simulation.driver import simulate
from tmfem.system import load_preset

REDUCED = os.environ.get("TMFEM_SLOW_SCALE") == "reduced"
#: fractions of the 1-4(D) SBC bar chain (A, two nodes, H_1j at 1/4, two nodes, B)
CHAIN = np.array([0.0, 1 / 12, 1 / 6, 0.25, 0.5, 0.75, 1.0])


def _chains(system, q, s):
    """Chain nodes (3, n_bars, n) on the chords of the bars at q."""
    X = system.nodes(q)
    n = system.M * system.N
    a, b = X[:, :n], X[:, n:2 * n]
    return a[:, :, None] + (b - a)[:, :, None] * s[None, None, :]


@pytest.mark.parametrize("preset", ["1-4D", "2-3-deploy"])
def test_rigid_fit_of_straight_bars_is_their_chord(preset):
    """Straight bars (stage 1 on fixed bases; the 2-3 stage-2 bars of free base): the rigid
    fit returns the q of their end nodes (eqs. 3.1-3.2) to round-off."""
    system = load_preset(preset)
    q = np.asarray(system.q, dtype=float)
    s = np.linspace(0.0, 1.0, 4) if preset == "2-3-deploy" else CHAIN
    got = rigid_bar_fit(system, _chains(system, q, s), s)
    ref = q_from_positions(system, system.nodes(q))
    assert np.max(np.abs(got - ref)) < 1e-12


@pytest.mark.parametrize("preset", ["1-4D", "2-3-deploy"])
def test_rigid_fit_of_two_node_bars_is_their_chord(preset):
    """A bar of two nodes (the MTC model's truss bars) is its chord whatever the positions:
    with the nodes moved at random by up to 5 mm (the bar stretched and turned, a free base
    moved), the rigid fit (lumped masses 1/2, 1/2) returns the q of the end nodes (eqs.
    3.1-3.2) to round-off -- so the MTC plant's chord measurement is the SBC plant's default
    rigid fit."""
    system = load_preset(preset)
    q = np.asarray(system.q, dtype=float)
    s = np.array([0.0, 1.0])
    X = _chains(system, q, s)
    X[:, :, 1:] += 5e-3 * np.random.default_rng(3).uniform(-1, 1, X[:, :, 1:].shape)
    free = np.arange(system.M * system.N) >= system.N        # stage 2: the base moves too
    X[:, free, 0] += 5e-3 * np.random.default_rng(4).uniform(-1, 1, X[:, free, 0].shape)
    got = rigid_bar_fit(system, X, s)
    ends = q_from_positions(system, np.concatenate([X[:, :, 0], X[:, :, 1]], axis=1))
    assert np.max(np.abs(got - ends)) < 1e-12


def test_sbc_plant_measures_the_rigid_fit_by_default(dep):
    """The SBC plant's bar measurement defaults to the rigid fit (the chords see the beams'
    bending modes, docs/guides/fe-plant.md), on the library's plant as on the CLI's."""
    from tmfem.reference.deployment_plants import FEPlantOptions
    from tmfem.cli import build_parser
    s, init, plant, _ = dep
    assert plant.estimator.bars == "rigid"
    args = build_parser().parse_args(["deploy", "--preset", "1-4D", "--plant", "sbc"])
    assert FEPlantOptions.of(args).arguments("sbc")["bars"] == "rigid"
    assert FEStatePlant(plant.dyn, s.model, bars="chord").estimator.bars == "chord"


def test_rigid_fit_ignores_a_bending_shape_orthogonal_to_the_rotation():
    """A bar on a fixed base bent by a shape phi(s) = s^2 (s - c) normal to it, with c such
    that sum_i m_i s_i phi_i = 0 (mass-orthogonal to the rigid rotation about A): the fit
    keeps the straight bar's q exactly, while the chord turns by delta phi(1) / l."""
    system = load_preset("1-4D")
    q = np.asarray(system.q, dtype=float)
    s = CHAIN
    m = np.zeros_like(s)
    m[:-1] += 0.5 * np.diff(s)
    m[1:] += 0.5 * np.diff(s)
    c = np.sum(m * s**4) / np.sum(m * s**3)            # sum m s (s^3 - c s^2) = 0
    phi = s**2 * (s - c)
    X = _chains(system, q, s)
    n = system.M * system.N
    delta = 2e-3
    for j in range(n):
        d = X[:, j, -1] - X[:, j, 0]
        nrm = np.cross(d, [0.0, 0.0, 1.0])
        X[:, j, :] += delta * np.outer(nrm / np.linalg.norm(nrm), phi)
    got = rigid_bar_fit(system, X, s)
    assert np.max(np.abs(got - q_from_positions(system, system.nodes(q)))) < 1e-12
    chord = q_from_positions(system, np.concatenate([X[:, :, 0], X[:, :, -1]], axis=1))
    l = np.linalg.norm(X[:, 0, -1] - X[:, 0, 0])
    assert np.max(np.abs(chord - q)) == pytest.approx(delta * abs(phi[-1]) / l, rel=0.05)


@pytest.fixture(scope="module")
def dep():
    s = setup("1-4D", controller="adaptive")
    init = load_preset("1-4D-initial")
    return s, init, sbc_deployment_plant(s.model, init, mesh_n=4), \
        start_rest_lengths(init, "cable", s.model.u0)


def test_rigid_measurement_follows_the_com_input_response(dep):
    """psi_11 after a 1 mm step of the four SL rest lengths (as
    models/sbc/test_sbc_plant.py::test_sbc_input_response_against_the_com): measured as the bars' rigid
    fit, the SBC's response has the COM's sign from the first sample and stays within 25 %
    of it at 10-100 ms (measured 0 %, -14 %, -19 %, -19 % at 10, 20, 50, 100 ms on 4 x 4 x 4),
    where the chord moves the other way over the first 30 ms."""
    s, init, plant, r0 = dep
    rigid = FEStatePlant(plant.dyn, s.model, bars="rigid")
    ipsi = list(s.model.system.q_names).index("psi_11")
    u = r0.copy()
    u[:4] += 1e-3
    d = {}
    for name, p in (("com", StatePlant(s.model, z0=s.z0)), ("rigid", rigid)):
        base = simulate(p, t_end=0.1, dt=0.01, controller=r0, jacobian="step").y[:, ipsi]
        step = simulate(p, t_end=0.1, dt=0.01, controller=u, jacobian="step").y[:, ipsi]
        d[name] = (step - base)[[1, 2, 5, 10]]
    assert np.all(d["com"] > 0) and np.all(d["rigid"] > 0)
    assert np.max(np.abs(d["rigid"] / d["com"] - 1)) < 0.25


def test_bar_measurement_and_damping_refused_where_they_do_not_apply(dep, capsys):
    from tmfem.cli import main
    from tmfem.control.fe_plant.state_estimate import deployment_plant
    s, init, plant, _ = dep
    with pytest.raises(InputError, match="expected one of"):
        FEStatePlant(plant.dyn, s.model, bars="beam")
    with pytest.raises(InputError, match="expected the SBC plant"):
        deployment_plant("com", s.model, init, bars="rigid")
    with pytest.raises(InputError, match="expected an FE plant"):
        deployment_plant("com", s.model, init, beta=1e-3)
    for argv, needle in ((["--preset", "1-4D", "--plant-bars", "rigid"], "belongs to an SBC plant"),
                         (["--preset", "2-3-deploy", "--plant", "mtc", "--plant-bars", "rigid"],
                          "belongs to an SBC plant"),
                         (["--preset", "1-4D", "--plant-damping", "1e-3"], "--plant-damping belongs"),
                         (["--preset", "2-3-lpv", "--plant-bars", "rigid"], "belongs to an SBC plant")):
        assert main(["deploy", *argv, "--t-end", "0.05"]) == 2
        assert needle in capsys.readouterr().err


def test_damped_inversion_closed_form():
    """bounded_inversion with damping mu: u = V diag(s / (s^2 + (mu s_1)^2)) U^T R v for
    R B_q = U S V^T (M_q = R^T R), the exact inverse for mu = 0; with active limits the
    damped objective at the bounded solution is no larger than at the clipped damped one."""
    rng = np.random.default_rng(4)
    n = 6
    A = rng.standard_normal((n, n))
    Mq = A @ A.T + n * np.eye(n)
    B = rng.standard_normal((n, n)) @ np.diag(np.logspace(0, -2, n))
    terms = PFLTerms(M_q=Mq, F_q=np.zeros(n), B_q=B, M12=None, M22=None, F2=None)
    v = rng.standard_normal(n)
    u0, act = bounded_inversion(terms, v, lower=-np.inf, upper=np.inf)
    assert not act and np.allclose(B @ u0, v, atol=1e-12)
    R = np.linalg.cholesky(Mq).T
    U, sv, Vt = np.linalg.svd(R @ B)
    mu = 0.05
    lam = mu * sv[0]
    u, act = bounded_inversion(terms, v, lower=-np.inf, upper=np.inf, damping=mu)
    assert not act
    assert np.allclose(u, Vt.T @ (sv / (sv**2 + lam**2) * (U.T @ R @ v)), atol=1e-12)
    lim = 0.5 * np.max(np.abs(u))
    ub, act = bounded_inversion(terms, v, lower=-lim, upper=lim, damping=mu)

    def J(x):
        return np.sum((R @ (B @ x - v))**2) + lam**2 * np.sum(x**2)
    assert act and np.all(np.abs(ub) <= lim + 1e-12)
    assert J(ub) <= J(np.clip(u, -lim, lim)) + 1e-12
    with pytest.raises(InputError, match="expected >= 0"):
        bounded_inversion(terms, v, lower=-1, upper=1, damping=-1.0)


@pytest.mark.slow
def test_undamped_sbc_plant_fails_under_the_com_rest_lengths(dep):
    """Whether the integrator or the controller fails (docs/guides/fe-plant.md): the rest lengths of
    the COM's own closed-loop 1-4(D) run (uncertainty 'exact', eq. 5.58), applied open loop
    to the 4 x 4 x 4 SBC plant, stop Park's Newton method before 2.5 s (measured 2.35 s, with
    every tendon taut: 6.8 N at least), and with stiffness-proportional Rayleigh damping
    beta = 1e-3 s the same inputs integrate to 2.5 s."""
    s, init, _, _ = dep
    sc = setup("1-4D", controller="adaptive", uncertainty="exact")
    com = run_deployment(model=sc.model, reference=sc.reference, controller=sc.controller,
                         z0=sc.z0, t_end=2.5)
    U = com.u
    runs = {}
    for beta in (0.0, 1e-3):
        plant = sbc_deployment_plant(sc.model, init, mesh_n=4, beta=beta)
        ol = OpenLoop(lambda t: U[min(int(np.floor(t / 0.01 + 1e-9)), len(U) - 1)])
        runs[beta] = run_deployment(model=sc.model, reference=sc.reference, controller=ol,
                                    z0=sc.z0, t_end=2.5, plant=plant, partial=True,
                                    jacobian="step")
    assert runs[0.0].failure and runs[0.0].t[-1] < 2.45
    assert runs[0.0].plant_report["tendon_slack_samples"] == 0
    assert runs[1e-3].failure is None and runs[1e-3].t[-1] == pytest.approx(2.5)


@pytest.mark.slow
def test_1_4d_on_the_sbc_plant_with_the_rigid_measurement_follows_the_com_run(dep):
    """The 7.4 1-4(D) controller (uncertainty 'initial' of eq. 5.72, the PFL at the
    reference, the CLI's defaults with an FE plant) on the 4 x 4 x 4 SBC plant measured
    through the bars' rigid fit, with Rayleigh damping beta = 1e-3 s: over 0.4 s the run does
    not diverge (with the chords it diverges at 0.08 s), commands no rest length above its
    tendon's length, and its bars stay within 5 mrad of the COM run of the same controller
    (measured 3.9 mrad, the 3.7 mrad start offset of the bars' static bending included)."""
    s, init, _, _ = dep
    sf = setup("1-4D", controller="adaptive", evaluation="reference")
    plant = sbc_deployment_plant(sf.model, init, mesh_n=4, bars="rigid", beta=1e-3)
    r = run_deployment(model=sf.model, reference=sf.reference, controller=sf.controller,
                       z0=sf.z0, t_end=0.4, plant=plant, partial=True, jacobian="step")
    sc = setup("1-4D", controller="adaptive", evaluation="reference")
    rc = run_deployment(model=sc.model, reference=sc.reference, controller=sc.controller,
                        z0=sc.z0, t_end=0.4)
    assert r.failure is None and r.t[-1] == pytest.approx(0.4)
    assert np.all(r.u <= r.lengths + 1e-12)
    nq = sf.model.nq
    assert np.max(np.abs(r.z[:, :nq] - rc.z[:, :nq])) < 5e-3
