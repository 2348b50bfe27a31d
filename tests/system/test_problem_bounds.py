"""Upper bounds of the problem tables, checked when the file is read (docs/guides/system-file.md):
a value that would overflow the reference's closed form, hang the deployment (RBF centres) or
the LPV linearisations (grid axes) is refused with its table and key; the presets stay valid."""
import copy

import pytest
import tomli_w

from tmfem.errors import InputError
from tmfem.system import load_preset, load_system
from tmfem.system.presets import preset_dict
from tmfem.system.problem import UPPER


def load(tmp_path, preset, table, key, value):
    d = copy.deepcopy(preset_dict(preset))
    d[table][key] = value
    p = tmp_path / "f.toml"
    p.write_bytes(tomli_w.dumps(d).encode())
    return load_system(p)


@pytest.mark.parametrize("preset, table, key, value, match", [
    # omega_r = 1e300 and w_bar = 1e300 ended `tmfem deploy` with an OverflowError traceback
    ("2-3-deploy", "deployment", "omega_r", 1e300, r"\[deployment\]: expected 'omega_r' .* <= 100"),
    ("2-3-deploy", "deployment", "w_bar", 1e300, r"'w_bar' .* <= 1e\+12"),
    # rbf_centres = 10**7 ran past 4 minutes
    ("2-3-deploy", "deployment", "rbf_centres", 10**7, r"'rbf_centres' to be an integer in 2..1000"),
    ("2-3-lpv", "lpv", "omega_r", 1e3, r"\[lpv\]: expected 'omega_r'"),
    ("2-3-lpv", "lpv", "theta_grid_deg", [60 + 0.01 * i for i in range(61)],
     r"'theta_grid_deg' with at most 60 angles .* found 61"),
    ("2-3-lpv", "lpv", "membrane_modes", 1000, r"\[lpv\] membrane_modes 1000: expected 0 <= K <= 40"),
    ("2-3-deploy", "control", "alpha", 1e9, r"\[control\]: expected 'alpha'"),
])
def test_implausible_values_refused_on_reading(tmp_path, preset, table, key, value, match):
    with pytest.raises(InputError, match=match):
        load(tmp_path, preset, table, key, value)


@pytest.mark.parametrize("table, key", [("deployment", "omega_r"), ("deployment", "rbf_centres")])
def test_the_bound_itself_is_accepted(tmp_path, table, key):
    value = UPPER[key] if key != "rbf_centres" else int(UPPER[key])
    assert load(tmp_path, "2-3-deploy", table, key, value).problem.deployment is not None



def test_packaged_holds_no_problem_tables(tmp_path):
    # [packaged] [packaged] used to be merged and reported as a stage-count error of the
    # nested table
    d = copy.deepcopy(preset_dict("2-3-deploy"))
    d["packaged"]["packaged"] = {"symmetric": {"l": [2.0]}}
    d["packaged"]["deployment"] = {"omega_r": 1.0}
    p = tmp_path / "f.toml"
    p.write_bytes(tomli_w.dumps(d).encode())
    with pytest.raises(InputError, match=r"\[packaged\]: expected overrides of the structure's "
                                         r"tables, found the problem table\(s\) \['deployment', "
                                         r"'packaged'\]"):
        load_system(p)



@pytest.mark.parametrize("key, value", [("theta0_deg", 150.0), ("theta_e_deg", 60.0),
                                        ("psi0_deg", 9.5)])
def test_scheduling_values_on_the_grid(tmp_path, key, value):
    # theta0_deg = 150 ran the synthesis for minutes before the deployment refused it; the
    # file stays valid for a design (control lpv), the deployment refuses it before any work
    system = load(tmp_path, "2-3-lpv", "lpv", key, value)
    with pytest.raises(InputError, match=rf"\[lpv\]: expected '{key}' inside its grid .* found {value:g}"):
        system.problem.lpv.check_schedule(system.name)
    load_preset("2-3-lpv").problem.lpv.check_schedule("2-3-lpv")         # the preset is on it
