"""Cost estimates before any work for inputs that come from a file (tmfem.resources): a
system whose equilibrium design cannot fit the machine is refused at once with its estimate
and the limit (exit 3), whatever command reads it."""
import copy
import time

import pytest
import tomli_w

from tests.cli.test_cli_misuse import TOO_LARGE, last_line, run
from tmfem.resources import design_bytes, memory_limit
from tmfem.system.presets import preset_dict


def stages(M):
    """The 2-3 preset with M stages (every upper stage a copy of stage 2, 0.4 m apart)."""
    d = copy.deepcopy(preset_dict("2-3"))
    for k in ("as_printed", "rest_lengths", "printed"):
        d.pop(k, None)
    s = d["symmetric"]
    for k in s:
        s[k] = [s[k][0]] + [s[k][1]] * (M - 1)
    s["z"] = [0.4 * i for i in range(M)]
    return d


@pytest.mark.parametrize("command", [["equilibrium"], ["static", "--mesh", "4"],
                                     ["modal", "--model", "com"], ["study", "--out", "OUT"]])
def test_2000_stages_refused_fast_with_the_estimate(command, tmp_path, capsys):
    p = tmp_path / "tall.toml"
    p.write_bytes(tomli_w.dumps(stages(2000)).encode())
    # 2000 x 3 bars: n_q = 6 + 15 x 1999 = 29 991 coordinates, 12 000 nodes; the node
    # Jacobian alone is 3 x 12 000 x 29 991 doubles (8.6 GB)
    need = design_bytes(M=2000, N=3, n_tendons=3 + 18 * 1999)
    assert need > memory_limit()
    argv = [a.replace("OUT", str(tmp_path / "out")) for a in command] + [str(p)]
    t0 = time.perf_counter()
    rc, _, err = run(argv, capsys)
    line = last_line(err)
    assert rc == TOO_LARGE, err
    assert "2000 stages x 3 bars, 35985 tendons" in line and "equilibrium design" in line
    assert f"about {need / 2**30:.1f} GiB" in line and "the limit is" in line
    assert time.perf_counter() - t0 < 10


def test_a_few_stages_are_within_the_estimate():
    # the 2-3 preset's design: a few MB over the interpreter's base
    assert design_bytes(M=2, N=3, n_tendons=21) < 0.31e9
