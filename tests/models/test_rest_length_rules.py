"""The rest-length rules have one meaning in every command (docs/guides/mtc.md, "Rest-length rules"):
``design`` is the ch. 3 design on the analysis mesh, ``design@n`` the design on the n x n mesh
held fixed. The same rule at the same mesh gives the same frequencies in ``tmfem modal`` and
``tmfem converge``; the two rules differ at a mesh other than n (source of the design: eqs.
3.8-3.9 through tmfem.equilibrium.design_equilibrium; 1-4 preset, Table 6.2)."""
import json

import numpy as np
import pytest

from tmfem.cli import main

MESH, MODES = 4, 4


def _freqs(argv, capsys):
    assert main(argv + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    if "rows" in d:
        return d["rest_lengths_rule"], np.array([d["rows"][0][f"f{i + 1}"] for i in range(MODES)])
    return d["rest_lengths_source"], np.array(d["freq_hz"])


@pytest.mark.parametrize("rule", ["design", "design@10"])
def test_same_rule_same_mesh_same_frequencies(rule, capsys):
    common = ["--preset", "1-4", "--mesh", str(MESH), "--modes", str(MODES), "--rest-lengths", rule]
    src_m, f_modal = _freqs(["modal"] + common, capsys)
    src_c, f_conv = _freqs(["converge"] + common, capsys)
    assert src_m == src_c == rule
    # modal starts from the undeformed membrane, converge from the design: the same equilibrium
    assert f_modal == pytest.approx(f_conv, rel=1e-7)


def test_defaults_are_named_and_differ_off_the_design_mesh(capsys):
    base = ["--preset", "1-4", "--mesh", str(MESH), "--modes", str(MODES)]
    src_m, f_modal = _freqs(["modal"] + base, capsys)
    src_c, f_conv = _freqs(["converge"] + base, capsys)
    assert (src_m, src_c) == ("design", "design@10")
    # on the 4 x 4 x 4 mesh the point-corner design is stiffer than on 10 x 10 (F_Delta falls
    # like 1/log n, docs/guides/equilibrium.md): shorter rest lengths, higher frequencies
    assert f_modal[0] > 1.02 * f_conv[0]


def test_design_at_n_is_refused_when_malformed(capsys):
    rc = main(["modal", "--preset", "1-4", "--mesh", "4", "--rest-lengths", "design@x"])
    assert rc == 2 and "design@n with an integer n >= 1" in capsys.readouterr().err
