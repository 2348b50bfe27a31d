"""``tmfem equilibrium FILE --packaged THETA`` on symmetric M >= 2 systems: the printed
``[packaged] symmetric`` line pastes into the file (TOML), reproduces the user 2-6's own
[packaged] (the file was made with it), `deploy` starts from it, a theta without a packaged
equilibrium is a one-line InfeasibleDesign (exit 1), and a general system is refused (exit 2).
The library's result is tested against independent checks in
tests/control/deployment/test_packaged_stages.py."""
import tomllib

import numpy as np
import pytest

from tests.cli.test_cli_units import _unitless_numbers
from tests.cli.test_own_system_design import SYSTEMS, run, write
from tests.system.test_validate import general_2_3
from tmfem.cli import main
from tmfem.cli.equilibrium import format_text
from tmfem.system import load_system


@pytest.mark.slow
def test_packaged_of_the_2_6_is_its_own_and_pastes_into_the_file(capsys):
    f = SYSTEMS / "hexagon-2-6.toml"
    r, _ = run(["equilibrium", str(f), "--packaged", "70"], capsys)
    assert r["assist"] == "packaged-stages" and r["path"]["points_checked"] == 101
    assert r["path"]["min_margin"] > 0 and r["Delta"] == pytest.approx(r["Delta_deployed"], abs=1e-12)
    assert _unitless_numbers({k: v for k, v in r.items() if k != "units"}) == []
    # the text's last two lines are a TOML table with the JSON's entries
    text = format_text(r)
    pasted = tomllib.loads("\n".join(text.splitlines()[-2:]))["packaged"]["symmetric"]
    assert pasted == r["symmetric"]
    # ... and the file's [packaged] is that table
    own = tomllib.loads(f.read_text())["packaged"]["symmetric"]
    assert own == r["symmetric"]
    s = load_system(f)
    assert s.problem.packaged.symmetric.membrane_delta(6, s.r_mb) == pytest.approx(r["Delta_deployed"], abs=1e-9)


@pytest.mark.slow
def test_deploy_starts_from_the_packaged_configuration_found_for_a_2_4(tmp_path, capsys):
    # the 2-4 has no [packaged]; the one found at theta = 70 deg, written into a copy with a
    # [deployment] table, is checked before the run (both designs, the automatic path) and a
    # short deployment from it runs (rc 0) with no slack tendon
    r, _ = run(["equilibrium", str(SYSTEMS / "square-2-4.toml"), "--packaged", "70"], capsys)
    d = tomllib.loads((SYSTEMS / "square-2-4.toml").read_text())
    d["packaged"] = {"symmetric": r["symmetric"]}
    d["deployment"] = {"omega_r": 0.5, "uncertainty": "exact"}
    dep, _ = run(["deploy", write(tmp_path, d), "--t-end", "0.2", "--dt", "0.02"], capsys)
    assert dep["path"] == "auto" and dep["path_check"]["min_margin"] > 0
    assert dep["failure"] is None and np.isfinite(dep["final_tracking_error"])


@pytest.mark.slow
def test_a_theta_without_packaged_equilibria_is_one_line(capsys):
    rc = main(["equilibrium", str(SYSTEMS / "pentagon-2-5.toml"), "--packaged", "30"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 1 and len(err) == 1
    assert err[0].startswith("tmfem equilibrium: error: packaged configuration: no feasible equilibrium at "
                             "theta = 30 deg (psi in [-80, 80] deg in steps down to 10 deg")
    assert "no positive null vector of 3.3.2" in err[0] and "eq. 3.22 has a top radius for" in err[0]


def test_packaged_is_refused_on_a_general_system(tmp_path, capsys):
    rc = main(["equilibrium", write(tmp_path, general_2_3()), "--packaged", "70"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "expected a symmetric system" in err and len(err.splitlines()) == 1


def test_packaged_is_refused_on_a_one_stage_system_that_does_not_deploy(capsys):
    rc = main(["equilibrium", str(SYSTEMS / "pentagon-1-5.toml"), "--packaged", "80"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "expected a 1-N(D) system (deployable = true) or a symmetric system with M >= 2 " \
                       "stages, found 1-5" in err


@pytest.mark.slow
def test_the_2_6_deploys_from_its_packaged_configuration(capsys):
    """`deploy FILE` of the 2-6 from the [packaged] that `--packaged 70` gave, coarse step: the
    automatic path checked at 101 points, the switch to the H-infinity controller (eq. 5.70,
    R_c = 0.01, after the reference of eq. 5.68 with omega_r = 0.5 rad/s has settled to 1 %:
    t > 13.3 s), no failed strength check (tendons below the file's 450 MPa yield stress), rest
    lengths above r_min."""
    r, _ = run(["deploy", str(SYSTEMS / "hexagon-2-6.toml"), "--t-end", "20", "--dt", "0.02"], capsys)
    assert r["path"] == "auto" and r["path_check"]["points_checked"] == 101 and r["path_check"]["min_margin"] > 0
    assert r["switch_time_s"] is not None and 13.3 < r["switch_time_s"] < 20
    assert r["final_tracking_error"] < 0.01 and r["failure"] is None and r["failed_checks"] == []
    assert r["max_tendon_stress_Pa"] < 450e6 and r["min_rest_length_margin_m"] > 0
