"""`tmfem mesh`, `tmfem export`, the reference meshes in meshes/ and the membrane field."""
import json
from pathlib import Path

import meshio            # a declared dependency (pyproject.toml): a missing one must fail, not skip
import numpy as np
import pytest

from tmfem.cli import main
from tmfem.errors import InputError
from tmfem.io.msh import read_membrane_mesh, write_membrane_mesh
from tmfem.system import beta, load_preset

MESHES = Path(__file__).resolve().parents[2] / "meshes"


def _line_data(m):
    """Line cells (bars, then tendons) and their cell data, concatenated over blocks."""
    k = [i for i, b in enumerate(m.cells) if b.type == "line"]
    return (np.concatenate([m.cells[i].data for i in k]),
            {name: np.concatenate([v[i] for i in k]) for name, v in m.cell_data.items()})


@pytest.mark.parametrize("name, args, N, r_mb", [
    ("square_4x10x10.msh", ["--preset", "1-4"], 4, 1.4142),       # 6.2.1
    ("triangle_3x10x10.msh", ["--preset", "2-3", "--as-printed"], 3, 1.87),  # Table 6.4
    ("hexagon_6x10x10.msh", ["--polygon", "6", "--r-mb", "2"], 6, 2.0),   # 7.3.2
])
def test_reference_meshes_regenerate(tmp_path, capsys, name, args, N, r_mb):
    out = tmp_path / name
    assert main(["mesh", *args, "--n", "10", str(out), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["elements"] == N * 100 and r["nodes"] == N * 100 + N * 10 + 1
    new, ref = read_membrane_mesh(out), read_membrane_mesh(MESHES / name)
    np.testing.assert_allclose(new.p, ref.p, atol=1e-12)
    np.testing.assert_array_equal(new.t, ref.t)
    np.testing.assert_array_equal(new.corners, ref.corners)
    assert ref.n == 10
    # the corners are the regular N-gon of circumradius r_mb: edge 2 r_mb sin(pi/N)
    c = ref.p[:, ref.corners]
    edges = np.linalg.norm(np.roll(c, -1, axis=1) - c, axis=0)
    np.testing.assert_allclose(edges, 2 * r_mb * np.sin(np.pi / N), rtol=1e-12)
    np.testing.assert_allclose(c[:, -1], 0.0, atol=1e-12)          # O_f at corner N
    np.testing.assert_allclose(c[1, 0], 0.0, atol=1e-12)           # x_f through corner 1


def test_mesh_file_round_trip_and_errors(tmp_path):
    ref = read_membrane_mesh(MESHES / "triangle_3x10x10.msh")
    for suffix in (".vtu", ".msh"):
        back = read_membrane_mesh(write_membrane_mesh(tmp_path / f"t{suffix}", ref))
        np.testing.assert_allclose(back.p, ref.p)
        np.testing.assert_array_equal(back.t, ref.t)
        np.testing.assert_array_equal(back.corners, ref.corners)
    with pytest.raises(InputError, match="does not exist"):
        read_membrane_mesh(tmp_path / "missing.msh")
    (tmp_path / "bad.msh").write_text("not a mesh")
    with pytest.raises(InputError, match="cannot read"):
        read_membrane_mesh(tmp_path / "bad.msh")


def test_mesh_cli_errors(tmp_path, capsys):
    assert main(["mesh", "--polygon", "6", str(tmp_path / "h.msh")]) == 2
    assert "needs --r-mb > 0" in capsys.readouterr().err
    assert main(["mesh", "--preset", "1-4", str(tmp_path / "h.stl")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "expected a suffix in ['.msh', '.vtu', '.xdmf']" in err


def test_export_cli(tmp_path, capsys):
    out, png = tmp_path / "e" / "c.vtu", tmp_path / "c.png"
    assert main(["export", "--preset", "2-3", str(out), "--png", str(png), "--mesh", "4",
                 "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    s = load_preset("2-3")
    # symmetric system: every corner moves radially by Delta of eq. 3.22
    Delta = s.symmetric.membrane_delta(s.N, s.r_mb)
    np.testing.assert_allclose(r["corner_radial_displacement"], Delta, rtol=1e-9)
    assert (Delta <= 0) == any("not stretched" in w for w in r["warnings"])
    m = meshio.read(out)
    assert m.points.shape[0] == 12 + (3 * 16 + 3 * 4 + 1)             # nodes + 3x4x4 mesh
    assert sum(b.data.shape[0] for b in m.cells if b.type == "quad") == 48
    assert png.stat().st_size > 10_000
    # the 2-3 preset is a feasible design (Delta = 1 mm, Table 7.7 rule): the file carries the
    # design forces, and its rest lengths obey eqs. 3.8-3.9 with the file's own lengths
    assert r["forces_from"] == "design_equilibrium" and r["warnings"] == []
    _, d = _line_data(m)
    T, L, rest = d["axial_force"][6:], d["length"][6:], d["rest_length"][6:]
    np.testing.assert_allclose(T, list(r["tendon_forces"].values()))
    assert np.all(T > 0)
    np.testing.assert_allclose(rest, s.tendon_EA * L / (T + s.tendon_EA), rtol=1e-12)
    # --as-printed carries the rest lengths printed in Table 6.4
    assert main(["export", "--preset", "2-3", "--as-printed", str(tmp_path / "a.vtu"),
                 "--mesh", "0", "--no-equilibrium"]) == 0
    m = meshio.read(tmp_path / "a.vtu")
    rest = np.concatenate([m.cell_data["rest_length"][k] for k, b in enumerate(m.cells)
                           if b.type == "line"])[6:]
    table_6_4 = {"S1": 1.9425, "V2": 1.9953, "D2": 2.1424, "C2": 0.8204, "R2": 0.8042,
                 "P2": 2.0176, "S2": 2.0939}
    np.testing.assert_allclose(rest, [table_6_4[t.group] for t in s.tendons])
    assert main(["export", "--preset", "1-4", str(tmp_path / "p.vtu"), "--mesh", "0"]) == 0
    m = meshio.read(tmp_path / "p.vtu")
    assert [b.type for b in m.cells] == ["line", "polygon"] and m.points.shape == (8, 3)
    capsys.readouterr()
    assert main(["export", "--preset", "1-4", str(tmp_path / "p.obj")]) == 2
    assert "expected a suffix" in capsys.readouterr().err


def test_membrane_design_field_lands_on_the_bar_tops():
    from tmfem.post.fields import corner_radial_displacements, membrane_design_field

    s = load_preset("1-4")
    mf = membrane_design_field(s, n=4)
    B = s.membrane_corners_inertial()
    # the corners are Dirichlet nodes of the plane-stress problem: exactly on B_1j
    np.testing.assert_allclose(mf.x[:, mf.mesh.corners], B, atol=1e-12)
    # displacement from the undeformed membrane placed in O_f (corner N fixed): corner j
    # moves by Delta (e_j - e_N), e_j = (cos beta_j, sin beta_j) (eqs. 3.21, 3.22)
    u = mf.point_data["displacement_Of"].T     # one field name in every output (was "displacement")
    b = beta(s.N)
    e = np.array([np.cos(b), np.sin(b)])
    Delta = s.symmetric.membrane_delta(s.N, s.r_mb)
    np.testing.assert_allclose(np.linalg.norm(u[:, mf.mesh.corners], axis=0),
                               Delta * np.linalg.norm(e - e[:, [-1]], axis=0), atol=1e-12)
    # stretched membrane (Delta > 0): tension everywhere on average
    assert np.all(corner_radial_displacements(s) > 0)
    assert mf.cell_data["sigma_p1"].min() > 0


def test_export_writes_the_equilibrium_design(tmp_path, capsys):
    assert main(["export", "--preset", "1-4", str(tmp_path / "d.vtu"), "--mesh", "4",
                 "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["forces_from"] == "design_equilibrium" and r["warnings"] == []
    _, d = _line_data(meshio.read(tmp_path / "d.vtu"))
    T, L, r0 = d["axial_force"][4:], d["length"][4:], d["rest_length"][4:]
    np.testing.assert_allclose(T, list(r["tendon_forces"].values()))
    assert np.all(T > 0) and np.all(d["slack"][4:] == 0)
    s = load_preset("1-4")
    EA = s.tendon_EA
    np.testing.assert_allclose(r0, EA * L / (T + EA), rtol=1e-12)          # eq. 3.9
    np.testing.assert_allclose(T, T[0], rtol=1e-9)                          # symmetric design
    assert np.all(d["axial_force"][:4] < 0)                                 # bars compressed


def test_export_from_a_system_file(tmp_path, capsys):
    from tmfem.system import dump_system

    s = load_preset("1-4")
    dump_system(s, tmp_path / "s.toml")
    assert main(["export", str(tmp_path / "s.toml"), str(tmp_path / "s.vtu"), "--mesh", "2",
                 "--no-equilibrium", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["system"] == "1-4" and r["membrane_elements"] == 4 * 2 * 2
    m = meshio.read(tmp_path / "s.vtu")
    np.testing.assert_allclose(m.points[:8], s.nodes().T, atol=1e-12)
