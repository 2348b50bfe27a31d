"""A static solve that ends in a collapsed or unstable structure is named as such (exit 1,
one line naming the bars, the tendons and the check), before any file is written."""
import re

import numpy as np
import pytest

from tests.cli.test_cli_misuse import REFUSED, last_line, run
from tmfem.errors import CollapsedStructure
from tmfem.system import load_preset
from tmfem.system.collapse import check_standing, flat_bars, nonfinite_keys


@pytest.mark.parametrize("command", [["static"], ["modal"], ["static", "--model", "sbc"]])
def test_rest_length_far_too_short_is_a_collapse(command, tmp_path, capsys):
    # 1-4: the designed rest length is 1.509 m (docs/guides/equilibrium.md); 0.4 m pulls the bars
    # flat onto the base plane (theta = 90 deg), where the membrane's law breaks down
    vtu = tmp_path / "s.vtu"
    argv = command + ["--preset", "1-4", "--mesh", "4", "--rest-lengths", "S1=0.4"]
    if command == ["static"]:
        argv += ["--vtk", str(vtu)]
    rc, out, err = run(argv, capsys)
    line = last_line(err)
    assert rc == REFUSED, err
    assert "collapsed: bars b_11, b_12, b_13, b_14 lie flat" in line
    # the most stretched tendons named (the four S tendons stretch alike, 3.53 x)
    assert re.search(r"S_1\d at 3\.5\d x its rest length", line)
    assert not vtu.exists()                       # refused before any file is written
    assert "nan" not in out.lower()


def test_flat_bars_of_a_configuration():
    s = load_preset("1-4")
    X = s.nodes().copy()
    n = s.M * s.N
    assert flat_bars(s, X) == []
    X[2, n + 1] = X[2, 1] + 0.01 * 2.015           # b_12 at 1 % of l: flat (limit 2 %)
    X[2, n + 2] = X[2, 2] - 0.5                     # b_13 through its lower end
    assert flat_bars(s, X) == [1, 2]
    with pytest.raises(CollapsedStructure, match=r"bars b_12, b_13 lie flat"):
        check_standing(s, X, what="test")


def test_nonfinite_results_are_named():
    s = load_preset("1-4")
    assert nonfinite_keys({"a": 1.0, "b": [1.0, np.nan], "c": {"d": np.inf}, "e": "x"}) == ["b", "c.d"]
    with pytest.raises(CollapsedStructure, match=r"has no valid state: non-finite results \(m\.vm"):
        check_standing(s, s.nodes(), what="test", values={"m": {"vm": float("nan")}})


def test_negative_stiffness_is_unstable():
    from types import SimpleNamespace
    from tmfem.system.collapse import check_stable
    model = SimpleNamespace(system=load_preset("1-4"), name="mtc")
    check_stable(model, SimpleNamespace(omega2=np.array([1e-9, 4.0, 9.0])))
    with pytest.raises(CollapsedStructure, match=r"unstable: 1 of 3 modes have negative stiffness "
                                                 r"\(mode 1: omega\^2 = -2"):
        check_stable(model, SimpleNamespace(omega2=np.array([-2.0, 4.0, 9.0])))
