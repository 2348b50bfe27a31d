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


def test_packaged_configuration_of_a_user_1_6d_deploys_along_a_feasible_path(capsys):
    """--packaged on a 1-6(D) of our own: the suggested psi is the file's [packaged] one, it lies
    in a printed band, and the delta-rule path from it to the deployed configuration is an
    equilibrium (eq. 3.41) at 101 progress values, checked here by the deployment's own
    reference and checker; Delta within 10 % of the deployed one (eq. 3.22)."""
    import numpy as np

    from tmfem.control.deployment.reference_trajectory import DeploymentReference
    from tmfem.control.deployment.run import equilibrium_checker
    from tmfem.system import load_system
    f = str(SYSTEMS / "hexagon-1-6D.toml")
    r, _ = run(["equilibrium", f, "--packaged", "86"], capsys)
    s = load_system(f)
    assert r["psi_deg"] == pytest.approx(np.degrees(s.problem.packaged.symmetric.psi[0]))
    assert any(a <= r["psi_deg"] <= b for a, b in r["psi_deg_bands"])
    assert r["Delta"] == pytest.approx(r["Delta_deployed"], rel=0.1) and r["path_points_checked"] == 101
    ref = DeploymentReference(initial=s.problem.packaged.symmetric, final=s.symmetric, N=6,
                              q_names=list(s.q_names), omega_r=0.5, r_mb=s.r_mb)
    assert ref.check_equilibria(checker=equilibrium_checker(s), n=101).size == 101


def test_packaged_psi_of_a_1_3d_skips_a_start_whose_path_leaves_the_equilibria(capsys, monkeypatch):
    """The 1-3(D) at theta = 80 deg: the psi of smallest Delta (30 deg = 90 - 180/N, where
    eq. 3.22 puts the bar ends closest to the axis) has no feasible delta-rule path to the
    deployed configuration, so another psi of the band is suggested, whose path is feasible;
    above theta_max = asin((r_mb + Delta_e + r_1) / l) the deployed Delta is out of reach and
    the text says so. (The command runs twice, for its JSON and for its text; the scan of
    the same file at the same theta is computed once and the second run prints it.)"""
    import dataclasses

    import numpy as np

    from tmfem.control.deployment import packaged
    from tmfem.control.deployment.reference_trajectory import DeploymentReference
    from tmfem.control.deployment.run import equilibrium_checker
    from tmfem.errors import InfeasibleDesign
    from tmfem.system import load_system
    scans, scan = {}, packaged.packaged_configurations

    def once(system, *, theta_deg, **kw):
        key = (system.name, theta_deg, tuple(sorted(kw.items())))
        if key not in scans:
            scans[key] = scan(system, theta_deg=theta_deg, **kw)
        return scans[key]
    monkeypatch.setattr(packaged, "packaged_configurations", once)
    f = str(SYSTEMS / "triangle-1-3D.toml")
    r, _ = run(["equilibrium", f, "--packaged", "80"], capsys)
    s = load_system(f)
    c = s.symmetric

    def path_from(psi_deg):
        start = dataclasses.replace(c, theta=np.radians([80.0]), psi=np.radians([psi_deg]))
        ref = DeploymentReference(initial=start, final=c, N=3, q_names=list(s.q_names), omega_r=0.5,
                                  r_mb=s.r_mb)
        return ref.check_equilibria(checker=equilibrium_checker(s), n=101)

    with pytest.raises(InfeasibleDesign):
        path_from(30.0)
    assert path_from(r["psi_deg"]).size == 101 and r["psi_deg"] != 30.0
    Delta_e = r["Delta_deployed"]
    assert r["theta_max_deg"] == pytest.approx(np.degrees(np.arcsin((s.r_mb + Delta_e + c.r[0]) / c.l[0])))
    assert main(["equilibrium", f, "--packaged", "80"]) == 0 and len(scans) == 1
    assert f"reachable only for theta <= {r['theta_max_deg']:.4g} deg" in capsys.readouterr().out


def test_bases_print_the_file_angle_as_written(tmp_path):
    """--bases at theta = 60 deg prints theta_deg = [60.0, 60.0] (not the radian round trip's
    59.99999999999999), as the file has it."""
    from tmfem.equilibrium.assist import feasible_bases
    from tmfem.system import load_system
    d = tomllib.loads((SYSTEMS / "square-2-4.toml").read_text())
    d["symmetric"].update(theta_deg=[60.0, 60.0])
    r = feasible_bases(load_system(write(tmp_path, d)), starts=1)
    assert r["symmetric"]["theta_deg"] == [60.0, 60.0]
