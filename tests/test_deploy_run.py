"""Closed-loop deployments (dissertation 7.4): tracking, switching, no slack, bounded membrane
vibration, stresses against the printed conclusions. Sources: 7.4.1-7.4.3 (switch times, Euler
loads, yield stresses); reproduction figures in docs/reproduction.md."""
import os

import numpy as np
import pytest

from tmfem.cli.deploy import setup
from tmfem.control.deploy import run_deployment

REDUCED = os.environ.get("TMFEM_SLOW_SCALE") == "reduced"


@pytest.fixture(scope="module")
def run14():
    s = setup("1-4D", controller="adaptive-lqr", uncertainty="exact")
    r = run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                       t_end=12.0, dt=0.01)
    return s, r


def test_1_4D_tracks_and_switches(run14):
    s, r = run14
    nq = s.model.nq
    pfl = np.array([c == "adaptive-pfl" for c in r.controller])
    # tracking of eq. 5.48 during the PFL phase: |q - q_d| well below the 12.6 deg stroke
    assert np.max(np.abs(r.z[pfl, :nq] - r.q_d[pfl])) < np.radians(0.5)
    # switch (eq. 5.70, R_c = 0.01) after the reference has settled (6.79 s, 7.4.1)
    assert 6.79 < r.switch_time < 10.0
    i = np.searchsorted(r.t, r.switch_time)
    assert r.relative_error[i] <= 0.01 < r.relative_error[i - 1]
    # the linear controller holds the final equilibrium
    assert np.max(np.abs(r.z[-1] - s.z_e)) < 1e-3


def test_1_4D_no_slack_and_stresses(run14):
    s, r = run14
    # a rest length never exceeds its tendon's length and stays positive (7.4)
    assert np.all(r.u <= r.lengths + 1e-12) and np.all(r.u > 0)
    assert r.min_margin >= 0
    # Euler load of eq. 5.31, printed 891.9 N (7.4.1): bars do not buckle
    st = r.stress
    assert st["bar_critical_load_N"] == pytest.approx(891.9, rel=1e-3)
    assert st["peak_bar_compression_N"] < st["bar_critical_load_N"]
    # membrane von Mises below Kapton's 61 MPa (7.4.1)
    assert st["max_von_mises_Pa"] < 61e6


def test_1_4D_zero_dynamics_bounded(run14):
    s, r = run14
    pfl = np.array([c == "adaptive-pfl" for c in r.controller])
    E = r.eta_energy[: len(pfl)][pfl]
    # bounded (7.6): the membrane energy of the second half of the PFL phase does not exceed
    # twice that of the first half, and the deflections stay below 10 mm
    n = E.size // 2
    assert E[n:].max() < 2 * E[:n].max()
    assert np.max(np.abs(r.w[: len(pfl)][pfl])) < 0.01


@pytest.mark.slow
def test_1_6D_switch_time():
    s = setup("1-6D", controller="adaptive-lqr")
    r = run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                       t_end=15.0 if REDUCED else 20.0, dt=0.01)
    if REDUCED:
        assert r.switch_time is None
        return
    # printed 18.44 s (7.4.2); ours within 1 s
    assert r.switch_time == pytest.approx(18.44, abs=1.0)
    assert r.stress["bar_critical_load_N"] == pytest.approx(479.6, rel=1e-3)


@pytest.mark.slow
def test_1_4D_switch_to_lmi_hinf():
    # the LMI H-infinity controller of 7.3 (issue 12) after the switch stabilises the whole
    # system at the deployed equilibrium (7.4.1: "rapidly stabilized"), membrane included
    s = setup("1-4D", controller="adaptive-hinf", uncertainty="exact")
    r = run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                       t_end=16.0, dt=0.01, stress_every=50)
    assert r.controller[-1] == "hinf-lmi" and 6.79 < r.switch_time < 10.0
    assert np.max(np.abs(r.z[-1] - s.z_e)) < 1e-4
    assert np.max(np.abs(r.w[-100:])) < 1e-4
