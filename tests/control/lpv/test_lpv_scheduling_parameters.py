"""The scheduling parameters of an N-bar system's LPV plant: rho = [theta_1N, psi_1N], the
stage-1 bar whose azimuth is the configuration's psi (eq. 3.20: psi_1j = psi_1 + 2 pi j / N),
theta_13, psi_13 of 8.3 for the three-bar 2-3. On a five-bar system (a user 2-5,
tests/data/systems/pentagon-2-5-lpv.toml) the bar 13 sits 2 pi 3/5 away from psi, so a
deployment scheduled on it read psi_13 = -119 deg against a grid at 25 deg."""
from pathlib import Path

import numpy as np
import pytest

from tmfem.control.lpv.plant import com_lpv_plant, scheduling_parameters
from tmfem.reference.deployments import lpv_bases, lpv_setup
from tmfem.system import load_system

PENTAGON = Path(__file__).resolve().parents[2] / "data" / "systems" / "pentagon-2-5-lpv.toml"


@pytest.mark.parametrize("N, names", [(3, ["theta_13", "psi_13"]), (5, ["theta_15", "psi_15"]),
                                      (12, ["theta_1,12", "psi_1,12"])])
def test_the_scheduled_bar_is_the_last_of_stage_one(N, names):
    assert scheduling_parameters(N) == names


@pytest.fixture(scope="module")
def pentagon_point():
    # the file's [lpv] reference (eq. 5.100): theta from 70 to 64 deg at psi = 25 deg
    s = load_system(PENTAGON)
    return s, com_lpv_plant(s, theta=np.radians([64.0, 70.0]), psi=np.radians([25.0]), bases=lpv_bases(s))


@pytest.mark.slow
def test_the_grid_values_are_the_scheduled_bars_angles(pentagon_point):
    s, plant = pentagon_point
    assert plant.parameter_names == ["theta_15", "psi_15"]
    x_e = plant.x_e[1, 0]
    q = {n: x_e[plant.state_names.index(n)] for n in s.q_names}
    assert np.degrees(q["theta_15"]) == pytest.approx(70.0, abs=1e-9)
    assert np.degrees(q["psi_15"]) == pytest.approx(25.0, abs=1e-9)
    # eq. 3.20: bar 13 is 2 pi 3/5 further round, wrapped onto (-pi, pi]
    assert np.degrees(q["psi_13"]) == pytest.approx(25.0 + 216.0 - 360.0, abs=1e-9)


@pytest.mark.slow
def test_the_deployment_measures_the_grid_point_at_its_start(pentagon_point):
    s, plant = pentagon_point
    dep = lpv_setup(s, plant)
    y = dep.measure(np.concatenate([dep.z0, np.zeros_like(dep.z0)]))
    assert np.degrees(y[-2:]) == pytest.approx([70.0, 25.0], abs=1e-9)
    assert np.degrees(dep.reference_rho(0.0)) == pytest.approx([70.0, 25.0], abs=1e-9)
