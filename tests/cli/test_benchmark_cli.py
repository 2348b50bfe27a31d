"""``tmfem benchmark``: registry, JSON rows with units, CSV and refusals.

Source of the numbers: the closed-form total-Lagrangian load of the two-bar arch
(benchmarks.json von_mises_truss_formulas), also checked in test_element_benchmarks.
"""
import csv
import json

import numpy as np
import pytest

from tmfem.cli import main


def test_list_names_every_benchmark(capsys):
    assert main(["benchmark", "--list", "--json"]) == 0
    names = json.loads(capsys.readouterr().out)["benchmarks"]
    assert "truss-arch" in names


def test_truss_arch_rows_follow_the_closed_form(tmp_path, capsys):
    out = tmp_path / "arch.csv"
    assert main(["benchmark", "truss-arch", "--reduced", "--json", "--csv", str(out)]) == 0
    r = json.loads(capsys.readouterr().out)
    P = np.array([row["P"] for row in r["rows"]])
    Pc = np.array([row["P_closed_form"] for row in r["rows"]])
    np.testing.assert_allclose(P, Pc, atol=1e-9 * r["P_limit_closed_form_N"])
    assert r["units"] == {"v": "m", "P": "N", "P_closed_form": "N"}
    with open(out, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["v [m]", "P [N]", "P_closed_form [N]"] and len(rows) == len(P) + 1


@pytest.mark.parametrize("argv, message", [
    (["benchmark"], "expected a benchmark name or --list"),
    (["benchmark", "no-such"], "expected one of"),
    (["benchmark", "--list", "truss-arch"], "--list takes no benchmark name"),
    (["benchmark", "truss-arch", "--plot", "x.jpg"], ".png"),
])
def test_bad_benchmark_calls_are_refused(argv, message, capsys):
    assert main(argv) == 2
    assert message in capsys.readouterr().err
