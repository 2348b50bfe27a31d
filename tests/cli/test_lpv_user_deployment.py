"""The LPV deployment of a user five-bar two-stage system from the command line
(tests/data/systems/pentagon-2-5-lpv.toml: theta from 70 to 64 deg at psi = 25 deg, eq. 5.100),
designed and deployed as a user would: `tmfem control lpv FILE --sample-time DT --save` on a
2 x 1 grid (the verification on the 5 x 1 grid, refined by cutting planes where the design
fails between its points), then `tmfem deploy FILE --controller lpv --lpv-controller`.
Sources: 7.4 (rest lengths never above the tendon lengths), the file's yield stresses, the
pointwise lower bound of gamma (tmfem.control.lpv.bounds)."""
import json
import os
from pathlib import Path

import pytest

from tmfem.cli import main

PENTAGON = Path(__file__).resolve().parents[1] / "data" / "systems" / "pentagon-2-5-lpv.toml"
REDUCED = os.environ.get("TMFEM_SLOW_SCALE") == "reduced"


@pytest.mark.slow
def test_a_user_five_bar_system_is_designed_and_deployed_by_lpv(tmp_path, capsys):
    design = tmp_path / "c.npz"
    assert main(["control", "lpv", str(PENTAGON), "--grid", "2x1", "--sample-time", "0.01",
                 "--gamma-rtol", "0.2" if REDUCED else "0.05", "--save", str(design), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["system"] == "pentatower-lpv" and out["scheduling_parameters"] == ["theta_15", "psi_15"]
    assert out["verification_grid"] == [5, 1] and out["passed"] is True
    assert out["verification_max_eig"] < 0 and out["sampled_max_radius"] < 1
    assert out["lpv_gamma_lower_bound"] <= out["gamma"] <= 2 * out["lpv_gamma_lower_bound"]
    if "design_refinement" in out:                  # the design failed between its points
        assert out["design_refinement"]["passed"] and out["gamma"] == out["design_refinement"]["gamma"]

    t_end = 6.0 if REDUCED else 20.0
    assert main(["deploy", str(PENTAGON), "--controller", "lpv", "--lpv-controller", str(design),
                 "--t-end", str(t_end), "--json"]) == 0
    run = json.loads(capsys.readouterr().out)
    assert run["failure"] is None and run["t_end_s"] == pytest.approx(t_end)
    assert run["gamma"] == pytest.approx(out["gamma"], rel=1e-12)
    assert run["min_rest_length_margin_m"] > 0                        # 7.4: no rest length above its tendon
    assert run["max_tendon_stress_Pa"] < 94.8e6                       # the file's tendon yield stress
    assert run["max_von_mises_Pa"] < 61e6                             # the file's membrane yield stress
    assert run["max_tracking_error"] < 0.01
    assert run["peak_bar_compression_N"] < run["bar_critical_load_N"]
