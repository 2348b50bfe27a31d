"""`tmfem control lpv`: input refusals and the pointwise bound on a small grid (the synthesis
itself: tests/control/lpv/test_lpv_synthesis.py)."""
import json

import numpy as np
import pytest

from tmfem.cli import main


@pytest.mark.parametrize("argv, msg", [
    (["control", "lpv", "--grid", "7x3"], "at most 6x3"),
    (["control", "lpv", "--grid", "six"], "expected AxB"),
    (["control", "lpv", "--refine", "2"], "expected >= 4"),
    (["control", "lpv", "--preset", "2-3", "--grid", "1x1"], "expected an [lpv] table"),
    (["control", "lpv", "--alpha", "0.4"], "do not apply"),
    (["control", "lpv", "--solver", "ARE"], "applies to `tmfem control hinf` only"),
    (["control", "pbh", "--preset", "1-4D", "--grid", "2x2"], "apply to `tmfem control lpv` only"),
    (["control", "hinf", "--preset", "1-4D", "--gamma", "3"], "apply to `tmfem control lpv` only"),
    (["control", "hinf", "--preset", "1-4D", "--solver", "EIGOPT"], "applies to `tmfem control lpv` only"),
])
def test_lpv_cli_refuses_bad_input(argv, msg, capsys):
    assert main(argv) == 2
    assert msg in capsys.readouterr().err


@pytest.mark.slow
def test_lpv_cli_bound_only_on_one_point(capsys):
    # one grid point (theta = 71.59 deg, psi = 8.36 deg of P_D: one point of an axis is its middle): the pointwise
    # state-feedback optimum (Riccati test) is tight: a static gain designed at 1.01 x it has a
    # closed-loop H-infinity norm (SLICOT ab13dd via python-control) between the two
    assert main(["control", "lpv", "--grid", "1x1", "--bound-only", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["grid"] == [1, 1] and out["printed_gamma_bound"] == 4.18
    assert np.degrees(out["lpv_gamma_lower_bound_at"]) == pytest.approx([71.59, 8.36])
    g, nrm = out["lpv_gamma_lower_bound"], out["lpv_gamma_lower_bound_achieved_norm"]
    assert g * (1 - 1e-4) <= nrm <= 1.01 * g * (1 + 1e-6)
    assert "gamma" not in out
