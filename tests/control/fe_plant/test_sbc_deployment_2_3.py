"""The 2-3 deployments on the SBC plant (docs/guides/fe-plant.md "The 2-3 deployments on
the SBC plant"). Why the LPV deployment of 8.4 diverges there: the linear sampled loop of an
FE plant under Park's method (:mod:`tmfem.control.fe_plant.sampled_loop`), checked against Park's
characteristic equation, at the start of the LPV deployment on the SBC, the MTC and a
stiff-bar SBC plant; the adaptive deployment of 7.4 there against the MTC plant. Sources:
Park's formula (eqs. 5.34-5.35, closed form for one oscillator); the MTC plant (another model,
whose closed loops run: tests/control/lpv/test_lpv_deployment.py, tests/control/fe_plant/test_fe_deployment.py)."""
import dataclasses

import numpy as np
import pytest

from tmfem.control.fe_plant.sampled_loop import (LinearizedFEPlant, dominant_eigenvalues, lpv_start_loop,
                                           park_loop)
from tmfem.errors import InputError


def _park_p(z, dt):
    """Park's derivative operator on z^n: v = p(z) x with p = (10 - 15/z + 6/z^2 - 1/z^3) / (6 dt)."""
    return (10 - 15 / z + 6 / z**2 - 1 / z**3) / (6 * dt)


@pytest.mark.parametrize("c, b_f", [(0.0, 0.0), (0.8, 0.0), (0.0, -300.0), (0.5, -300.0)])
def test_park_loop_of_one_oscillator_is_parks_characteristic_equation(c, b_f):
    # m x'' + c x' + k x = b u_n with u_n = f x_n: x_n = z^n in Park's formulas gives
    # m p^2 z + c p z + k z - b f = 0 (u_n enters the step n -> n+1); every eigenvalue of the
    # transition matrix that is not a start-up zero solves it
    dt, m, k = 0.01, 2.0, 2.0 * (2 * np.pi * 5.0) ** 2
    lin = LinearizedFEPlant(M=np.array([[m]]), C=np.array([[c]]) if c else None, K=np.array([[k]]),
                            B=np.array([[1.0]]), C_z=np.eye(1))
    A = park_loop(lin, F_x=np.array([[b_f]]), F_v=np.zeros((1, 1)), dt=dt)
    lam = np.linalg.eigvals(A)
    lam = lam[np.abs(lam) > 1e-9]
    assert lam.size >= 4
    p = _park_p(lam, dt)
    res = (m * p**2 + c * p + k) * lam - b_f
    np.testing.assert_allclose(res / (k + m / dt**2), 0.0, atol=1e-9)
    # the undamped open loop: Park's dissipation keeps every root inside the unit circle
    if c == 0.0 and b_f == 0.0:
        assert np.max(np.abs(lam)) < 1.0


def test_park_loop_refuses_bad_shapes():
    lin = LinearizedFEPlant(M=np.eye(2), C=None, K=np.eye(2), B=np.ones((2, 1)), C_z=np.eye(2))
    with pytest.raises(InputError, match=r"expected feedback matrices of shape \(1, 2\)"):
        park_loop(lin, F_x=np.zeros((2, 2)), F_v=np.zeros((1, 2)), dt=0.01)
    with pytest.raises(InputError, match="expected dt > 0"):
        park_loop(lin, F_x=np.zeros((1, 2)), F_v=np.zeros((1, 2)), dt=0.0)


def _start_radius(design, plant_kind, bar_factor=None, bars=None):
    """Spectral radius and dominant frequency of the LPV deployment's sampled loop at its start
    on the 3 x 2 x 2 FE plant ``plant_kind`` (the plant built as `tmfem deploy` builds it; the
    SBC plant's q measured by ``bars``), the bars' Young's modulus x ``bar_factor`` (the COM's
    bars are rigid either way)."""
    from tmfem.control.fe_plant.state_estimate import deployment_plant
    from tmfem.reference.deployments import lpv_setup
    from tmfem.system import load_preset
    s = load_preset("2-3-lpv")
    if bar_factor is not None:
        s = s.replace(bar=dataclasses.replace(s.bar, E=s.bar.E * bar_factor))
    pl, d, _ = design
    dep = lpv_setup(s, pl)
    plant = deployment_plant(plant_kind, dep.model, dep.packaged(), mesh_n=2, bars=bars)
    return dominant_eigenvalues(lpv_start_loop(dep, d, plant, dt=0.01), 0.01, k=1)[0]


@pytest.fixture(scope="module")
def mtc_start(design21):  # noqa: F811
    return _start_radius(design21, "mtc")


@pytest.mark.slow
def test_lpv_start_loop_on_the_sbc_plant_is_unstable_near_nyquist(design21, mtc_start):  # noqa: F811
    # the chord of the SBC bars sees their bending modes (20-35 Hz, 95-130 Hz on 3 x 4 x 4),
    # which the gain designed on rigid bars drives: the sampled loop grows by ~1.5 per sample
    # at 45.6 Hz (measured 1.4998); on the MTC plant (truss bars) 1.0095 at 5.8 Hz, whose
    # closed loop runs (tests/control/lpv/test_lpv_deployment.py)
    r_sbc, f_sbc = _start_radius(design21, "sbc", bars="chord")
    r_mtc, _ = mtc_start
    assert r_sbc > 1.3 and f_sbc > 40.0, (r_sbc, f_sbc)
    assert r_mtc < 1.02, r_mtc


@pytest.mark.slow
def test_lpv_start_loop_with_stiff_bars_is_the_mtc_one(design21, mtc_start):  # noqa: F811
    # the bars' bending is the cause: with E x 10 (bending modes x 3.2 in frequency, x 10 less
    # compliance) the SBC loop at the start is the MTC one (measured 1.00943 against 1.00953)
    r, _ = _start_radius(design21, "sbc", bar_factor=10.0, bars="chord")
    assert r == pytest.approx(mtc_start[0], abs=1e-3)


@pytest.mark.parametrize("bars", [None, "chord"])
@pytest.mark.slow
def test_2_3_adaptive_deployment_on_the_sbc_plant_is_the_mtc_one(bars, capsys):
    # the 7.4 deployment of the 2-3 system (adaptive PFL at the reference, cable tendons) runs
    # on the SBC plant with q measured as the bars' rigid fit (the default) and as their
    # chords: its gains are low enough that the bars' bending modes stay out of the loop; over
    # the first 2 s on 3 x 4 x 4 its bars stay within 0.5 mrad of the same deployment on the
    # MTC plant (measured 0.041 mrad with either, the bases within 0.047 / 0.057 mm; 3 x 10 x 10
    # over 20 s with the switch: 0.20 mrad, docs/guides/fe-plant.md), no rest length above its
    # tendon, and the FE tendons slack only where the allocation holds the P_2j at zero tension
    import json
    from tmfem.cli import main
    assert main(["deploy", "--preset", "2-3-deploy", "--controller", "adaptive", "--plant", "sbc",
                 "--plant-mesh", "4", "--compare-plant", "mtc", "--t-end", "2", "--json",
                 *(["--plant-bars", bars] if bars else [])]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["plant_bars"] == (bars or "rigid")
    assert out["failure"] is None and out["compare"]["failure"] is None
    assert np.radians(out["compare"]["deviation"]["max_bar_deviation_deg"]) < 5e-4
    assert out["min_rest_length_margin_m"] >= 0.0
    assert set(out["plant_slack_tendons"]) <= {"P_21", "P_22", "P_23"}
