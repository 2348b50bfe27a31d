"""Units of the design assistance's JSON (`tmfem equilibrium FILE --target-delta MM`,
`--packaged THETA`): every number has its unit, the Delta of the file and of the deployed
configuration and the bands of psi included."""
import json

import pytest

from tests.cli.test_cli_units import _unitless_numbers
from tmfem.cli import main

FILE = "tests/data/systems/pentagon-1-5D.toml"


@pytest.mark.parametrize("option", [["--target-delta", "2"], ["--packaged", "86"]])
def test_design_assistance_json_states_every_unit(option, capsys):
    assert main(["equilibrium", FILE, *option, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert _unitless_numbers(d) == []
    u = d["units"]
    if option[0] == "--packaged":
        assert u["psi_deg_bands"] == "deg" and u["Delta_deployed"] == "m"
        lo, hi = d["psi_deg_bands"][0]
        assert lo < d["psi_deg"] < hi      # the printed psi lies in a feasible band
    else:
        assert u["Delta_file"] == "m" and u["r_mb_max"] == "m"


def test_the_bases_search_json_states_the_units_of_its_symmetric_table():
    """`--bases` prints a `[symmetric]` table (r, l, z in m, angles in deg): its JSON's numbers
    under `symmetric` carry them (the search itself: docs/guides/system-file.md)."""
    from tmfem.io.units import unit_of
    doc = {"Delta": 0.0067, "symmetric": {"theta_deg": [70.0, 70.0], "z": [0.0, 0.3865],
                                          "r": [0.8, 1.011], "l": [2.0, 2.0]}}
    assert _unitless_numbers(doc) == []
    assert unit_of("symmetric").startswith("r, l, z in m")
