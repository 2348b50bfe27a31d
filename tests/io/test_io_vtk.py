"""VTK output (tmfem.io): files read back with meshio and with VTK itself (pyvista)."""
import h5py  # noqa: F401  (XDMF: the xdmf extra, installed with dev); meshio and pyvista are dependencies:
import meshio            # a broken install must fail here, not skip
import numpy as np
import pytest
import pyvista as pv

from tmfem.errors import InputError
from tmfem.io import (FAMILY_CODES, KIND_CODES, MembraneField, SeriesWriter, configuration_cells,
                      read_pvd, write_configuration, write_modes, write_series)
from tmfem.mesh import polygon_quad_mesh
from tmfem.post.placement import mean_value_coordinates, membrane_on_configuration
from tmfem.system import load_preset


@pytest.fixture(scope="module")
def sys23():
    return load_preset("2-3")


@pytest.fixture(scope="module")
def sys14():
    return load_preset("1-4")


def _lines(m):
    """All line cells and their cell data, concatenated over blocks (meshio may merge them)."""
    idx = [k for k, b in enumerate(m.cells) if b.type == "line"]
    conn = np.concatenate([m.cells[k].data for k in idx])
    data = {name: np.concatenate([v[k] for k in idx]) for name, v in m.cell_data.items()}
    return conn, data


def test_configuration_round_trip(tmp_path, sys23):
    s = sys23
    nt = len(s.tendons)
    rng = np.random.default_rng(1)
    f = rng.uniform(1.0, 20.0, nt)
    f[3] = -0.5                                  # one slack tendon
    fb = -rng.uniform(5.0, 15.0, s.M * s.N)
    path = write_configuration(tmp_path / "c.vtu", s, tendon_forces=f, bar_forces=fb,
                               point_data={"height": s.nodes()[2]})
    m = meshio.read(path)
    X = s.nodes()
    np.testing.assert_allclose(m.points, X.T)
    conn, d = _lines(m)
    nb = s.M * s.N
    assert conn.shape == (nb + nt, 2) == (6 + 21, 2)      # 2-3: 6 bars, 3 + 6*3 tendons (2.2)
    np.testing.assert_array_equal(conn[:nb].T, s.bar_connectivity)
    np.testing.assert_array_equal(conn[nb:].T, s.tendon_connectivity)
    # lengths: independent recomputation from the node coordinates read back
    L = np.linalg.norm(m.points[conn[:, 1]] - m.points[conn[:, 0]], axis=1)
    np.testing.assert_allclose(d["length"], L, rtol=1e-12)
    np.testing.assert_allclose(d["length"][:nb], np.repeat(s.l[:, 0], s.N), rtol=1e-12)
    np.testing.assert_allclose(d["axial_force"], np.concatenate([fb, f]))
    np.testing.assert_allclose(d["force_density"], np.concatenate([fb, f]) / L)   # q = f / l
    # stress = f / (pi d^2 / 4), d = 0.6 mm tendons, 30 mm bars (2-3 preset, Table 6.1)
    np.testing.assert_allclose(d["axial_stress"][nb:], f / (np.pi * 0.6e-3**2 / 4), rtol=1e-12)
    np.testing.assert_allclose(d["axial_stress"][:nb], fb / (np.pi * 0.03**2 / 4), rtol=1e-12)
    np.testing.assert_array_equal(d["slack"][nb:], (f <= 0).astype(int))
    assert np.all(d["slack"][:nb] == -1)
    assert np.all(d["kind"][:nb] == KIND_CODES["bar"]) and np.all(d["kind"][nb:] == KIND_CODES["tendon"])
    fams = [FAMILY_CODES[k] for k in d["family"][nb:]]
    assert fams == [t.family for t in s.tendons]
    np.testing.assert_array_equal(d["stage"][nb:], [t.stage for t in s.tendons])
    # membrane polygon B_21, B_22, B_23 (one cell) when no mesh is given
    poly = [b for b in m.cells if b.type == "polygon"]
    assert len(poly) == 1 and poly[0].data.shape == (1, 3)
    assert [s.node_labels[k] for k in poly[0].data[0]] == ["B_21", "B_22", "B_23"]
    # node codes reproduce the labels
    lab = [("A", "B", "H")[k] + f"_{i}{j}" for k, i, j in
           zip(m.point_data["node_kind"], m.point_data["node_stage"], m.point_data["node_j"])]
    assert lab == s.node_labels
    np.testing.assert_allclose(m.point_data["height"], X[2])


def test_rest_lengths_give_strain_and_slack(tmp_path, sys14):
    s = sys14
    L = s.tendon_lengths()
    r = L * np.array([0.9, 0.95, 1.02, 0.99])           # third tendon longer than its span
    m = meshio.read(write_configuration(tmp_path / "r.vtu", s, rest_lengths=r))
    _, d = _lines(m)
    nb = s.N
    np.testing.assert_allclose(d["rest_length"][nb:], r)
    np.testing.assert_allclose(d["strain"][nb:], (L - r) / r, rtol=1e-12)
    np.testing.assert_array_equal(d["slack"][nb:], [0, 0, 1, 0])
    assert np.all(np.isnan(d["axial_force"]))          # no forces were given
    # without forces or rest lengths the slack flag is "unknown" (-1)
    m = meshio.read(write_configuration(tmp_path / "g.vtu", s.replace(rest_lengths=None)))
    _, d = _lines(m)
    assert np.all(d["slack"] == -1)


def test_membrane_mesh_is_written_as_quads(tmp_path, sys23):
    s = sys23
    mesh = polygon_quad_mesh(s.membrane_corners, 10)
    vm = np.linspace(0.0, 1.0, mesh.t.shape[1])
    mf = membrane_on_configuration(s, mesh, cell_data={"von_mises": vm},
                                   point_data={"w": np.arange(mesh.p.shape[1], dtype=float)})
    m = meshio.read(write_configuration(tmp_path / "m.vtu", s, membrane=mf))
    nn = mesh.p.shape[1]
    assert m.points.shape[0] == len(s.node_labels) + nn
    quads = [k for k, b in enumerate(m.cells) if b.type == "quad"]
    assert len(quads) == 1 and m.cells[quads[0]].data.shape == (300, 4)   # 3 x 10 x 10 (6.2.2)
    np.testing.assert_allclose(m.cell_data["von_mises"][quads[0]], vm)
    _, d = _lines(m)
    assert np.all(np.isnan(d["von_mises"]))
    assert np.all(m.cell_data["kind"][quads[0]] == KIND_CODES["membrane"])
    np.testing.assert_allclose(m.point_data["w"][-nn:], np.arange(nn))
    assert np.all(np.isnan(m.point_data["w"][:-nn]))
    # quads refer to the membrane points, which sit on the bar tops at the corners
    q = m.cells[quads[0]].data
    assert q.min() == len(s.node_labels)
    np.testing.assert_allclose(m.points[len(s.node_labels) + mesh.corners].T,
                               s.membrane_corners_inertial(), atol=1e-12)


def test_membrane_placement_is_the_radial_stretch_of_eq_3_22(sys14):
    # symmetric 1-4 design: every corner moves radially by Delta (eq. 3.22), so mean value
    # interpolation (linear precision) gives the uniform stretch (r_mb + Delta) / r_mb
    s = sys14
    mesh = polygon_quad_mesh(s.membrane_corners, 6)
    mf = membrane_on_configuration(s, mesh)
    Delta = s.symmetric.membrane_delta(s.N, s.r_mb)
    c_ref = s.membrane_corners.mean(axis=1, keepdims=True)
    c_cur = mf.x[:, mesh.corners].mean(axis=1, keepdims=True)
    r_ref = np.linalg.norm(mesh.p - c_ref, axis=0)
    r_cur = np.linalg.norm(mf.x - c_cur, axis=0)
    np.testing.assert_allclose(r_cur, r_ref * (s.r_mb + Delta) / s.r_mb, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(mf.x[2], mf.x[2, 0], atol=1e-12)     # flat, horizontal


def test_mean_value_coordinates_reproduce_linear_functions():
    # an irregular convex heptagon: vertices on a circle in angular order (always convex);
    # random radii would not be (seed 3 gave a reflex vertex at P_0)
    rng = np.random.default_rng(3)
    ang = np.sort(rng.uniform(0, 2 * np.pi, 7))
    P = 1.1 * np.array([np.cos(ang), np.sin(ang)])
    e = np.roll(P, -1, axis=1) - P
    assert np.all(e[0] * np.roll(e[1], -1) - e[1] * np.roll(e[0], -1) > 0)   # convex, CCW
    w = rng.uniform(0, 1, (7, 200))
    w /= w.sum(axis=0)
    X = P @ w                                                  # points inside the polygon
    X = np.concatenate([X, P, 0.5 * (P + np.roll(P, -1, axis=1))], axis=1)  # + corners, edges
    lam = mean_value_coordinates(P, X)
    np.testing.assert_allclose(lam.sum(axis=0), 1.0, atol=1e-12)
    np.testing.assert_allclose(P @ lam, X, atol=1e-12)         # linear precision
    np.testing.assert_allclose(lam[:, 200:207], np.eye(7), atol=1e-12)
    assert np.all(lam >= -1e-12)                               # convex: non-negative


def test_xdmf_and_vtk_reader(tmp_path, sys14):
    s = sys14
    p = write_configuration(tmp_path / "c.xdmf", s, tendon_forces=np.full(4, 7.0))
    m = meshio.read(p)
    tri = [b for b in m.cells if b.type == "triangle"]
    assert tri and tri[0].data.shape == (2, 3)       # square polygon -> fan of N - 2 triangles
    _, d = _lines(m)
    np.testing.assert_allclose(d["axial_force"][4:], 7.0)
    # VTK's own XML reader accepts the .vtu (independent of meshio's reader)
    g = pv.read(write_configuration(tmp_path / "c.vtu", s, tendon_forces=np.full(4, 7.0)))
    assert g.n_cells == 4 + 4 + 1 and g.n_points == 8
    np.testing.assert_allclose(g.cell_data["axial_force"][4:8], 7.0)
    # legacy .vtk: VTK's reader rejects meshio's int32 type names, so codes are int64
    g = pv.read(write_configuration(tmp_path / "c.vtk", s, tendon_forces=np.full(4, 7.0)))
    np.testing.assert_array_equal(g.cell_data["kind"], [0] * 4 + [1] * 4 + [2])
    np.testing.assert_array_equal(g.point_data["node_kind"], [0] * 4 + [1] * 4)


def test_modes_file(tmp_path, sys14):
    s = sys14
    X = s.nodes()
    n = X.shape[1]
    rng = np.random.default_rng(0)
    S = rng.normal(size=(3 * n, 5))
    f = np.array([1.5, 2.0, 2.0, 3.25, 7.0])
    p = write_modes(tmp_path / "modes.vtu", X, configuration_cells(s), S, f)
    m = meshio.read(p)
    for k in range(5):   # node-interleaved dofs: dof = 3 node + component
        np.testing.assert_allclose(m.point_data[f"mode_{k + 1}"], S[:, k].reshape(n, 3))
    np.testing.assert_allclose(m.field_data["frequency_hz"], f)
    g = pv.read(p)
    np.testing.assert_allclose(np.asarray(g.field_data["frequency_hz"]), f)
    assert float(np.asarray(g.field_data["mode_4_hz"])[0]) == 3.25


def test_series_survives_an_interrupted_run(tmp_path, sys14):
    s = sys14
    X = s.nodes()
    cells = configuration_cells(s)

    def frames():
        for k in range(5):
            if k == 3:
                raise RuntimeError("simulation stopped")
            yield (0.1 * k, X + 0.01 * k, cells, {"z": X[2] + k})

    with pytest.raises(RuntimeError, match="stopped"):
        write_series(tmp_path / "run", frames(), name="vib")
    entries = read_pvd(tmp_path / "run" / "vib.pvd")
    assert [t for t, _ in entries] == pytest.approx([0.0, 0.1, 0.2])
    last = meshio.read(entries[-1][1])
    np.testing.assert_allclose(last.points, (X + 0.02).T)
    np.testing.assert_allclose(last.point_data["z"], X[2] + 2)
    w = SeriesWriter(tmp_path / "cfg", name="q")
    w.append_configuration(0.0, s)
    w.append_configuration(0.5, s, tendon_forces=np.ones(4))
    assert len(read_pvd(w.pvd)) == 2
    reader = pv.get_reader(str(w.pvd))          # VTK's own PVD reader accepts the collection
    assert reader.time_values == pytest.approx([0.0, 0.5])
    reader.set_active_time_value(0.5)
    np.testing.assert_allclose(reader.read()[0].cell_data["axial_force"][4:8], 1.0)
    with pytest.raises(InputError, match="increase"):
        w.append_configuration(0.5, s)


def test_errors_name_what_was_expected(tmp_path, sys14):
    s = sys14
    with pytest.raises(InputError, match=r"suffix in \['.vtu'"):
        write_configuration(tmp_path / "c.stl", s)
    (tmp_path / "d.vtu").mkdir()
    with pytest.raises(InputError, match="is a directory"):
        write_configuration(tmp_path / "d.vtu", s)
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="not a directory"):
        write_configuration(tmp_path / "file" / "c.vtu", s)
    with pytest.raises(InputError, match=r"tendon_forces: expected shape \(4,\), found \(3,\)"):
        write_configuration(tmp_path / "c.vtu", s, tendon_forces=np.ones(3))
    with pytest.raises(InputError, match="non-finite"):
        write_configuration(tmp_path / "c.vtu", s, tendon_forces=np.array([1, np.nan, 1, 1]))
    mesh = polygon_quad_mesh(s.membrane_corners, 2)
    with pytest.raises(InputError, match=r"expected positions x of shape \(3, 25\)"):
        MembraneField(mesh=mesh, x=np.zeros((3, 24)))
    with pytest.raises(InputError, match=r"expected shape \(16,\) or \(c, 16\)"):
        MembraneField(mesh=mesh, x=np.zeros((3, 25)), cell_data={"s": np.zeros(15)})
    X = s.nodes()
    with pytest.raises(InputError, match=r"shapes: expected shape \(24, k\)"):
        write_modes(tmp_path / "m.vtu", X, configuration_cells(s), np.zeros((23, 2)), [1, 2])
    with pytest.raises(InputError, match="expected 2 frequencies"):
        write_modes(tmp_path / "m.vtu", X, configuration_cells(s), np.zeros((24, 2)), [1.0])
    with pytest.raises(InputError, match=r"node indices must lie in \[0, 8\)"):
        write_modes(tmp_path / "m.vtu", X, [("line", np.array([[0], [8]]))], np.zeros((24, 1)), [1])
    with pytest.raises(InputError, match="suffix"):
        write_modes(tmp_path / "m.xdmf", X, configuration_cells(s), np.zeros((24, 1)), [1])
