"""`tmfem control lpv FILE`: the grid, the rate bound and the scheduling values come from the
file's `[lpv]` table; a file without one is refused."""
import json
import re
from pathlib import Path

import numpy as np
import pytest

from tmfem.cli import main
from tmfem.errors import InputError
from tmfem.system import load_system
from tmfem.system.presets import _preset_files

DATA = Path(__file__).resolve().parents[1] / "data" / "systems"


def preset_text_renamed(name: str, *, printed: bool) -> str:
    """The 2-3-lpv preset file under another name, with or without its `[printed]` table."""
    text = _preset_files()["2-3-lpv"].read_text()
    text = re.sub(r'^name = ".*"$', f'name = "{name}"', text, count=1, flags=re.M)
    return text if printed else text[:text.index("[printed]")]


def bound_only(argv, capsys) -> dict:
    assert main(["control", "lpv", *argv, "--bound-only", "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.slow
def test_a_renamed_copy_of_the_preset_gives_the_preset_numbers(tmp_path, capsys):
    # the same [lpv] grid and rate bound read from a user file: the same frozen plants and
    # pointwise optima (Riccati) as the preset; without [printed] no printed bound is shown
    f = tmp_path / "my-two-stage.toml"
    f.write_text(preset_text_renamed("my-two-stage", printed=False))
    ours = bound_only([str(f), "--grid", "2x1"], capsys)
    ref = bound_only(["--preset", "2-3-lpv", "--grid", "2x1"], capsys)
    assert ours["system"] == "my-two-stage" and ours["grid"] == ref["grid"] == [2, 1]
    assert ours["rate_bound_deg"] == ref["rate_bound_deg"] == 10.0
    np.testing.assert_allclose(ours["pointwise_gamma"], ref["pointwise_gamma"], rtol=1e-10)
    np.testing.assert_allclose(ours["lpv_gamma_lower_bound_at"], ref["lpv_gamma_lower_bound_at"], rtol=1e-12)
    # --grid 2x1 takes both ends of theta and the middle psi of the 6 x 3 grid of 8.3
    assert np.degrees(ref["lpv_gamma_lower_bound_at"]) == pytest.approx([63.0, 8.36])
    assert "printed_gamma_bound" not in ours and ref["printed_gamma_bound"] == 4.18


def test_the_grid_and_the_rate_bound_are_the_files(tmp_path, capsys):
    text = preset_text_renamed("one-point", printed=False)
    text = re.sub(r"^theta_grid_deg = .*$", "theta_grid_deg = [70.0]", text, flags=re.M)
    text = re.sub(r"^psi_grid_deg = .*$", "psi_grid_deg = [8.0]", text, flags=re.M)
    text = re.sub(r"^rate_bound_deg = .*$", "rate_bound_deg = 5.0", text, flags=re.M)
    f = tmp_path / "one-point.toml"
    f.write_text(text)
    out = bound_only([str(f)], capsys)
    assert out["grid"] == [1, 1] and out["rate_bound_deg"] == 5.0
    assert np.degrees(out["lpv_gamma_lower_bound_at"]) == pytest.approx([70.0, 8.0])
    # the pointwise optimum is tight: the norm a static gain at 1.01 x it achieves lies between
    g, nrm = out["lpv_gamma_lower_bound"], out["lpv_gamma_lower_bound_achieved_norm"]
    assert g * (1 - 1e-4) <= nrm <= 1.01 * g * (1 + 1e-6)


@pytest.mark.parametrize("make, msg", [
    (lambda: (DATA / "square-2-4.toml").read_text(), "expected an [lpv] table with the design grid"),
    (lambda: re.sub(r"^theta_grid_deg = .*$", "", preset_text_renamed("x", printed=False), flags=re.M),
     "found no grid"),
])
def test_a_file_without_an_lpv_grid_is_refused(make, msg, tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text(make())
    assert main(["control", "lpv", str(f), "--bound-only"]) == 2
    err = capsys.readouterr().err.strip()
    assert msg in err and "theta_grid_deg" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("line, msg", [
    ("psi_grid_deg = [9.21, 7.5]", "strictly increasing"),
    ("psi_grid_deg = []", "strictly increasing"),
    ("rate_bound_deg = -1.0", "'rate_bound_deg' to be a finite number >= 0"),
    ("theta0_deg = 400.0", "'theta0_deg' to be an angle"),
])
def test_bad_lpv_fields_are_refused(line, msg, tmp_path):
    key = line.split(" = ")[0]
    text = re.sub(rf"^{key} = .*$", line, preset_text_renamed("x", printed=False), flags=re.M)
    f = tmp_path / "s.toml"
    f.write_text(text)
    with pytest.raises(InputError, match=re.escape(msg)):
        load_system(f)


@pytest.mark.slow
def test_the_lpv_deployment_of_a_renamed_copy_is_the_presets(design21, tmp_path, capsys):
    # the 8.4 deployment reads its grid, path and eq. 5.100 values from [lpv]: a user file that
    # is the preset under another name deploys with the same saved controller to the same run
    pl, d, path = design21
    f = tmp_path / "my-two-stage.toml"
    f.write_text(preset_text_renamed("my-two-stage", printed=False))
    runs = []
    for spec in ([str(f)], ["--preset", "2-3-lpv"]):
        assert main(["deploy", *spec, "--lpv-controller", str(path), "--t-end", "0.2", "--json"]) == 0
        runs.append(json.loads(capsys.readouterr().out))
    ours, ref = runs
    assert ours["system"] == "my-two-stage" and ours["controller"] == ref["controller"] == "lpv"
    for key in ("t_end_s", "max_membrane_deflection_m", "max_tendon_stress_Pa", "peak_bar_compression_N"):
        assert ours[key] == pytest.approx(ref[key], rel=1e-10), key


@pytest.mark.slow
def test_a_user_two_stage_system_gets_its_own_lpv_bound(capsys):
    # a 2-5 of our own (tests/data/systems/pentagon-2-5-lpv.toml), reduced to the two ends of
    # its theta grid at the middle psi: the frozen plants at the file's points, no printed bound,
    # and the pointwise optimum tight (the norm a static gain at 1.01 x it achieves lies between)
    out = bound_only([str(DATA / "pentagon-2-5-lpv.toml"), "--grid", "2x1"], capsys)
    assert out["system"] == "pentatower-lpv" and out["grid"] == [2, 1] and "printed_gamma_bound" not in out
    g = np.asarray(out["pointwise_gamma"]).ravel()
    assert np.all(np.isfinite(g)) and np.all(g > 0)
    assert out["lpv_gamma_lower_bound"] == pytest.approx(g.max(), rel=1e-12)
    assert np.degrees(out["lpv_gamma_lower_bound_at"])[1] == pytest.approx(25.0)
    assert np.degrees(out["lpv_gamma_lower_bound_at"])[0] in (pytest.approx(64.0), pytest.approx(70.0))
    nrm = out["lpv_gamma_lower_bound_achieved_norm"]
    assert g.max() * (1 - 1e-4) <= nrm <= 1.01 * g.max() * (1 + 1e-6)


def test_an_lpv_path_other_than_the_grid_rules_is_refused(tmp_path):
    text = (DATA / "pentagon-2-5-lpv.toml").read_text().replace('path = "table-7-7-bases"', 'path = "linear"')
    f = tmp_path / "s.toml"
    f.write_text(text)
    with pytest.raises(InputError, match=re.escape("expected 'path' to be one of ['table-7-7-bases', 'auto']")):
        load_system(f)
