"""A grid point with no feasible design is named in the LPV plant's error, whatever the
stage-base rule: the two-stage 2-5 of tests/data/systems/pentagon-2-5-lpv.toml on its
"table-7-7-bases" rule (its file notes that psi = 26 deg leaves the region of feasible
equilibria at theta = 68 deg). Independent reference: the positive-null-vector test of
3.3.2 (tmfem.equilibrium.deployment_path.path_feasibility) on the rule's configuration."""
from pathlib import Path

import numpy as np
import pytest

from tmfem.control.lpv.plant import com_lpv_plant
from tmfem.equilibrium.deployment_path import path_feasibility
from tmfem.equilibrium.symmetric_map import configuration_5_97
from tmfem.errors import SlackTendon
from tmfem.reference.deployments import lpv_bases
from tmfem.system import load_system

SYSTEM = Path(__file__).resolve().parents[2] / "data" / "systems" / "pentagon-2-5-lpv.toml"


def test_a_slack_grid_point_of_the_table_7_7_rule_is_named_in_degrees():
    s = load_system(SYSTEM)
    th, ps = np.radians(70.0), np.radians(26.0)
    rule = lpv_bases(s)
    # 3.3.2: no positive self-stress at this point, the stage-2 tendons C_2k without tension
    reason = path_feasibility(s, configuration_5_97(s, th, ps, **rule(th, ps))).reason
    assert "no positive null vector" in reason and "C2 (-" in reason
    with pytest.raises(SlackTendon, match=r"^LPV grid point theta = 70 deg, psi = 26 deg is not a feasible "
                                          r"equilibrium .*C_21=-.*narrow the \[lpv\] theta_grid_deg"):
        com_lpv_plant(s, theta=[th], psi=[ps], bases=rule, membrane_modes=4)
