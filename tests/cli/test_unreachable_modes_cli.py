"""Deployment and report of a user system whose COM has membrane modes no tendon reaches.

``square-1-4D.toml`` (a 1-4(D) at 3 m, K = 4): the membrane mode at 4.276 Hz has PBH margin 0
(eq. 5.71). ``tmfem deploy`` and ``tmfem report`` refuse its H-infinity switch by default,
naming the mode, the option and the file key; with ``--exclude-uncontrollable`` or
``[control] uncontrollable = "exclude"`` the switch is designed on the reachable part and the
deployment runs.
"""
import json
from pathlib import Path

import pytest

from tmfem.cli import main

SYSTEMS = Path(__file__).resolve().parents[1] / "data" / "systems"
SQUARE = SYSTEMS / "square-1-4D.toml"


def deploy_json(argv, capsys):
    rc = main(["deploy", *argv, "--json", "--quiet"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    return json.loads(out)


def unreachable_hz(capsys):
    """The frequencies [Hz] of the modes `control pbh` finds uncontrollable (margin <= tol), one
    per complex pair: the independent source of the excluded modes."""
    assert main(["control", "pbh", str(SQUARE), "--json"]) == 0
    p = json.loads(capsys.readouterr().out)["pbh"]
    lc = p["least_controllable"]
    assert lc["margin"] <= p["tol"] and p["controllable"] is False
    return lc["frequency_hz"]


def test_deploy_refuses_unreachable_modes_naming_option_and_key(capsys):
    assert main(["deploy", str(SQUARE), "--quiet", "--t-end", "1"]) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "4.276 Hz are not reached by any tendon" in err
    assert "--exclude-uncontrollable" in err and 'uncontrollable = "exclude"' in err and "[control]" in err


@pytest.mark.slow
def test_deploy_with_excluded_modes_runs_and_names_them(tmp_path, capsys):
    """With the option: the excluded mode is the one `control pbh` finds unreachable, the
    switch happens and the run ends at the deployed configuration (eq. 5.70 error far below
    R_c = 0.01) with no failed check; the file key gives the same run."""
    f_pbh = unreachable_hz(capsys)
    r = deploy_json([str(SQUARE), "--exclude-uncontrollable"], capsys)
    assert r["excluded_modes_hz"] == pytest.approx([f_pbh], rel=1e-9)
    assert r["switch_time_s"] is not None and r["final_tracking_error"] < 1e-3
    assert r["failed_checks"] == [] and r["failure"] is None
    keyed = tmp_path / "square-exclude.toml"
    keyed.write_text(SQUARE.read_text() + '\n[control]\nuncontrollable = "exclude"\n')
    k = deploy_json([str(keyed)], capsys)
    assert k["excluded_modes_hz"] == r["excluded_modes_hz"]
    assert (k["switch_time_s"], k["final_tracking_error"]) == (r["switch_time_s"], r["final_tracking_error"])
    assert main(["deploy", str(SQUARE), "--exclude-uncontrollable", "--quiet"]) == 0
    assert "modes no tendon reaches, left out of the H-infinity switch" in capsys.readouterr().out


@pytest.mark.parametrize("argv", [["--controller", "adaptive-lqr"], ["--controller", "adaptive"]])
def test_deploy_refuses_the_option_without_the_hinf_switch(argv, capsys):
    assert main(["deploy", str(SQUARE), "--exclude-uncontrollable", *argv, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "--exclude-uncontrollable applies to the H-infinity switch" in err and argv[1] in err


def test_file_key_is_checked(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(SQUARE.read_text() + '\n[control]\nuncontrollable = "ignore"\n')
    assert main(["deploy", str(bad), "--quiet"]) == 2
    assert "expected 'uncontrollable' to be one of ['refuse', 'exclude'], found 'ignore'" in capsys.readouterr().err


def test_report_option_without_a_deployment_is_refused(tmp_path, capsys):
    out = tmp_path / "rep"
    assert main(["report", str(SYSTEMS / "triangle-1-3.toml"), "--out", str(out),
                 "--exclude-uncontrollable", "--quiet"]) == 2
    assert "option does not apply" in capsys.readouterr().err


@pytest.mark.slow
def test_report_deploys_with_excluded_modes(tmp_path, capsys):
    """The report of the same system with the option: exit 0, the deployment section and the
    text name the excluded mode, the JSON lists it."""
    out = tmp_path / "rep"
    rc = main(["report", str(SQUARE), "--out", str(out), "--mesh", "4", "--t-end", "0.5",
               "--no-render", "--quiet", "--exclude-uncontrollable"])
    text = capsys.readouterr().out
    assert rc == 0, text
    r = json.loads((out / "report.json").read_text())
    assert r["failed_checks"] == [] and r["deployment"]["excluded_modes_hz"] == pytest.approx([4.2756], abs=1e-4)
    section = (out / "index.md").read_text().split("## 5. Deployment")[1]
    assert "left out of the H-infinity design" in section and "4.276 Hz" in section
    assert "--exclude-uncontrollable" in section
    assert "modes no tendon reaches, left out of the H-infinity switch" in text
