"""Systems a user describes, through the commands, with nothing of the dissertation by name.

The user systems of ``tests/data/systems/`` (a 1-3, a 1-5, a 1-5(D) with its packaged
configuration, a 2-4, the 1-4 re-materialised at 3 m) and two impostors: the preset 1-4's
structure under another name, and the 1-5 under the preset name ``1-4``. A file carries what it
declares and nothing else: no printed frequencies, no implied prestress, no explanations, no
7.4 design data appear for them.
"""
import json
import re
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from tmfem.cli import main
from tmfem.system.presets import preset_dict

SYSTEMS = Path(__file__).resolve().parents[1] / "data" / "systems"
#: text that only the dissertation's data put into an output
DISSERTATION = ("Table 6", "Table 7", "dissertation", "errata", "1.5025", "7.32", "implied")


def run(argv, capsys):
    rc = main(argv + ["--json"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    return json.loads(out), out


def structure_of(preset: str, name: str) -> dict:
    """The structure of a preset (what docs/guides/system-file.md shows) under ``name``:
    none of its printed, report, control or deployment tables."""
    d = preset_dict(preset)
    for k in ("printed", "report", "notes", "control", "deployment", "packaged", "lpv", "monitor"):
        d.pop(k, None)
    return {**d, "name": name, "description": "a user's copy"}


@pytest.fixture(scope="module")
def impostors(tmp_path_factory):
    """(the 1-4 structure named 'my-1-4', the 1-5 named '1-4', the 1-5(D) named '1-4D')."""
    import tomllib
    root = tmp_path_factory.mktemp("impostors")
    files = []
    for name, d in (("my-1-4", structure_of("1-4", "my-1-4")),
                    ("1-4", {**tomllib.loads((SYSTEMS / "pentagon-1-5.toml").read_text()), "name": "1-4"}),
                    ("1-4D", {**tomllib.loads((SYSTEMS / "pentagon-1-5D.toml").read_text()), "name": "1-4D"})):
        p = root / f"{name}.toml"
        p.write_bytes(tomli_w.dumps(d).encode())
        files.append(p)
    return files


def assert_no_dissertation(text: str):
    found = [w for w in DISSERTATION if w in text]
    assert not found, found


@pytest.mark.parametrize("which", [0, pytest.param(1, marks=pytest.mark.slow)])
def test_modal_of_a_renamed_preset_prints_no_table(which, impostors, capsys):
    """`modal` (MTC and COM): no 'dissertation' columns, no differences to Table 6.6."""
    f = str(impostors[which])
    r, out = run(["modal", f, "--model", "mtc", "--modes", "4", "--mesh", "4"], capsys)
    assert "dissertation" not in r and "relative_difference_to_MTC" not in r
    assert np.all(np.isfinite(r["freq_hz"])) and min(r["freq_hz"]) > 0
    r, out = run(["modal", f, "--model", "com", "--modes", "6"], capsys)
    assert "dissertation" not in r and "relative_difference" not in r
    assert_no_dissertation(out)


@pytest.mark.parametrize("which", [0, pytest.param(1, marks=pytest.mark.slow)])
def test_report_of_a_renamed_preset_is_its_own(which, impostors, tmp_path, capsys):
    """`report`: one prestress case (designed), no printed columns, no notes, no deployment."""
    out = tmp_path / "r"
    r, text = run(["report", str(impostors[which]), "--out", str(out), "--mesh", "4", "--modes", "6",
                   "--t-end", "0.1", "--no-render"], capsys)
    assert r["implied_prestress"] is None and r["printed_frequencies_hz"] is None
    assert r["deployment"] is None and r["notes"] == []
    assert set(r["frequencies_hz"]) == {"MTC designed", "SBC designed", "COM designed"}
    index = (out / "index.md").read_text()
    assert "printed [Hz]" not in index and "Why ours and the printed" not in index
    assert_no_dissertation(text.replace('"implied_prestress": null', "") + index)


@pytest.mark.slow
def test_hinf_of_a_deployable_named_like_a_preset_uses_its_own_scales(impostors, capsys):
    """`control hinf` on a 1-5(D) named '1-4D': no printed f_max, alpha_1 and u_m from the
    system's own scales (0.1 x 2 pi f_1 and 0.5 % of the bar length), not 7.4's 0.5 and 0.01."""
    r, out = run(["control", "hinf", str(impostors[2])], capsys)
    assert r["open_loop_f_max_printed_hz"] is None
    assert r["u_m"] == pytest.approx(0.005 * 2.2)
    pbh, _ = run(["control", "pbh", str(impostors[2])], capsys)
    assert pbh["open_loop_f_max_printed_hz"] is None and pbh["pbh"]["controllable"]
    assert r["alpha"] != 0.5 and r["closed_loop_max_real_part"] < -r["alpha"]
    assert_no_dissertation(out)


@pytest.mark.parametrize("file, modes", [("triangle-1-3.toml", 6),
                                         pytest.param("pentagon-1-5.toml", 12, marks=pytest.mark.slow),
                                         pytest.param("square-2-4.toml", 12, marks=pytest.mark.slow),
                                         pytest.param("kapton-1-4.toml", 12, marks=pytest.mark.slow)])
def test_user_system_modes_and_design(file, modes, capsys):
    """`equilibrium` and `modal` (MTC, COM) on each user system, rc 0, finite positive
    frequencies, the MTC's two lowest beside the COM's within 10 % (both models of the same
    structure; 6.4 finds < 3 % for 1-4 with its K; the 2-4's COM is 6 % below whatever K)."""
    f = str(SYSTEMS / file)
    d, _ = run(["equilibrium", f], capsys)
    assert d["ok"]
    mtc, _ = run(["modal", f, "--model", "mtc", "--modes", "4"], capsys)
    com, out = run(["modal", f, "--model", "com", "--modes", str(min(modes, 6))], capsys)
    assert np.all(np.asarray(mtc["freq_hz"]) > 0)
    assert com["freq_hz"][:2] == pytest.approx(mtc["freq_hz"][:2], rel=0.10)
    assert_no_dissertation(out)


@pytest.mark.slow
def test_deploy_of_a_user_1_5d_tracks_and_switches(tmp_path, capsys):
    """`deploy FILE`: the 1-5(D) from its packaged configuration (its own [packaged] table) to
    the deployed one: tracking error small at the end, the switch to the H-infinity controller
    taken, no slack tendon, rest lengths within limits."""
    r, out = run(["deploy", str(SYSTEMS / "pentagon-1-5D.toml"), "--t-end", "16",
                  "--csv", str(tmp_path / "d.csv")], capsys)
    assert r["switch_time_s"] is not None and r["final_tracking_error"] < 1e-3
    assert r["failure"] is None and r["min_rest_length_margin_m"] > 0
    assert r["pfl_gains"] == [4.0, 10.0, 20.0, 0.9]
    assert_no_dissertation(out)


@pytest.mark.slow
def test_deploy_of_a_user_2_5_on_the_automatic_path(tmp_path, capsys):
    """`deploy FILE` of a two-stage five-bar system (its own [packaged] and [deployment]; no
    path declared: the automatic path of M >= 2 systems, which corrects the stage-2 base where
    the straight line slackens P2), coarse step: the path checked at 101 points with a positive
    margin, the switch to the H-infinity controller taken (eq. 5.70, R_c = 0.01, after the
    reference of eq. 5.68 with omega_r = 0.5 rad/s has settled to 1 %: (1 + w t) exp(-w t) < 0.01
    needs t > 13.3 s), the tracking error below R_c at the end, no slack tendon (tendon forces
    > 0 in the CSV) and every rest length inside [r_min, |tendon|]."""
    import csv
    r, out = run(["deploy", str(SYSTEMS / "pentagon-2-5.toml"), "--t-end", "20", "--dt", "0.02",
                  "--csv", str(tmp_path / "d.csv")], capsys)
    from tests.cli.test_cli_units import _unitless_numbers
    assert _unitless_numbers({k: v for k, v in r.items() if k != "units"}) == []
    assert r["path"] == "auto" and r["path_check"]["points_checked"] == 101
    assert r["path_check"]["min_margin"] > 0 and r["path_check"]["optimizer_evaluations"] > 0
    assert r["switch_time_s"] is not None and 13.3 < r["switch_time_s"] < 20
    assert r["final_tracking_error"] < 0.01 and r["failure"] is None
    assert r["min_rest_length_margin_m"] > 0
    # strength: the tendons' transient stays below the file's yield stress (450 MPa), the bars
    # below their Euler load (eq. 5.31): no failed check
    assert r["max_tendon_stress_Pa"] < 450e6 and r["peak_bar_compression_N"] < r["bar_critical_load_N"]
    assert r["failed_checks"] == []
    with open(tmp_path / "d.csv") as fh:
        rows = list(csv.reader(fh))
    head, data = rows[0], np.array([[float(v) for v in row[:-1]] for row in rows[1:]])
    T = data[:, [k for k, h in enumerate(head) if h.startswith("T_")]]
    u = data[:, [k for k, h in enumerate(head) if h.startswith("r_")]]
    assert T.shape[1] == u.shape[1] == 35 and T.min() > 0 and u.min() >= 1e-3
    assert_no_dissertation(out)


@pytest.mark.slow
def test_deploy_refuses_a_2_5_without_a_path_naming_the_obstacle(tmp_path, capsys):
    """The 2-5 packaged at theta = 78 deg, psi = 28 deg with its stage-2 base at sigma_2 =
    -60 deg (a feasible equilibrium, checked before the path): no path through the symmetric
    equilibria is found, so `deploy` stops before any controller design with an error naming
    the progress, the angles and the slack tendon group (InfeasibleDesign, exit 1)."""
    text = (SYSTEMS / "pentagon-2-5.toml").read_text()
    text = text.replace("psi_deg = [20.0, 20.0], sigma_deg = [0.0, 0.0], z = [0.0, 0.153], r = [0.9, 1.3286]",
                        "psi_deg = [28.0, -32.0], sigma_deg = [0.0, -60.0], z = [0.0, 0.257], r = [0.9, 0.9573]")
    f = tmp_path / "no-path.toml"
    f.write_text(text)
    assert main(["deploy", str(f), "--t-end", "1"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert [e for e in err if "error" in e] == err[-1:]        # before it: the search's log line
    err = err[-1]
    assert "no path through the symmetric equilibria" in err
    assert re.search(r"fails at s = [0-9.]+ \(theta = \[[0-9., ]+\] deg, psi = \[[-0-9., ]+\] deg\): "
                     r"no positive null vector of 3.3.2: force sign of .*P2", err), err


@pytest.mark.slow
def test_deploy_of_an_over_actuated_3_3_tracks_and_switches_with_every_tendon_taut(tmp_path, capsys):
    """`deploy FILE` of the three-stage 3-3 (13 N = 39 tendons for 12 N = 36 bar coordinates,
    eqs. 3.1-3.2: a wide B_q of eq. 5.46) on its automatic path, coarse step: B_q of full row
    rank all along (its condition number finite), the PFL tracking to the switch to the
    H-infinity controller (eq. 5.70, R_c = 0.01, after the reference of eq. 5.68 with omega_r =
    0.5 rad/s has settled to 1 %: t > 13.3 s), the error below R_c at the end, every tendon in
    tension (forces > 0 in the CSV: the extra tendons keep half the path's elongation), every
    rest length inside [r_min, |tendon|) and no failed strength check."""
    import csv
    r, out = run(["deploy", str(SYSTEMS / "tower-3-3.toml"), "--t-end", "20", "--dt", "0.02",
                  "--csv", str(tmp_path / "d.csv")], capsys)
    assert r["path"] == "auto" and r["path_check"]["min_margin"] > 0
    assert 1 <= r["B_q_condition_max"] < 1e10
    assert r["switch_time_s"] is not None and 13.3 < r["switch_time_s"] < 20
    assert r["final_tracking_error"] < 0.01 and r["failure"] is None
    assert r["min_rest_length_margin_m"] > 0
    assert r["peak_bar_compression_N"] < r["bar_critical_load_N"] and r["failed_checks"] == []
    with open(tmp_path / "d.csv") as fh:
        rows = list(csv.reader(fh))
    head, data = rows[0], np.array([[float(v) for v in row[:-1]] for row in rows[1:]])
    cols = {p: [k for k, h in enumerate(head) if h.startswith(p)] for p in ("T_", "r_", "L_")}
    T, u, L = (data[:, cols[p]] for p in ("T_", "r_", "L_"))
    assert T.shape[1] == u.shape[1] == 39 and T.min() > 0
    assert u.min() >= 1e-3 and np.all(u < L)
    assert_no_dissertation(out)


def test_deploy_refuses_a_file_without_a_packaged_configuration(capsys):
    rc = main(["deploy", str(SYSTEMS / "pentagon-1-5.toml")])
    err = capsys.readouterr().err
    assert rc != 0 and "[packaged]" in err and "[deployment]" in err


def test_report_of_a_1_3_takes_the_modes_its_com_has(tmp_path, capsys):
    """`report` on the 1-3 with `[models.com] membrane_modes = 4`: its COM has n_q + K = 6 + 4
    coordinates, so the default 12 modes become 10 (said on stderr), rc 0."""
    import tomllib
    d = tomllib.loads((SYSTEMS / "triangle-1-3.toml").read_text())
    f = tmp_path / "k4.toml"
    f.write_bytes(tomli_w.dumps({**d, "models": {"com": {"membrane_modes": 4}}}).encode())
    rc = main(["report", str(f), "--out", str(tmp_path / "r"),
               "--mesh", "4", "--t-end", "0.1", "--no-render", "--json"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    r = json.loads(out)
    assert r["modes"] == 10 and "10 coordinates" in err
    assert all(len(f) == 10 for f in r["frequencies_hz"].values())
    # the COM's membrane on the report's mesh, as the FE models': their lowest (bar) mode agrees
    # (the point-attached corners make every model's frequencies depend on the mesh)
    f = r["frequencies_hz"]
    assert f["COM designed"][0] == pytest.approx(f["MTC designed"][0], rel=0.02)
    # a system without printed values: its tables have no printed and no rel. diff columns
    # (the input r_1 named in the source of the eq. 3.33 row, not put in a printed column)
    for name in ("equilibrium.csv", "statics.csv"):
        head = (tmp_path / "r" / name).read_text().splitlines()[0]
        assert "printed" not in head and "rel_diff" not in head, (name, head)
    md = (tmp_path / "r" / "equilibrium.md").read_text()
    assert "| quantity | unit | value | source |" in md and "carries no printed values" in md
    assert "eq. 3.33 (input r_1 = " in md and "printed column" not in md


@pytest.mark.slow
def test_report_of_a_deployable_uses_sbc_com_and_its_own_deployment(tmp_path, capsys):
    """`report` on the 1-5(D): the SBC model in place of the MTC (no H_1j nodes), the COM, and
    the system's own deployment ([packaged], [deployment]), shortened here."""
    from tmfem.reference import report as rep
    with pytest.MonkeyPatch.context() as mp:
        own = rep.report_deployment
        mp.setattr(rep, "report_deployment",
                   lambda s: {**own(s), "t_end": 0.3, "controller": "adaptive-lqr"})
        r, text = run(["report", str(SYSTEMS / "pentagon-1-5D.toml"), "--out", str(tmp_path / "r"),
                       "--mesh", "4", "--modes", "6", "--t-end", "0.1", "--no-render"], capsys)
    assert r["fe_model"] == "SBC" and set(r["vibration"]) == {"COM", "SBC"}
    assert set(r["frequencies_hz"]) == {"SBC designed", "COM designed"}
    # the SBC and the COM of the same structure: lowest mode within 5 % (0.713 / 0.718 Hz)
    f = r["frequencies_hz"]
    assert f["COM designed"][0] == pytest.approx(f["SBC designed"][0], rel=0.05)
    assert r["deployment"]["system"] == "pentagon-D" and r["deployment"]["failure"] is None
    index = (tmp_path / "r" / "index.md").read_text()
    assert "shell-beam-cable model (6.2)" in index
    # no placeholder for the files the SBC model does not write, the tendon shown named as it is
    assert ", -" not in index and "| rest length SL_1 " in index and "S_11" not in index
    assert_no_dissertation(text.replace('"implied_prestress": null', "") + index)


@pytest.mark.slow
def test_report_with_a_failed_check_does_not_say_passed(tmp_path, capsys):
    """The 1-5 with a tendon yield stress of 1 MPa (its design stresses the tendons to ~52 MPa):
    the FE statics' yield check fails, so the report lists it, exits 1 and never says
    'passed'."""
    import tomllib
    d = tomllib.loads((SYSTEMS / "pentagon-1-5.toml").read_text())
    d["tendons"]["S"]["yield_stress"] = 1e6
    f = tmp_path / "weak.toml"
    f.write_bytes(tomli_w.dumps(d).encode())
    rc = main(["report", str(f), "--out", str(tmp_path / "r"), "--mesh", "4", "--modes", "4",
               "--t-end", "0.1", "--no-render"])
    out, err = capsys.readouterr()
    assert rc == 1
    assert "checks FAILED" in out and "MTC designed: tendon stress <= yield" in out
    assert "passed" not in out and "all passed" not in (tmp_path / "r" / "index.md").read_text()


@pytest.mark.parametrize("freqs, unstable", [
    ({"SBC implied": [-85.0, 0.3, 1.2]}, {"SBC implied": [1]}),
    ({"MTC designed": [0.1, 0.3]}, {}),
])
def test_an_unstable_mode_is_named_not_printed_as_a_frequency(freqs, unstable):
    """omega^2 < 0 (eq. 5.32, a signed frequency < 0): the mode is listed as unstable and its
    table cell reads 'unstable'."""
    from tmfem.reference.report import frequency_cell, unstable_modes
    assert unstable_modes(freqs) == unstable
    cells = [frequency_cell(f) for v in freqs.values() for f in v]
    assert ("unstable" in cells) == bool(unstable) and not any(c.startswith("-") for c in cells)


def test_com_disagreement_names_the_modes():
    """The report's warning when the COM leaves the FE model by more than 5 % (6.4: < 3 % for
    1-4): the modes named, K in the message; none when they agree."""
    from tmfem.reference.report import com_disagreement
    freqs = {"MTC designed": np.array([0.47, 3.51, 5.45]), "COM designed": np.array([0.46, 3.47, 7.34])}
    d = com_disagreement(freqs, "MTC", 4)
    assert d["modes"] == [3] and "K = 4" in d["message"]
    assert com_disagreement({k: v[:2] for k, v in freqs.items()}, "MTC", 4) is None


@pytest.mark.parametrize("file", ["triangle-1-3.toml",
                                  pytest.param("square-2-4.toml", marks=pytest.mark.slow)])
def test_compare_of_user_systems_sets_the_three_models_side_by_side(file, tmp_path, capsys):
    """`compare FILE`: the SBC, MTC and COM frequencies of a user system with their differences
    to the SBC model, no printed columns; the two FE models agree within 1 % in the lowest mode
    (6.4.2's bound for 2-3), the COM within 10 % (the 2-4's COM is 4-7 % below its FE models
    whatever K: its tendons are strained by percents, where the COM's linear springs of eqs.
    3.8-3.9 are softer than the FE models' Green-Lagrange trusses,
    tests/models/com/test_com_tendon_strain.py)."""
    r, out = run(["compare", str(SYSTEMS / file), "--modes", "4", "--mesh", "6",
                  "--csv", str(tmp_path / "c.csv"), "--plot", str(tmp_path / "c.png")], capsys)
    assert r["printed"] is None and r["stated"] is None
    assert r["models"] == ["SBC", "MTC", "COM"] and r["left_out"] == {}
    assert abs(r["vs_SBC"]["ours"]["MTC"][0]) < 0.01 and abs(r["vs_SBC"]["ours"]["COM"][0]) < 0.10
    assert (tmp_path / "c.csv").read_text().startswith("mode,SBC_ours_hz")
    assert (tmp_path / "c.png").stat().st_size > 10_000     # the three models, no printed markers
    assert_no_dissertation(out)


def test_compare_plot_without_printed_values_draws_the_three_models_only(tmp_path):
    """The figure of a system without printed frequencies: one line per model in the top
    panel, the MTC and COM differences to the SBC model in the bottom one, no printed markers
    and no stated bound."""
    from tmfem.post.compare import plot_model_frequencies
    ours = {"SBC": [1.0, 2.0], "MTC": [1.01, 2.1], "COM": [0.99, 2.05]}
    r = {"system": "mine", "ours": ours, "printed": None, "stated_bound": None, "stated": None,
         "source": None, "vs_SBC": {"ours": {m: [a / b - 1 for a, b in zip(ours[m], ours["SBC"])]
                                             for m in ("MTC", "COM")}}}
    png = plot_model_frequencies(tmp_path / "f.png", r)
    assert png.stat().st_size > 10_000


@pytest.mark.slow
def test_compare_of_a_deployable_user_system_sets_the_sbc_and_com_models_side_by_side(tmp_path, capsys):
    """`compare FILE` on the 1-5(D) (tendons at H_1j along the bars, which the MTC model cannot
    represent): rc 0, the SBC and COM models only, a line saying why the MTC model is left out,
    the SBC-COM pairs by shape, and no MTC column in the text, the CSV or the JSON. Each model's
    frequencies are the ones `modal --model sbc|com` computes on its own at the same mesh; the
    pentagon's SBC and COM modes 1-6 have the same shapes in order (MAC > 0.99, the degenerate
    pairs 2-3 and 5-6 compared by their spans), so the paired differences are those by order."""
    file = str(SYSTEMS / "pentagon-1-5D.toml")
    csv_path, png = tmp_path / "c.csv", tmp_path / "c.png"
    r, out = run(["compare", file, "--modes", "6", "--mesh", "6", "--csv", str(csv_path), "--plot", str(png)],
                 capsys)
    assert r["models"] == ["SBC", "COM"] and list(r["left_out"]) == ["MTC"] and "1-N(D)" in r["left_out"]["MTC"]
    assert set(r["ours"]) == {"SBC", "COM"} and set(r["vs_SBC"]["ours"]) == {"COM"}
    assert "MTC" not in r["mode_pairs"] and "MTC" not in r["max_abs_vs_SBC"]["paired"]
    for model in ("sbc", "com"):
        alone, _ = run(["modal", file, "--model", model, "--mesh", "6", "--modes", "6"], capsys)
        np.testing.assert_allclose(r["ours"][model.upper()], alone["freq_hz"], rtol=1e-8)
    pairs = r["mode_pairs"]["COM"]
    assert pairs["mode"] == [1, 2, 3, 4, 5, 6] and min(pairs["mac"]) > 0.99 and pairs["identity"]
    np.testing.assert_allclose(pairs["vs_SBC"], r["vs_SBC"]["ours"]["COM"], rtol=1e-12)
    header = csv_path.read_text().splitlines()[0]
    assert header == ("mode,SBC_ours_hz,COM_ours_hz,COM_vs_SBC,COM_paired_mode,COM_mac,COM_paired_hz,"
                      "COM_paired_vs_SBC")
    assert png.stat().st_size > 10_000
    assert main(["compare", file, "--modes", "6", "--mesh", "6"]) == 0
    text = capsys.readouterr().out
    assert "pentagon-D: SBC and COM natural frequencies" in text
    assert "MTC model left out: the MTC model cannot represent a 1-N(D) system" in text
    assert "MTC ours" not in text and "nan" not in text.lower()
    assert_no_dissertation(out)


def test_compare_vibrate_refuses_a_deployable_and_says_why(capsys):
    """The free vibration compares all three models: a 1-N(D) system is refused with the reason
    and the command that compares the models that apply."""
    assert main(["compare", str(SYSTEMS / "pentagon-1-5D.toml"), "--vibrate"]) == 2
    err = capsys.readouterr().err
    assert "MTC model cannot represent a 1-N(D) system" in err and "without --vibrate" in err


def test_converge_sbc_of_a_deployable_user_system(capsys):
    """`converge --model sbc` on the 1-5(D) (the MTC model cannot represent it, the SBC model
    can): rc 0, the lowest frequency settles with the mesh (n = 2 -> 4 within 1 %)."""
    r, _ = run(["converge", str(SYSTEMS / "pentagon-1-5D.toml"), "--model", "sbc", "--mesh", "2,4",
                "--modes", "3"], capsys)
    f1 = [row["f1"] for row in r["rows"]]
    assert f1[1] == pytest.approx(f1[0], rel=0.01)
    from tmfem.cli.converge import format_text
    header = format_text(r).splitlines()[2].split()     # every column with its unit
    assert header[-6:] == ["f1", "Hz", "f2", "Hz", "f3", "Hz"]


def test_report_values_that_could_not_be_computed_are_absent_not_nan():
    from tmfem.reference.report import finite_or_none
    assert finite_or_none({"a": [1.0, float("nan")], "b": np.inf, "c": (2, np.float64("nan"))}) == \
        {"a": [1.0, None], "b": None, "c": [2, None]}


def test_vibrate_without_perturb_starts_from_the_files_perturbation(capsys):
    """`vibrate FILE` without --perturb: the default theta_11_dot = 0.01 rad/s (a run from the
    equilibrium itself would stay there): the symmetric equilibrium (all theta_1j equal, eq.
    3.19) is left, theta_11 and theta_12 differ at the end."""
    r, _ = run(["vibrate", str(SYSTEMS / "triangle-1-3.toml"), "--t-end", "0.5"], capsys)
    assert r["perturbation"] == {"theta_11_dot": 0.01}
    assert abs(r["final"]["theta_11"] - r["final"]["theta_12"]) > 1e-4


@pytest.mark.parametrize("model", ["mtc", "sbc"])
def test_static_text_of_a_user_system_has_units_and_no_printed_column(model, capsys):
    """`static FILE` (text): the results table has the model's column only (the file has no
    `[printed]`), and every check states its values with their unit (stresses in MPa, the
    yield stresses of the file: 61 MPa membrane, 94.8 MPa tendons; loads in N)."""
    assert main(["static", str(SYSTEMS / "pentagon-1-5D.toml" if model == "sbc" else SYSTEMS / "pentagon-1-5.toml"),
                 "--model", model, "--mesh", "4", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert_no_dissertation(out)
    header = next(line for line in out.splitlines() if line.strip() == model.upper())
    assert "printed" not in header
    checks = [line for line in out.splitlines() if line.startswith("check ")]
    assert checks and all(re.search(r"\(\S+ (MPa|N|slack tendons) vs \S+ (MPa|N|slack tendons),", c)
                          for c in checks), checks
    if model == "sbc":
        assert any("vs 61 MPa" in c for c in checks) and any("vs 94.8 MPa" in c for c in checks)


@pytest.mark.slow
def test_report_of_a_deployable_system_whose_switch_cannot_be_designed(tmp_path, capsys):
    """A 1-4(D) whose COM (K = 4) has a membrane mode that no tendon reaches (PBH margin 0,
    eq. 5.71): the deployment's H-infinity switch cannot be designed, and the report still
    writes every other section, says in section 5 why there is no deployment, and exits 1
    with the deployment among the failed checks (never "checks passed")."""
    out = tmp_path / "rep"
    rc = main(["report", str(SYSTEMS / "square-1-4D.toml"), "--out", str(out), "--mesh", "4",
               "--t-end", "0.5", "--no-render", "--quiet"])
    text = capsys.readouterr().out
    assert rc == 1
    assert "checks FAILED: deployment not run" in text and "not reached by any tendon" in text
    r = json.loads((out / "report.json").read_text())
    assert r["failed_checks"] == ["deployment not run"] and "4.276 Hz" in r["deployment"]["not_run"]
    assert "--exclude-uncontrollable" in r["deployment"]["not_run"]
    assert 'uncontrollable = "exclude"' in r["deployment"]["not_run"]
    index = (out / "index.md").read_text()
    assert "was not run: " in index.split("## 5. Deployment")[1]
    assert (out / "vibration_sbc.png").exists() and not (out / "INCOMPLETE").exists()
    assert_no_dissertation(text)


def test_sbc_static_says_when_the_bars_bending_takes_the_membrane_prestress(capsys):
    """The 1-4(D) at 3 m: its bars bend by about 1 mm at H_1j, and the SBC model's membrane
    keeps about a third of the design's corner displacement (1 mm). The JSON gives both Delta,
    the design's equal to eq. 3.22 of the file, and the text says what it means."""
    from tmfem.equilibrium.symmetric import membrane_delta_system
    from tmfem.system import load_system
    f = SYSTEMS / "square-1-4D.toml"
    r, _ = run(["static", str(f), "--model", "sbc", "--mesh", "4", "--quiet"], capsys)
    assert r["Delta_design_mean"] == pytest.approx(membrane_delta_system(load_system(f)), rel=1e-9)
    assert 0 < r["Delta_mean"] < 0.5 * r["Delta_design_mean"] and min(r["bar_bow"]) > 5e-4
    assert main(["static", str(f), "--model", "sbc", "--mesh", "4", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"note: the membrane keeps \d+ % of the design's corner displacement", out)
    assert main(["static", str(SYSTEMS / "pentagon-1-5D.toml"), "--model", "sbc", "--mesh", "4", "--quiet"]) == 0
    assert "note: the membrane keeps" not in capsys.readouterr().out
