"""The SBC free vibration on the fine 4 x 20 x 20 mesh (docs/guides/sbc.md, "Free vibration on the
fine mesh"): the run that stopped at t = 4.94 s, and how a failing model is named.

Sources: the other FE model (the MTC model on the same mesh, an independent formulation of
the same structure) within the bounds of the 4 x 10 x 10 comparison in docs/guides/sbc.md ("The
three models side by side"), and energy conservation of the undamped system.
"""
from __future__ import annotations

import functools
import os

import numpy as np
import pytest

from tmfem.cli import main

REDUCED = os.environ.get("TMFEM_SLOW_SCALE", "") == "reduced"


def test_compare_names_the_model_whose_integration_fails(monkeypatch, capsys):
    # a genuine Newton failure (one iteration allowed per step) in the first model run
    import tmfem.simulation.driver as driver
    monkeypatch.setattr(driver, "park_integrate",
                        functools.partial(driver.park_integrate, max_iter=1))
    rc = main(["compare", "--preset", "1-4", "--vibrate", "--mesh", "2", "--t-end", "0.05"])
    err = capsys.readouterr().err
    assert rc == 1                                     # ConvergenceError (docs/guides/cli.md)
    line = [ln for ln in err.splitlines() if "error" in ln][-1]
    assert line.startswith("tmfem compare: error: SBC model of 1-4 (FE mesh 2): Park step 1 "
                           "(t = 0.01 s, dt = 0.01 s): Newton did not converge in 1 iterations")
    assert "at the predictor" in line and "last |dx|" in line


@pytest.mark.slow
def test_fine_mesh_1_4_vibration_runs_past_the_old_failure():
    # 6.5.1 on the 4 x 20 x 20 mesh: plain Newton diverged at Park step 494 (t = 4.94 s) in
    # the SBC model; with the line search it runs through. No reduced size can reach the old
    # failure: the SBC part alone takes about an hour of wall time here (3488 s for 10 s).
    # CI covers the line search by tests/solvers/test_park.py (closed form) and the named failure
    # by test_compare_names_the_model_whose_integration_fails.
    if REDUCED:
        pytest.skip("4 x 20 x 20 SBC vibration to t = 4.94 s: about 30 min, full scale only")
    from tmfem.reference.vibration_compare import three_model_vibration
    t_end = 10.0
    r = three_model_vibration("1-4", t_end=t_end, dt=0.01, mesh_n=20)
    c = r["comparison"]
    assert c["t_end"] == pytest.approx(t_end)
    # undamped: Park's method only dissipates (the unresolved high modes); measured on
    # 4 x 10 x 10 over 10 s 2.8e-2 (SBC), 2.3e-2 (MTC); here 3.0e-2, 4.9e-2 (5 s: 8.6e-3, 1.1e-2)
    for m in ("SBC", "MTC"):
        assert c["energy_drift_over_initial_kinetic"][m] < 0.08, m
    # the two FE models against each other, within the bounds of the 4 x 10 x 10 run
    # (docs/guides/sbc.md: first 2 s rms differences 1.0 % theta_12, 1.0 % B_12 z, 7.4 % w_1;
    # amplitudes of the perturbed bar within 0.4 %); measured here 0.78 %, 0.78 %, 6.3 %,
    # 0.2 % (10 s) and 0.4 % (5 s), frequencies 0.3078 / 0.3079 Hz
    early = c["rms_difference_vs_SBC_early"]["MTC"]
    assert early["theta_12"] < 0.03 and early["B_12_z"] < 0.03
    assert early["w_1"] < 0.15
    pp = c["peak_to_peak"]
    assert pp["MTC"]["theta_12"] == pytest.approx(pp["SBC"]["theta_12"], rel=0.02)
    f = c["fitted_frequency_hz"]["theta_12"]
    assert f["MTC"] == pytest.approx(f["SBC"], rel=0.01)
    assert np.all(np.isfinite(r["signals"]["SBC"]["theta_12"]))
