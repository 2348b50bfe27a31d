"""The 2-3 deployment of 7.4 (adaptive PFL, Table 7.7) on the MTC finite-element plant
(docs/guides/fe-plant.md): where the PFL evaluates its model, its tendon model, and the closed
loop on the FE plant against the same controller on the control-oriented model."""
import os

import numpy as np
import pytest

from tmfem.control.deployment.adaptive import AdaptivePFL
from tmfem.control.deployment.run import run_deployment
from tmfem.control.fe_plant.state_estimate import mtc_deployment_plant
from tmfem.errors import ConvergenceError, InputError
from tmfem.models.com.model import ControlOrientedModel
from tmfem.reference.deployments import setup
from tmfem.system import load_preset

REDUCED = os.environ.get("TMFEM_SLOW_SCALE") == "reduced"


@pytest.fixture(scope="module")
def deploy23():
    return setup("2-3-deploy", controller="adaptive")


def _pfl(s, **kw):
    ad = s.adaptive
    return AdaptivePFL(model=s.model, reference=s.reference, gains=ad.gains, rbf=ad.rbf,
                       w_bar=ad.w_bar, gamma=ad.gamma, **kw)


def test_cable_inversion_gives_the_commanded_acceleration(deploy23):
    """Eq. 5.46 solved in w = 1/u (tendon_law="cable"): the rest lengths it returns give, on
    a control-oriented model whose rates are EA / u at those very rest lengths (eq. 3.9: a
    second model built with rest_lengths = u), the bar acceleration the law demands,
    q'' = q_d'' - d_q (q' - q_d') - k_q (q - q_d) (eq. 5.47 with W_F = 0)."""
    s = deploy23
    m = s.model
    pfl = _pfl(s, uncertainty="exact", allocation="clip", tendon_law="cable")
    t = 0.7
    rng = np.random.default_rng(3)
    q_d, qd_d, qdd_d = s.reference(t)
    z = np.concatenate([q_d + 1e-3 * rng.standard_normal(m.nq), 1e-4 * rng.standard_normal(m.K)])
    zd = np.concatenate([qd_d + 1e-3 * rng.standard_normal(m.nq), np.zeros(m.K)])
    xc = pfl.reset(0.0, np.concatenate([z, zd]), 0.01)
    u = pfl.output(t, np.concatenate([z, zd]), xc)
    other = ControlOrientedModel(m.system, membrane_modes=m.K, rest_lengths=u)
    d_q, k_q = s.adaptive.gains(t)
    want = qdd_d - d_q * (zd[:m.nq] - qd_d) - k_q * (z[:m.nq] - q_d)
    got = other.acceleration(z, zd, u)[:m.nq]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-8 * np.max(np.abs(want)) + 1e-10)
    # the fixed-rate law of eq. 5.19 commands other rest lengths for the same demand
    u_fixed = _pfl(s, uncertainty="exact", allocation="clip").output(t, np.concatenate([z, zd]), xc)
    assert np.max(np.abs(u_fixed - u)) > 1e-3


@pytest.mark.parametrize("kw, needle", [
    ({"evaluation": "desired"}, "evaluation: expected one of"),
    ({"tendon_law": "spring"}, "tendon_law: expected one of"),
    ({"tendon_law": "cable", "uncertainty": "initial"}, "expected uncertainty 'no-MG' or 'exact'"),
])
def test_pfl_options_refused(deploy23, kw, needle):
    with pytest.raises(InputError, match=needle):
        _pfl(deploy23, **kw)


@pytest.mark.slow
def test_pfl_at_the_state_diverges_at_the_reference_tracks():
    """The diagnosis of docs/guides/fe-plant.md, on the 3 x 10 x 10 MTC plant with the COM's
    fixed-rate tendons over the first 1.5 s: the law of eq. 5.58 with its terms at the
    measured state cancels the structure's stiffness (up to omega^2 = 3.2e3 s^-2) against
    k_q <= 60 s^-2 and the closed loop diverges (Park's Newton fails at 1.4 s); with the
    terms at the reference the bars stay within 10 mrad (angles) and 10 mm (bases) of it (the
    COM plant under eq. 5.58: 9.4 mrad, 9.4 mm)."""
    initial = load_preset("2-3-deploy-initial")
    errors = {}
    for ev in ("state", "reference"):
        s = setup("2-3-deploy", controller="adaptive", evaluation=ev)
        plant = mtc_deployment_plant(s.model, initial, mesh_n=10, tendon_law="fixed-rate")
        try:
            r = run_deployment(model=s.model, reference=s.reference, controller=s.controller,
                               z0=s.z0, t_end=1.5, dt=0.01, plant=plant, jacobian="step",
                               stress_every=40)
        except ConvergenceError:
            errors[ev] = np.inf
            continue
        errors[ev] = float(np.max(np.abs(r.z[:, :s.model.nq] - r.q_d)))
    assert errors["state"] > 0.05
    assert errors["reference"] < 0.010


@pytest.mark.slow
def test_2_3_deployment_on_the_mtc_plant():
    """`tmfem deploy --preset 2-3-deploy --controller adaptive-hinf --plant mtc --plant-mesh
    10` (cable tendons, the PFL at the reference with the cable tendon model) against the
    same controller on the COM plant (PFL at the reference, the COM's tendon rates): the FE
    run tracks the reference (bar angles within twice the COM run's error over the PFL
    phase), never commands a rest length above its tendon's length, has a slack FE tendon
    only while a limit holds a rest length at its tendon's length (zero tension), stays within
    5 mrad (bar angles) and 5 mm (stage-2 bases) of the COM run over the whole run (measured:
    2.9 mrad, 1.7 mm; docs/guides/fe-plant.md) and switches (eq. 5.70) within 0.5 s of it, to a final
    error below R_c. Reduced: the first 2 s on the 3 x 5 x 5 mesh, adaptive PFL only."""
    controller, t_end, mesh = ("adaptive", 2.0, 5) if REDUCED else ("adaptive-hinf", 20.0, 10)
    runs = {}
    for plant in ("com", "mtc"):
        law = "cable" if plant == "mtc" else "fixed-rate"
        s = setup("2-3-deploy", controller=controller, evaluation="reference", tendon_law=law)
        p = None if plant == "com" else mtc_deployment_plant(
            s.model, load_preset("2-3-deploy-initial"), mesh_n=mesh, tendon_law=law)
        runs[plant] = run_deployment(model=s.model, reference=s.reference, controller=s.controller,
                                     z0=s.z0, t_end=t_end, dt=0.01, plant=p,
                                     jacobian="reuse" if p is None else "step", stress_every=50)
    com, fe = runs["com"], runs["mtc"]
    nq = s.model.nq
    ang = [i for i, n in enumerate(s.model.system.q_names) if n.startswith(("theta", "psi"))]
    pos = [i for i in range(nq) if i not in ang]
    assert fe.t[-1] == pytest.approx(t_end)

    def tracking(r):
        pfl = np.array([c == "adaptive-pfl" for c in r.controller])
        return np.max(np.abs(r.z[pfl][:, ang] - r.q_d[pfl][:, ang]))
    assert tracking(fe) < 2 * tracking(com)
    assert np.all(fe.u <= fe.lengths + 1e-12) and fe.min_margin >= 0
    assert fe.plant_report["tendon_slack_samples"] <= np.sum(fe.limits_active > 0)
    dz = fe.z[:, :nq] - com.z[:, :nq]
    assert np.max(np.abs(dz[:, ang])) < 5e-3 and np.max(np.abs(dz[:, pos])) < 5e-3
    if not REDUCED:
        assert fe.switch_time == pytest.approx(com.switch_time, abs=0.5)
        assert fe.relative_error[-1] < 0.01


def test_cli_defaults_of_the_fe_plant(capsys):
    """`tmfem deploy --plant mtc` runs the PFL at the reference with the plant's tendon law
    (cable by default), and names the FE tendons that went slack; `--pfl-at state` is
    accepted on either plant (docs/guides/cli.md: exit 0)."""
    import json
    from tmfem.cli import main
    rc = main(["deploy", "--preset", "2-3-deploy", "--controller", "adaptive", "--plant", "mtc",
               "--plant-mesh", "3", "--t-end", "0.1", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc in (0, None)
    assert out["pfl_at"] == "reference" and out["plant_tendons"] == "cable"
    assert isinstance(out["plant_slack_tendons"], list)
    assert out["min_rest_length_margin_m"] >= 0
    rc = main(["deploy", "--preset", "2-3-deploy", "--controller", "adaptive", "--t-end", "0.05",
               "--pfl-at", "reference", "--json"])
    assert rc in (0, None) and json.loads(capsys.readouterr().out)["pfl_at"] == "reference"
