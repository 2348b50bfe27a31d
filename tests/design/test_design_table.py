"""The ``[design]`` table of a system file: read, written back, refused when malformed."""
import pytest
import tomli_w

from tmfem.errors import InputError
from tmfem.system import dump_system, load_preset, load_system
from tmfem.system.spec import system_to_dict

DESIGN = {"variables": {"S1": [1.40, 1.52], "d_bar": [0.02, 0.04]}, "objective": "max:freq",
          "constraints": ["tendon_stress<=6.32e7", "mass<=start"], "aperture": 0.8}


def write(tmp_path, design, name="d.toml"):
    d = system_to_dict(load_preset("1-4"))
    d["design"] = design
    path = tmp_path / name
    path.write_bytes(tomli_w.dumps(d).encode())
    return path


def test_design_table_is_read_and_written_back(tmp_path):
    system = load_system(write(tmp_path, DESIGN))
    design = system.problem.design
    assert design.variables == {"S1": (1.40, 1.52), "d_bar": (0.02, 0.04)}
    assert design.objective == "max:freq" and design.constraints == tuple(DESIGN["constraints"])
    assert design.aperture == 0.8
    dump_system(system, tmp_path / "back.toml")
    assert load_system(tmp_path / "back.toml").problem.design == design
    assert load_preset("1-4").problem.design is None


@pytest.mark.parametrize("design, text", [
    ({"variables": {"S1": [1.5, 1.4]}}, "lower < upper"),
    ({"variables": {"S1": 1.4}}, "lower < upper"),
    ({"variables": {}}, "expected 'variables'"),
    ({"variables": {"S1": [1.4, 1.5]}, "goal": "max:freq"}, "unknown keys"),
    ({"variables": {"S1": [1.4, 1.5]}, "objective": 3}, "objective"),
    ({"variables": {"S1": [1.4, 1.5]}, "constraints": "mass<=1"}, "list of strings"),
    ({"variables": {"S1": [1.4, 1.5]}, "aperture": -1}, "aperture"),
])
def test_malformed_design_tables_are_refused(tmp_path, design, text):
    with pytest.raises(InputError, match=text):
        load_system(write(tmp_path, design))
