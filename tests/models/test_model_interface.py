"""Every registered model implements the model interface of tmfem.models.base, on a preset and
on a system of our own (a one-stage three-bar system from a TOML file), with its numbers
checked against independent sources: finite differences of the plant's residual (the
Jacobians), a re-solved equilibrium (the static gain of the linearisation), the eigenvalues of
the linearisation (the modes), the design configuration and the other models."""
import numpy as np
import pytest

from tmfem.errors import InputError
from tmfem.models.base import Equilibrium, Model, Plant
from tmfem.models.registry import all_models, model_options, resolve_options
from tmfem.system import load_preset, load_system

OWN_SYSTEM = """
name = "own-1-3"
description = "A one-stage three-bar system (r_1 from eq. 3.33 for theta, psi, l, r_mb)"
N = 3

[symmetric]
theta_deg = [55.0]
psi_deg = [12.0]
r = [0.544996]
l = [1.6]

[membrane]
r_mb = 0.80
E = 165e6
nu = 0.34
rho = 1400.0
h = 51e-6
yield_stress = 61e6

[bar]
E = 200e9
rho = 7800.0
d = 0.025

[tendons.S]
E = 2e9
d = 0.6e-3
rho = 1140.0
yield_stress = 94.8e6

[monitor]
nodes = ["B_11"]
points = [[0.8, 0.4]]
"""

MODELS = sorted(all_models())
SYSTEMS = ("1-4", "own-1-3")
#: small discretisations: FE membrane n x n per patch, COM membrane modes K
SIZES = {"mesh": 4, "tendon_elements": 2, "membrane_modes": 3}


@pytest.fixture(scope="module")
def systems(tmp_path_factory):
    path = tmp_path_factory.mktemp("own") / "own-1-3.toml"
    path.write_text(OWN_SYSTEM)
    return {"1-4": load_preset("1-4"), "own-1-3": load_system(path)}


@pytest.fixture(scope="module")
def built(systems):
    """(model, equilibrium) of every model on every system, built through the registry."""
    cache = {}

    def get(name, system):
        if (name, system) not in cache:
            spec = all_models()[name]
            options = {o.name: o.default for o in spec.options}
            options.update({k: v for k, v in SIZES.items() if k in options})
            model = spec.build(systems[system], options, "scipy")
            cache[name, system] = (model, model.equilibrium())
        return cache[name, system]
    return get


def zeros(plant):
    return np.zeros_like(plant.x0)


@pytest.mark.parametrize("system", SYSTEMS)
@pytest.mark.parametrize("name", MODELS)
def test_named_signals_and_equilibrium(built, systems, name, system):
    model, eq = built(name, system)
    sysm = systems[system]
    assert isinstance(model, Model)
    assert model.input_names == [f"r_{t.name}" for t in sysm.tendons]
    assert model.output_names == list(sysm.q_names) + [f"w_{i + 1}" for i in
                                                       range(sysm.monitor_points.shape[1])]
    assert isinstance(eq, Equilibrium)
    np.testing.assert_array_equal(eq.u, model.u0)
    assert list(eq.outputs) == model.output_names
    assert eq.residual_history[-1] < eq.residual_history[0]
    # the residual of the equation of motion (another code path than the static solve)
    # vanishes at the equilibrium, on the scale of the forces of a 1 % change of rest lengths
    plant = model.plant(at=eq)
    z = zeros(plant)
    r = np.linalg.norm(plant.residual(plant.x0, z, z, 0.0, plant.u0))
    scale = np.linalg.norm(plant.residual(plant.x0, z, z, 0.0, 1.01 * plant.u0))
    plant.residual(plant.x0, z, z, 0.0, plant.u0)
    assert r <= 1e-6 * scale
    # the bar coordinates stay at the design (ch. 3) to the FE models' sag of the prestress
    nq = len(sysm.q_names)
    q = np.array([eq.outputs[n] for n in sysm.q_names])
    np.testing.assert_allclose(q, sysm.q, atol=2e-3)
    assert len(q) == nq


@pytest.mark.parametrize("system", SYSTEMS)
def test_equilibria_of_the_models_agree(built, system):
    # COM and the FE models: the same bar coordinates at the equilibrium of the same rest
    # lengths rule (the FE models' membrane sags the corners by Delta, eqs. 3.21-3.22, and
    # moves the bars by less than 1e-3 rad)
    outs = {n: built(n, system)[1].outputs for n in MODELS}
    for n in MODELS:
        qs = [v for k, v in outs[n].items() if not k.startswith("w_")]
        qc = [v for k, v in outs["com"].items() if not k.startswith("w_")]
        np.testing.assert_allclose(qs, qc, atol=1e-3)


@pytest.mark.parametrize("system", SYSTEMS)
@pytest.mark.parametrize("name", MODELS)
def test_plant_jacobians_match_finite_differences(built, name, system):
    model, eq = built(name, system)
    plant = model.plant(at=eq)
    assert isinstance(plant, Plant)
    assert plant.input_names == model.input_names
    assert plant.output_names == model.output_names
    np.testing.assert_allclose(plant.outputs(plant.x0, zeros(plant), plant.u0),
                               list(eq.outputs.values()), rtol=1e-10, atol=1e-12)
    x, z, u = plant.x0, zeros(plant), plant.u0
    rng = np.random.default_rng(0)
    d = rng.standard_normal(x.size)
    K, C, M = (np.asarray(a.todense()) if hasattr(a, "todense") else np.asarray(a)
               for a in plant.jacobians(x, z, z, 0.0, u))
    h = 1e-6

    def fd(f):
        return (f(h) - f(-h)) / (2 * h)

    Kd = fd(lambda e: plant.residual(x + e * d, z, z, 0.0, u))
    np.testing.assert_allclose(K @ d, Kd, rtol=0, atol=1e-5 * np.abs(Kd).max())
    Md = fd(lambda e: plant.residual(x, z, e * d, 0.0, u))
    np.testing.assert_allclose(M @ d, Md, rtol=0, atol=1e-6 * np.abs(Md).max())
    Cd = fd(lambda e: plant.residual(x, e * d, z, 0.0, u))
    np.testing.assert_allclose(C @ d, Cd, rtol=0, atol=1e-6 * max(np.abs(Cd).max(), 1e-12))
    S = plant.newton_matrix(x, z, z, 0.0, 2.0, 3.0, u)
    np.testing.assert_allclose(S @ d, K @ d + 2.0 * (C @ d) + 3.0 * (M @ d),
                               rtol=0, atol=1e-9 * np.abs(K @ d).max())


@pytest.mark.parametrize("system", SYSTEMS)
@pytest.mark.parametrize("name", MODELS)
def test_linearization_static_gain_and_modes(built, name, system):
    model, eq = built(name, system)
    ss = model.linearize(at=eq)
    assert ss.input_labels == model.input_names
    assert ss.output_labels == model.output_names
    assert ss.nstates == 2 * model.plant(at=eq).x0.size
    # static gain -C A^-1 B against the equilibrium re-solved for a changed rest length
    # (nonlinear, from the model's own start), first tendon
    u0 = np.array(model.u0)
    du = 1e-5 * u0[0]
    u1 = u0.copy()
    u1[0] += du
    y0 = np.array(list(eq.outputs.values()))
    y1 = np.array(list(model.equilibrium(u1).outputs.values()))
    model.equilibrium(u0)                               # back to the nominal rest lengths
    gain = -(ss.C @ np.linalg.solve(ss.A, ss.B[:, 0]))
    fd = (y1 - y0) / du
    np.testing.assert_allclose(gain, fd, rtol=0, atol=2e-3 * np.abs(fd).max())
    # the modes are the eigenvalues +-i omega of A (dense eigen solve against the model's
    # own eigen solver), to the backward error eps ||A|| of the dense solve (the shells'
    # rotary inertia makes ||A|| of the SBC model 1e15: its modal form is checked below)
    modes = model.modes(k=4, at=eq)
    lam = np.linalg.eigvals(ss.A)
    omega = np.sort(np.abs(lam.imag[lam.imag > 0]))[:4]
    np.testing.assert_allclose(omega, modes.omega, rtol=1e-6,
                               atol=1e-16 * np.linalg.norm(ss.A, 2))
    assert np.all(np.diff(modes.freq_hz) >= 0) and modes.freq_hz[0] > 0


@pytest.mark.parametrize("system", SYSTEMS)
@pytest.mark.parametrize("name", [n for n in MODELS if "finite-element" in
                                  all_models()[n].capabilities])
def test_modal_linearization_of_the_fe_models(built, name, system):
    # the reduced linearisation keeps the k lowest modes exactly
    model, eq = built(name, system)
    ss = model.linearize(at=eq, modes=5)
    assert ss.nstates == 10
    assert ss.state_labels[:2] == ["eta_1", "eta_2"]
    lam = np.linalg.eigvals(ss.A)
    np.testing.assert_allclose(np.sort(np.abs(lam.imag[lam.imag > 0])),
                               model.modes(k=5, at=eq).omega, rtol=1e-6)


def test_the_registry_declares_its_options_as_data():
    for name, spec in all_models().items():
        for o in spec.options:
            assert o.name.isidentifier() and o.doc, (name, o)
            assert o.type in (int, float, str), (name, o)
            if o.choices is not None:
                assert o.default in o.choices, (name, o)
            assert o.stage in (None, "equilibrium", "dynamics"), (name, o)
    # an option the chosen model does not take is refused, naming the model that takes it
    assert "bar_elements" in [o.name for o in model_options("sbc")]
    with pytest.raises(InputError, match="--bar-elements belongs to --model sbc"):
        resolve_options("mtc", {"bar_elements": 2}, command="static")
    # the options of a stage apply only to a run of that stage
    assert "rayleigh" not in [o.name for o in model_options("mtc", ("equilibrium",))]
    assert "rayleigh" in [o.name for o in model_options("mtc", ("equilibrium", "dynamics"))]

