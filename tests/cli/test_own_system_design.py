"""Design assistance of `tmfem equilibrium` on user systems: the membrane radius for a target
Delta, stage bases of a two-stage system, a packaged configuration of a 1-N(D) system, and
errors that say what to change."""
import json
import tomllib
from pathlib import Path

import pytest
import tomli_w

from tmfem.cli import main

SYSTEMS = Path(__file__).resolve().parents[1] / "data" / "systems"


def run(argv, capsys, rc=0):
    code = main(argv + ["--json"])
    out, err = capsys.readouterr()
    assert code == rc, err
    return (json.loads(out) if rc == 0 else None), err


def write(tmp_path, d, name="s.toml"):
    p = tmp_path / name
    p.write_bytes(tomli_w.dumps(d).encode())
    return str(p)


def test_slack_membrane_error_names_r_mb_and_target_delta_fixes_it(tmp_path, capsys):
    """A 1-5 with r_mb = 1.6 m is slack (Delta < 0); the error says to decrease r_mb below
    R_M; --target-delta 1.5 gives the r_mb whose design has Delta = 1.5 mm (eq. 3.22)."""
    d = tomllib.loads((SYSTEMS / "pentagon-1-5.toml").read_text())
    d["membrane"]["r_mb"] = 1.6
    f = write(tmp_path, d)
    _, err = run(["equilibrium", f], capsys, rc=1)
    assert "decrease r_mb below R_M = " in err
    r, _ = run(["equilibrium", f, "--target-delta", "1.5"], capsys)
    assert r["ok"] and r["Delta"] == pytest.approx(1.5e-3, rel=1e-9)
    m = r["membrane_radius"]
    assert m["r_mb_max"] - m["r_mb"] == pytest.approx(1.5e-3) and m["r_mb"] < 1.6


def test_packaged_band_of_1_4d_contains_the_printed_initial_configuration(capsys):
    """At theta = 87.6 deg the band of feasible psi of the preset 1-4D contains the initial
    configuration of Table 7.3 (psi = 38.4 deg, a feasible equilibrium: preset 1-4D-initial)."""
    r, _ = run(["equilibrium", "--preset", "1-4D", "--packaged", "87.6"], capsys)
    assert any(a <= 38.4 <= b for a, b in r["psi_deg_bands"])
    assert r["Delta"] > 0


def test_packaged_configuration_of_a_user_1_5d_is_feasible(tmp_path, capsys):
    """The suggested packaged psi of the 1-5(D), written as [packaged], passes the deployment's
    pre-run check (both configurations feasible equilibria)."""
    from tmfem.reference.deployments import checked_configurations
    from tmfem.system import load_system
    r, _ = run(["equilibrium", str(SYSTEMS / "pentagon-1-5D.toml"), "--packaged", "87.6"], capsys)
    d = tomllib.loads((SYSTEMS / "pentagon-1-5D.toml").read_text())
    d["packaged"] = {"symmetric": {"theta_deg": [87.6], "psi_deg": [r["psi_deg"]]}}
    s = checked_configurations(load_system(write(tmp_path, d)))
    assert s.problem.packaged.rest_lengths is not None
    assert r["Delta"] == pytest.approx(r["Delta_deployed"], abs=2e-4)


def test_bases_of_a_two_stage_system_give_a_feasible_design(tmp_path, capsys):
    """--bases on the 2-4 with a stage-2 base that has no positive null vector (a local search
    from the file's base: a start far from any feasible base may end infeasible, and says so): the printed
    [symmetric] entries (degrees) with r_mb from --target-delta 1 make a feasible design."""
    d = tomllib.loads((SYSTEMS / "square-2-4.toml").read_text())
    # slack tendons: the reduced matrix of 3.3.2 has no positive null vector (margin -0.16)
    d["symmetric"].update(z=[0.0, 0.3], r=[0.75, 0.5], sigma_deg=[0.0, -30.0], psi_deg=[20.0, -10.0])
    f = write(tmp_path, d)
    _, err = run(["equilibrium", f], capsys, rc=1)
    assert "--bases" in err or "r_mb" in err
    r, _ = run(["equilibrium", f, "--bases"], capsys)
    assert r["feasible"] and r["margin"] > 0
    d["symmetric"] = r["symmetric"]
    if r["r_mb"] is not None:                     # the bases need another membrane radius
        d["membrane"]["r_mb"] = r["r_mb"]
    f = write(tmp_path, d)
    r, _ = run(["equilibrium", f, "--target-delta", "1"], capsys)
    assert r["ok"] and r["Delta"] == pytest.approx(1e-3, rel=1e-6)
