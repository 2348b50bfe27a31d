"""`tmfem equilibrium` and `tmfem study` in-process: output, exit codes, one-line errors."""
import csv
import json
import tomllib

import numpy as np
import pytest

from tmfem.cli import main
from tmfem.equilibrium.design import design_equilibrium
from tmfem.system import load_preset
from tmfem.system.presets import preset_dict

import tomli_w


def run(argv, capsys):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def write_variant(tmp_path, name, preset, **sym):
    d = preset_dict(preset)
    d.pop("rest_lengths", None)
    d["symmetric"].update(sym)
    p = tmp_path / f"{name}.toml"
    p.write_bytes(tomli_w.dumps(d).encode())
    return str(p)


def test_equilibrium_json_matches_design(capsys):
    rc, out, err = run(["equilibrium", "--preset", "1-4", "--json", "--mesh", "4"], capsys)
    assert rc == 0 and err == ""
    r = json.loads(out)
    d = design_equilibrium(load_preset("1-4"), mesh_n=4)
    assert r["ok"] and r["Delta"] == pytest.approx(d.Delta)
    np.testing.assert_allclose([t["force"] for t in r["tendons"]], d.tendon_forces)
    np.testing.assert_allclose([t["rest_length"] for t in r["tendons"]], d.rest_lengths)
    assert set(r["nodes"]) == set(load_preset("1-4").node_labels)
    assert {c["name"] for c in r["checks"]} >= {"membrane stretched", "tendons taut",
                                                "equilibrium residual", "bar buckling"}


def test_equilibrium_text_as_printed_shows_given_rest_lengths(capsys):
    rc, out, _ = run(["equilibrium", "--preset", "1-4", "--as-printed", "--mesh", "4"], capsys)
    assert rc == 0
    assert "given rest" in out and "1.52900" in out       # Table 6.2 r_1^S
    assert "[ok] bar buckling" in out


def one_error_line(err):
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    return lines[0]


def test_slack_membrane(tmp_path, capsys):
    f = write_variant(tmp_path, "slack_membrane", "1-4")
    d = tomllib.loads(open(f).read())
    d["membrane"]["r_mb"] = 2.0          # Delta of eq. 3.22 < 0
    open(f, "wb").write(tomli_w.dumps(d).encode())
    rc, out, err = run(["equilibrium", f, "--mesh", "4"], capsys)
    line = one_error_line(err)
    assert rc == 1 and out == ""
    assert "membrane stretched" in line and "Delta = -" in line


def test_slack_tendon(tmp_path, capsys):
    # a 2-3 configuration with Delta > 0 whose null vector (3.3.2) has negative entries
    f = write_variant(tmp_path, "slack_tendon", "2-3", psi_deg=[20.0, 120.0],
                      sigma_deg=[0.0, 100.0], z=[0.0, 0.6001], r=[0.7, 0.2798])
    rc, _, err = run(["equilibrium", f, "--mesh", "4"], capsys)
    line = one_error_line(err)
    assert rc == 1 and "tendons taut" in line and "slack)" in line


def test_violated_equilibrium_condition(tmp_path, capsys):
    f = write_variant(tmp_path, "r1", "1-4", r=[0.40])     # eq. 3.33 needs 0.42854 m
    rc, _, err = run(["equilibrium", f, "--mesh", "4"], capsys)
    line = one_error_line(err)
    assert rc == 1 and "equilibrium residual" in line and "eq. 3.33" in line
    # --allow-infeasible prints the design and its failed checks instead
    rc, out, _ = run(["equilibrium", f, "--mesh", "4", "--allow-infeasible"], capsys)
    assert rc == 0 and "[FAIL] equilibrium residual" in out


def test_malformed_toml_and_negative_lengths(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("name = '1-4'\nN = 4\n[symmetric\n")
    rc, _, err = run(["equilibrium", str(bad)], capsys)
    assert rc == 2 and "bad.toml" in one_error_line(err)
    f = write_variant(tmp_path, "neg", "1-4", l=[-2.015])
    rc, _, err = run(["equilibrium", f], capsys)
    assert rc == 2 and "l" in one_error_line(err) and "-2.015" in err
    rc, _, err = run(["equilibrium", "--preset", "1-4", "--mesh", "0"], capsys)
    assert rc == 2 and "--mesh" in one_error_line(err)


def test_study_writes_table_plots_and_vtk(tmp_path, capsys):
    out = tmp_path / "study"
    rc, text, err = run(["study", "--preset", "1-4", "--out", str(out), "--mesh", "4",
                         "--no-render"], capsys)
    assert rc == 0, err
    assert "tmfem study: done" in err                       # progress on stderr
    for f in ("equilibrium.csv", "tendons.csv", "equilibrium.md", "configuration.png",
              "membrane_stress.png", "configuration.vtu", "design.json"):
        assert (out / f).stat().st_size > 0, f
    rows = {r["quantity"]: r for r in csv.DictReader(open(out / "equilibrium.csv"))}
    d = design_equilibrium(load_preset("1-4"), mesh_n=4)
    assert float(rows["rest length S1"]["ours"]) == pytest.approx(d.rest_lengths[0], rel=1e-7)
    assert float(rows["rest length S1"]["printed"]) == 1.529      # Table 6.2
    assert float(rows["bar load stage 1 (compression)"]["printed"]) == 14.53   # Table 6.3
    md = (out / "equilibrium.md").read_text()
    assert "| rest length S1 | m |" in md and "## Checks" in md
    import meshio
    m = meshio.read(out / "configuration.vtu")
    # 8 system nodes + the 4 x 4 x 4 membrane mesh (N n^2 + N n + 1 nodes, 6.2), 4 bars +
    # 4 tendons, 64 quads; the tendons carry the design forces
    assert m.points.shape[0] == 8 + 4 * 16 + 4 * 4 + 1
    cells = {b.type: b.data.shape[0] for b in m.cells}
    assert cells == {"line": 8, "quad": 64}
    line = [k for k, b in enumerate(m.cells) if b.type == "line"][0]
    np.testing.assert_allclose(m.cell_data["axial_force"][line][4:], d.tendon_forces, rtol=1e-12)
    tendons = list(csv.DictReader(open(out / "tendons.csv")))
    np.testing.assert_allclose([float(t["force_N"]) for t in tendons], d.tendon_forces, rtol=1e-6)


def test_study_2_3_as_printed_allow_infeasible_writes_map(tmp_path, capsys):
    out = tmp_path / "s23"
    rc, _, err = run(["study", "--preset", "2-3", "--as-printed", "--out", str(out), "--mesh", "3",
                      "--no-render", "--map-grid", "3"], capsys)
    assert rc == 1 and "membrane stretched" in one_error_line(err.splitlines()[-1])
    rc, _, err = run(["study", "--preset", "2-3", "--as-printed", "--out", str(out), "--mesh", "3",
                      "--no-render", "--map-grid", "3", "--allow-infeasible"], capsys)
    assert rc == 0, err
    m = json.loads((out / "equilibrium_map.json").read_text())
    assert np.array(m["feasible"]).shape == (3, 3)
    np.testing.assert_array_equal(m["feasible"], np.array(m["positive"]) & (np.array(m["Delta"]) > 0))
    # Delta of every grid point (eq. 5.97 configuration) against the bar-top geometry
    # (independent of eq. 3.22): circumradius of the corner triangle minus r_mb
    from tmfem.equilibrium.symmetric_map import configuration_5_97, with_configuration
    s = load_preset("2-3", as_printed=True)
    for a, th in enumerate(np.radians(m["theta_deg"])):
        for b, ps in enumerate(np.radians(m["psi_deg"])):
            B = with_configuration(s, configuration_5_97(s, th, ps)).membrane_corners_inertial()
            R = np.linalg.norm(B - B.mean(axis=1, keepdims=True), axis=0)
            assert m["Delta"][a][b] == pytest.approx(R.mean() - s.r_mb, abs=1e-12)
    assert (out / "equilibrium_map.png").stat().st_size > 0
