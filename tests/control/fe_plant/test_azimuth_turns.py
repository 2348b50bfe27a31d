"""The azimuths psi measured on a finite-element plant are counted continuously (a
multi-turn encoder, tmfem.control.fe_plant.state_estimate): a bar whose azimuth passes +-pi
does not jump by 2 pi, which the controllers would read as a tracking error of 2 pi. The
three-stage tower of tests/data/systems/tower-3-3.toml deploys through it: its bar 32 starts
at psi = 3.118 rad and ends at 3.260 rad (= -3.023 on (-pi, pi])."""
import json
from pathlib import Path

import numpy as np
import pytest

from tmfem.cli import main
from tmfem.control.fe_plant.state_estimate import FEStatePlant, fe_state_of, packaged_state
from tmfem.models.com.model import ControlOrientedModel
from tmfem.models.mtc.dynamics import MTCDynamics
from tmfem.models.mtc.model import MTCModel
from tmfem.reference.deployments import checked_configurations, deployable_system
from tmfem.system import load_system

TOWER = Path(__file__).resolve().parents[2] / "data" / "systems" / "tower-3-3.toml"


@pytest.fixture(scope="module")
def tower():
    s = checked_configurations(deployable_system(load_system(TOWER)))
    com = ControlOrientedModel(s, membrane_modes=3, rest_lengths="system")
    fe = MTCModel(s, mesh_n=4, rest_lengths=com.u0)
    initial = s.problem.packaged
    z_a = packaged_state(com, initial)
    return s, com, MTCDynamics(fe, fe.equilibrium().x), initial, z_a


def test_an_azimuth_passing_pi_is_measured_on_its_turn(tower):
    """Two placements of the COM's field (fe_state_of), the packaged configuration and the
    same with psi_32 turned by +0.05 rad past pi, are estimated back as placed, psi_32 =
    3.168 rad (to 1e-9, the round-off of the placement), rates included; an estimate
    without the start's turn reads 3.168 - 2 pi."""
    s, com, dyn, initial, z_a = tower
    k = list(s.q_names).index("psi_32")
    assert np.pi - 0.05 < z_a[k] < np.pi
    z_b = z_a.copy()
    z_b[k] += 0.05
    zd = np.zeros(com.nz)
    zd[k] = 0.1
    plant = FEStatePlant(dyn, com, q_start=initial.q)
    nz = com.nz
    x_a = fe_state_of(com, dyn, z_a, zd)
    y_a = plant.outputs(*x_a)
    # on the turn (-pi, pi] already: the same estimate as without a turn, bit for bit
    np.testing.assert_array_equal(y_a, FEStatePlant(dyn, com).outputs(*x_a))
    y_b = plant.outputs(*fe_state_of(com, dyn, z_b, zd))
    np.testing.assert_allclose(y_a[:nz], z_a, rtol=0, atol=1e-9)
    np.testing.assert_allclose(y_b[:nz], z_b, rtol=0, atol=1e-9)
    np.testing.assert_allclose(y_b[nz:], zd, rtol=0, atol=1e-8)
    # back across pi: the turn follows the previous estimate
    np.testing.assert_allclose(plant.outputs(*fe_state_of(com, dyn, z_a))[:nz], z_a, rtol=0, atol=1e-9)
    fresh = FEStatePlant(dyn, com)
    assert fresh.outputs(*fe_state_of(com, dyn, z_b))[k] == pytest.approx(z_b[k] - 2 * np.pi, abs=1e-9)


@pytest.mark.slow
def test_the_over_actuated_tower_deploys_on_the_mtc_plant(capsys):
    """The 3-3 deployment (adaptive PFL, then the H-infinity switch) on the 4 x 4 MTC plant
    against the same controller on the COM plant (the independent plant of the same run):
    both switch, within 0.1 s of each other, every FE tendon stays in tension, no check
    fails. Before the azimuths were counted continuously the FE run stopped at 1.44 s."""
    runs = {}
    for plant in ("com", "mtc"):
        argv = ["deploy", str(TOWER), "--t-end", "20", "--dt", "0.02", "--json"]
        argv += ["--plant-mesh", "4", "--plant", "mtc"] if plant == "mtc" else []
        assert main(argv) == 0
        runs[plant] = json.loads(capsys.readouterr().out)
    com, fe = runs["com"], runs["mtc"]
    assert fe["failure"] is None and fe["failed_checks"] == [] and fe["t_end_s"] == pytest.approx(20.0)
    assert com["switch_time_s"] is not None and fe["switch_time_s"] is not None
    assert abs(fe["switch_time_s"] - com["switch_time_s"]) <= 0.1
    assert fe["plant_tendon_slack_samples"] == 0 and fe["plant_min_tendon_force_N"] > 0.1
    assert fe["final_tracking_error"] < 0.05
