"""The control-oriented model's set-up time is estimated before it starts (tmfem.resources):
a many-stage system is refused at once with the stages, the membrane modes, the estimate and
the limit (exit 3), from a file on the command line and from Python alike. The estimate
against the measured CPU time of set-ups: ``benchmarks/bench_com_setup.py`` (a timing, not a
test)."""
import time

import pytest
import tomli_w

from tests.cli.test_cli_misuse import TOO_LARGE, last_line, run
from tests.cli.test_hostile_budget import stages
from tmfem.errors import ResourceLimit
from tmfem.models.com.model import ControlOrientedModel
from tmfem.resources import MAX_COM_SETUP_S, com_setup_seconds
from tmfem.system.spec import system_from_dict


def tower(M):
    d = stages(M)
    d.pop("monitor", None)
    return d


@pytest.mark.parametrize("command", [["modal", "--model", "com"],
                                     ["vibrate", "--model", "com", "--t-end", "0.1"]])
def test_400_stages_refused_before_the_set_up(command, tmp_path, capsys):
    p = tmp_path / "tall.toml"
    p.write_bytes(tomli_w.dumps(tower(400)).encode())
    # 400 x 3 bars: n_q = 6 + 15 x 399 = 5991 coordinates, K = 4 (the 2-3 file's)
    est = com_setup_seconds(n_q=5991, K=4)
    assert est > MAX_COM_SETUP_S
    t0 = time.perf_counter()
    rc, _, err = run(command + [str(p)], capsys)
    line = last_line(err)
    assert rc == TOO_LARGE, err
    assert "400 stages x 3 bars (5991 coordinates q), membrane_modes 4" in line, line
    assert f"takes about {est:.0f} s of CPU; the limit is {MAX_COM_SETUP_S:.0f} s" in line
    assert time.perf_counter() - t0 < 20


def test_python_api_refused_too():
    system = system_from_dict(tower(400), "tall")
    with pytest.raises(ResourceLimit, match=r"400 stages x 3 bars .* membrane_modes 6: the "
                                            r"control-oriented model's set-up"):
        ControlOrientedModel(system, membrane_modes=6)
    with pytest.raises(ResourceLimit, match="membrane_modes 1000: expected 0 <= K <= 40"):
        ControlOrientedModel(system_from_dict(tower(2), "two"), membrane_modes=1000)
