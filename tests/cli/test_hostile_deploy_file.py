"""`tmfem deploy FILE` with hostile [packaged] and [deployment] tables: one line naming the
table, the key or the path, exit 2; never a traceback (an overflow of the reference's closed
form, a negative base radius reported without its source)."""
import copy

import pytest
import tomli_w

from tests.cli.test_cli_misuse import BAD_INPUT, last_line, run
from tmfem.system.presets import preset_dict


def deploy_file(tmp_path, **tables):
    d = copy.deepcopy(preset_dict("2-3-deploy"))
    for table, values in tables.items():
        d[table].update(values)
    p = tmp_path / "d.toml"
    p.write_bytes(tomli_w.dumps(d).encode())
    return str(p)


@pytest.mark.parametrize("tables, expected", [
    ({"deployment": {"omega_r": 1e300}}, "[deployment]: expected 'omega_r' to be a finite number > 0 and <= 100"),
    ({"deployment": {"w_bar": 1e300}}, "[deployment]: expected 'w_bar'"),
    ({"packaged": {"packaged": {"symmetric": {"l": [2.0]}}}}, "found the problem table(s) ['packaged']"),
    # theta = 10 deg packaged: the stage-2 base rule of Table 7.7 gives r_2 = -0.70 m there
    ({"packaged": {"symmetric": {"theta_deg": [10.0, 10.0]}}},
     "path table-7-7-bases of 2-3-deploy: the stage-2 base radius of eq. 3.22 at theta = 10 deg"),
])
def test_hostile_deployment_tables(tmp_path, capsys, tables, expected):
    rc, _, err = run(["deploy", deploy_file(tmp_path, **tables), "--t-end", "0.1"], capsys)
    assert rc == BAD_INPUT, err
    assert expected in last_line(err) and "Traceback" not in err
