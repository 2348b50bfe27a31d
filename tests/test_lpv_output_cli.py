"""`tmfem control lpv --output-feedback`: refusals and one grid point of the 2-3 plant."""
import json

import numpy as np
import pytest

from tmfem.cli import main


@pytest.mark.parametrize("argv, msg", [
    (["control", "lpv", "--noise", "0.01"], "apply with --output-feedback only"),
    (["control", "lpv", "--sample-time", "0.01"], "apply with --output-feedback only"),
    (["control", "lpv", "--output-feedback", "--bound-only"], "does not apply with --output-feedback"),
    (["control", "lpv", "--output-feedback", "--noise", "0"], "expected a weight > 0"),
    (["control", "lpv", "--output-feedback", "--sample-time", "-1"], "expected dt > 0"),
    (["control", "hinf", "--preset", "1-4D", "--output-feedback"], "apply to `tmfem control lpv` only"),
])
def test_output_feedback_cli_refuses_bad_input(argv, msg, capsys):
    assert main(argv) == 2
    assert msg in capsys.readouterr().err


@pytest.mark.slow          # one grid point is already the reduced size (about 25 s idle, 85 s at load 12)
def test_output_feedback_on_one_point_of_the_2_3_plant(capsys, tmp_path):
    # one grid point (theta = 63, psi = 7.5 deg), K(rho) a feasible point at gamma = 20 (EIGOPT):
    # at a design point the frozen loop separates (eigenvalues of A + B2 K and A - L C): its
    # slowest pole is the state feedback's (closed_loop_max_real), the Kalman estimator's being
    # faster here (max Re(A - L C) <= -0.372 at every grid point of P_D, logged); and its norm
    # from [q_d, n_d, n] to p is no smaller than the state-feedback optimum there (the
    # pointwise bound, Riccati test: output feedback cannot beat state feedback on [q_d, n_d])
    f = tmp_path / "of.npz"
    assert main(["control", "lpv", "--grid", "1x1", "--solver", "EIGOPT", "--gamma", "20", "--output-feedback",
                 "--sample-time", "2e-4", "--save", str(f), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["output_feedback"] and out["output_feedback_passed"] and out["passed"]
    assert out["measured"][4:6] == ["theta_13", "psi_13"] and out["measured"][21:] == [f"wr_{i}" for i in range(1, 5)]
    assert out["output_feedback_closed_loop_max_real"] == pytest.approx(out["closed_loop_max_real"], rel=1e-6)
    assert out["output_feedback_closed_loop_max_real"] < 0 and out["output_feedback_sampled_max_radius"] < 1
    assert out["gamma"] >= out["lpv_gamma_lower_bound"] * (1 - 1e-4)
    assert out["state_feedback_gamma"] == 20.0 and out["verification_max_eig"] < 0
    saved = np.load(f)
    assert saved["L"].shape == (1, 1, 50, 25) and float(saved["W_n"]) == 1e-3
