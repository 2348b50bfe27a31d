"""`tmfem report FILE` whose [report] deployment is hostile: refused before any work with the
file's table and key named (not an option the user did not give), the documented exit code."""
import copy
import time

import pytest
import tomli_w

from tests.cli.test_cli_misuse import BAD_INPUT, TOO_LARGE, last_line, run
from tmfem.system.presets import preset_dict


@pytest.mark.parametrize("deployment, code, expected", [
    ({"controller": "x"}, BAD_INPUT, "[report] deployment: expected 'controller' one of"),
    # 1e9 s in steps of 0.01 s: the message named --t-end, which was 0.1
    ({"t_end": 1e9}, TOO_LARGE, "[report] deployment t_end 1e+09 s / --dt 0.01 s = "
                                "100,000,000,000 steps; the limit is 200,000"),
])
def test_report_deployment_refused_naming_the_file(tmp_path, capsys, deployment, code, expected):
    d = copy.deepcopy(preset_dict("2-3"))
    d.setdefault("report", {})["deployment"] = {"system": "2-3-deploy", **deployment}
    p = tmp_path / "r.toml"
    p.write_bytes(tomli_w.dumps(d).encode())
    t0 = time.perf_counter()
    rc, _, err = run(["report", str(p), "--out", str(tmp_path / "out"), "--no-render",
                      "--mesh", "4", "--t-end", "0.1"], capsys)
    assert rc == code, err
    line = last_line(err)
    assert expected in line and "--t-end 1e+09" not in line
    assert time.perf_counter() - t0 < 30 and not (tmp_path / "out" / "index.md").exists()
