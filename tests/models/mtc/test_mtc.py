"""Membrane-truss-cable model of a System (dissertation 4.4, 6.2-6.4)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tmfem.errors import InputError
from tmfem.models.mtc.model import MTCModel
from tmfem.fem.truss import green_rest_length, linear_rest_length
from tmfem.reference.tables import FREQUENCIES
from tmfem.models.mtc.post import static_summary
from tmfem.system import System, SymmetricConfig, load_preset


def exact_1_4() -> System:
    """The 1-4 system of Table 6.2 with r_1 from eq. 3.33 unrounded (printed 0.4286)."""
    s = load_preset("1-4", as_printed=True)
    c = s.symmetric
    r1 = c.l[0] * np.sin(c.theta[0]) * np.sin(c.psi[0]) / np.cos(np.pi / 4)
    cfg = SymmetricConfig(theta=c.theta, psi=c.psi, sigma=c.sigma, z=c.z, r=[r1], l=c.l)
    return System.symmetric_system(name="1-4", N=4, config=cfg, r_mb=s.r_mb, membrane=s.membrane,
                                   bar=s.bar, tendon_sections=s.tendon_sections, printed=s.printed)


@pytest.fixture(scope="module")
def exact_model():
    return MTCModel(exact_1_4(), mesh_n=6, tendon_elements=2, rest_lengths="mtc")


def test_topology_counts():
    # 1-4, n = 10, k = 3: (2 n + 1)^2 membrane nodes, 8 bar ends, 4 tendons x 2 internal
    # nodes; dependent B_1j (4) and pinned A_1j (4) leave 3 (457 - 8) = 1347 free dofs,
    # the "about 1.3k DOF" of the paper's mesh (6.2.1: 4 x 10 x 10 quads).
    m = MTCModel(load_preset("1-4", as_printed=True), mesh_n=10, tendon_elements=3)
    assert m.topology.n_mesh == 21 * 21
    assert m.n_nodes == 441 + 8 + 8
    assert m.ndof == 1347
    assert m.topology.mesh.t.shape[1] == 400


def test_deployable_rejected():
    s = load_preset("1-4", as_printed=True)
    from tmfem.system import TendonSection
    d = s.replace(deployable=True, k_H=0.5, tendons=(), rest_lengths=None,
                  tendon_sections={"*": TendonSection(E=2e9, d=0.6e-3, rho=1140.0)})
    with pytest.raises(InputError, match="deployable"):
        MTCModel(d, mesh_n=2)


def test_tangent_matches_finite_differences(exact_model):
    # independent check: K_red = T^T K T against central differences of T^T f(T x)
    m = exact_model
    rng = np.random.default_rng(0)
    xr = m.reduce(m.initial_positions("design")) + 1e-3 * rng.standard_normal(3 * m.topology.n_red)
    _, K = m.residual(xr)
    for j in rng.choice(np.flatnonzero(m.free), 6, replace=False):
        e = np.zeros_like(xr)
        e[j] = 1e-6
        fd = (m.residual(xr + e, tangent=False)[0] - m.residual(xr - e, tangent=False)[0]) / 2e-6
        col = K[:, j].toarray().ravel()
        assert np.allclose(col, fd, rtol=1e-5, atol=1e-6 * np.abs(col).max())


def test_residual_is_energy_gradient(exact_model):
    # the residual is the gradient of the strain energy (conservative system): central
    # differences of energy() against r along random directions
    m = exact_model
    rng = np.random.default_rng(1)
    xr = m.reduce(m.initial_positions("design")) + 1e-3 * rng.standard_normal(3 * m.topology.n_red)
    r, _ = m.residual(xr, tangent=False)
    for _ in range(3):
        d = rng.standard_normal(xr.size) * m.free
        h = 1e-7
        fd = (m.energy(xr + h * d) - m.energy(xr - h * d)) / (2 * h)
        assert fd == pytest.approx(r @ d, rel=1e-5)


def test_consistent_prestress_matches_eq_3_34(exact_model):
    # closed form of the 1-N null vector (eq. 3.34): (T/|S_1|) / (F_Delta/(Delta + r_mb))
    # = cos(psi + pi/N) / (2 sin psi sin(pi/N)); F_Delta from the nonlinear membrane.
    m = exact_model
    c = m.consistent_rest_lengths()
    s = m.system
    psi = s.symmetric.psi[0]
    Fc = c["corner_force"]
    F_delta = np.linalg.norm(Fc[:2], axis=0).mean()
    B = s.membrane_corners_inertial()
    R = np.linalg.norm(B - B.mean(axis=1, keepdims=True), axis=0).mean()   # Delta + r_mb
    ratio = (c["tendon_force"][0] / c["tendon_length"][0]) / (F_delta / R)
    assert ratio == pytest.approx(np.cos(psi + np.pi / 4) / (2 * np.sin(psi) * np.sin(np.pi / 4)),
                                  rel=1e-3)
    assert c["equilibrium_residual"] < 1e-3   # exact r_1: residual only from the membrane's w
    assert np.all(c["tendon_force"] > 0)


def test_static_lands_on_design_from_undeformed(exact_model):
    # with the design-consistent rest lengths the equilibrium IS the design (6.2: "the
    # system converges to the designed equilibrium"), reached from the unstressed membrane
    m = exact_model
    res = m.equilibrium(start="undeformed", monitor=["B_14"])
    X = res.x[:, m.topology.system_node]
    Xd = m.system.nodes()
    assert np.abs(X - Xd).max() < 2e-5      # round-off of the corner-force balance above
    h = res.monitor["B_14"]
    assert np.linalg.norm(h[0] - Xd[:, m.system.node_index("B_14")]) > 5e-4   # it moved
    # quadratic convergence at the end (mu -> 0, Newton steps): from 1e-2 N to the
    # round-off floor (~1e-8 N: bars with EA = 1.4e8 N) within five iterations
    r = np.array(res.residual_history)
    k = int(np.flatnonzero(r < 1e-2)[0])
    assert r[-1] < 1e-7 and len(r) - 1 - k <= 5
    assert res.mu_history[-1] < 1e-6 * res.mu_history[0]     # regularisation gone
    # the same state from the other start
    res2 = m.equilibrium(start="design")
    assert np.abs(res2.x - res.x).max() < 1e-7


def test_green_rest_length_inverts_truss_law():
    # N = EA E l / r, E = (l^2 - r^2) / (2 r^2) (tmfem.fem.truss); linear spring eq. 3.8
    l, T, EA = 1.53, 10.7, 565.0
    r = green_rest_length(l, T, EA)
    E = (l**2 - r**2) / (2 * r**2)
    assert EA * E * l / r == pytest.approx(T, rel=1e-12)
    assert linear_rest_length(l, T, EA) == pytest.approx(EA * l / (T + EA))


def test_design_prestress_agrees_with_linear_design():
    # independent formulation: tmfem.equilibrium.design (linear plane-stress membrane,
    # eq. 3.16 null vector) vs our nonlinear membrane + node balance at the same mesh
    from tmfem.equilibrium.design import design_equilibrium
    s = exact_1_4()
    d = design_equilibrium(s, mesh_n=6)
    m = MTCModel(s, mesh_n=6, tendon_elements=1, rest_lengths="mtc")
    c = m.consistent_rest_lengths()
    # the two membranes differ at first order in the strain: the relative force difference is
    # bounded by the peak membrane strain sigma_p1,max / E (0.6 % here; we find 0.4 %)
    strain = d.membrane_max_principal / s.membrane.E
    assert strain < 1e-2
    assert c["tendon_force"] == pytest.approx(d.tendon_forces, rel=strain)


@pytest.fixture(scope="module")
def paper_prestress_modes():
    # 4 x 10 x 10 membrane, 3 elements per tendon (6.4.1); rest length 1.5025 m, the value
    # the dissertation's own Tables 6.3 and 6.6 imply (docs/validation/errata.md, "MTC 1-4 prestress")
    s = load_preset("1-4", as_printed=True).with_rest_lengths({"S1": 1.5025})
    m = MTCModel(s, mesh_n=10, tendon_elements=3)
    res = m.equilibrium(start="undeformed")
    return m, res, m.modes(k=12, at=res.x)


def test_frequencies_vs_table_6_6(paper_prestress_modes):
    # Table 6.6, MTC column. Tolerance 0.5 %: the rest length is inferred to 0.1 mm, which
    # moves the membrane frequencies by up to 0.2 % (d f_4 / d r = -27.5 Hz/m, measured).
    m, res, modes = paper_prestress_modes
    ref = np.array(FREQUENCIES["1-4"]["MTC"])
    assert modes.freq_hz == pytest.approx(ref, rel=5e-3)


def test_cyclic_pairs(paper_prestress_modes):
    # C4 symmetry: modes 2-3, 6-7, 10-11 are degenerate pairs (Table 6.6)
    _, _, modes = paper_prestress_modes
    f = modes.freq_hz
    for a in (1, 5, 9):
        assert f[a] == pytest.approx(f[a + 1], rel=1e-6)
    assert f[0] < 0.999 * f[1]


def test_static_vs_table_6_3(paper_prestress_modes):
    # Table 6.3: bar load 14.53 N, max tendon stress 37.98 MPa, max sigma_p1 2.12 MPa,
    # max von Mises 1.91 MPa. Bar load within 1 %; tendon stress within 5 % (Green strain
    # of the TL truss vs the linear spring of eq. 3.8 at 1.9 % strain: 1.5 eps = 2.9 %);
    # membrane peaks sit at the point-loaded corners and are mesh dependent (docs/guides/mtc.md),
    # so only their order of magnitude is compared.
    m, res, _ = paper_prestress_modes
    st = static_summary(m, res.x)
    assert st["bar_load_max"] == pytest.approx(14.53, rel=1e-2)
    assert st["tendon_stress_max"] == pytest.approx(37.98e6, rel=5e-2)
    assert 0.5e6 < st["membrane_max_sigma_p1"] < 5e6
    assert all(c["ok"] for c in st["checks"])


def test_printed_rest_length_contradicts_table_6_3():
    # the printed r_1^S = 1.529 m (Table 6.2) leaves the tendons nearly unstressed: the
    # equilibrium it reaches has a tendon stress < 10 % of the printed 37.98 MPa (Table 6.3)
    s = load_preset("1-4", as_printed=True)
    m = MTCModel(s, mesh_n=6, tendon_elements=1)
    res = m.equilibrium(start="design")
    st = static_summary(m, res.x)
    assert st["tendon_stress_max"] < 0.1 * 37.98e6
    assert not st["tendon_slack"]


def test_tendon_subdivision_does_not_change_frequencies():
    # Fig. 6.12: frequencies of the first 12 modes identical for 1..n elements per tendon
    s = load_preset("1-4", as_printed=True).with_rest_lengths({"S1": 1.5025})
    f, ndof = [], []
    for k in (1, 3):
        m = MTCModel(s, mesh_n=4, tendon_elements=k)
        f.append(m.modes(k=12, at=m.equilibrium(start="design").x).freq_hz)
        ndof.append(m.ndof)
    assert ndof[1] == ndof[0] + 4 * 2 * 3          # two models: 2 inner nodes per tendon
    assert f[1] == pytest.approx(f[0], rel=2e-3)


def test_distributed_attachment_close_to_point():
    # a small patch (radius 10 % of r_mb, 0.14 m) changes the four global modes little (they
    # converge under refinement, docs/guides/mtc.md); the membrane modes from mode 5 on are the
    # corner-sensitive ones. At mesh 20 the patch holds 8-9 nodes per corner, so the two
    # models really differ
    s = load_preset("1-4", as_printed=True).with_rest_lengths({"S1": 1.5025})
    f = {}
    for att in ("point", "distributed"):
        m = MTCModel(s, mesh_n=20, tendon_elements=1, attachment=att)
        f[att] = m.modes(k=6, at=m.equilibrium(start="design").x).freq_hz
    assert min(nodes.size for nodes, _ in m.topology.weights) > 3
    assert f["distributed"][:4] == pytest.approx(f["point"][:4], rel=1e-2)
    assert np.max(np.abs(f["distributed"] / f["point"] - 1)) > 1e-3   # not the same model
    with pytest.raises(InputError, match="holds 3 membrane nodes"):
        MTCModel(s, mesh_n=10, tendon_elements=1, attachment="distributed")


def test_cli_static_and_modal_json(tmp_path, capsys):
    import json
    from tmfem.cli import main
    import meshio
    assert main(["static", "--preset", "1-4", "--as-printed", "--mesh", "4", "--tendon-elements",
                 "1", "--json", "--vtk", str(tmp_path / "s.vtu")]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["iterations"] > 1
    T = np.array(list(out["tendon_force"].values()))
    # the printed r_1^S = 1.529 m (Table 6.2) leaves the tendons nearly unstressed (see
    # test_printed_rest_length_contradicts_table_6_3); stress = T / (pi d^2 / 4), d = 0.6 mm
    assert out["tendon_stress_max"] == pytest.approx(T.max() / (np.pi * 0.3e-3**2), rel=1e-12)
    assert 0 < out["tendon_stress_max"] < 0.1 * 37.98e6
    # the VTK file carries the same forces, and they follow the Green-strain truss law
    # N = EA E l / r, E = (l^2 - r^2) / (2 r^2) (tmfem.fem.truss) from the written lengths.
    # rtol 1e-4: the file places the nodes from q with rigid bars (q_from_positions), off by
    # the bars' elastic shortening F l / EA_bar ~ 2e-8 m, which the 0.17 % tendon strain
    # amplifies x600; the linear spring EA (l - r) / r would be 2.5e-3 off
    m = meshio.read(tmp_path / "s.vtu")
    line = [k for k, b in enumerate(m.cells) if b.type == "line"][0]
    l, f = m.cell_data["length"][line][4:], m.cell_data["axial_force"][line][4:]
    np.testing.assert_allclose(f, T, rtol=1e-10)
    r, EA = 1.529, load_preset("1-4").tendon_EA[0]
    np.testing.assert_allclose(f, EA * (l**2 - r**2) / (2 * r**2) * l / r, rtol=1e-4)
    assert main(["modal", "--preset", "1-4", "--as-printed", "--mesh", "4", "--modes", "4",
                 "--json", "--vtk", str(tmp_path / "m.vtu")]) == 0
    out = json.loads(capsys.readouterr().out)
    f = np.array(out["freq_hz"])
    assert out["dissertation"]["MTC"] == [0.1386, 0.3076, 0.3076, 1.5599]     # Table 6.6
    np.testing.assert_allclose(out["relative_difference_to_MTC"],
                               f / [0.1386, 0.3076, 0.3076, 1.5599] - 1, rtol=1e-12)
    # soft system of the printed rest length (~0.04 Hz, tests/models/test_com_vs_mtc.py); modes 2-3
    # are a C4-degenerate pair (Table 6.6)
    assert f[0] < 0.35 * 0.1367 and f[1] == pytest.approx(f[2], rel=1e-6)
    np.testing.assert_allclose(meshio.read(tmp_path / "m.vtu").field_data["frequency_hz"], f,
                               rtol=1e-12)
    assert main(["static", "--preset", "1-4", "--mesh", "0", "--json"]) != 0
    assert "error" in capsys.readouterr().err
    assert main(["static", "--preset", "1-4", "--mesh", "3", "--tendon-elements", "1",
                 "--rest-lengths", "S1=1.5025", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["rest_lengths"]["S_13"] == 1.5025
    assert main(["modal", "--preset", "1-4", "--rest-lengths", "S1=x"]) != 0
    assert "GROUP=VALUE" in capsys.readouterr().err


def test_2_3_printed_rest_lengths_do_not_fit_printed_geometry():
    # Table 6.4: at the printed geometry the tendons are shorter than their printed rest
    # lengths (S_1: 1.626 m vs 1.9425 m, V_2: 1.101 m vs 1.9953 m), i.e. slack; the MTC
    # solve from that state finds no equilibrium and says which tendons are slack
    from tmfem.errors import ConvergenceError
    s = load_preset("2-3", as_printed=True)
    strain = s.tendon_lengths() / s.rest_lengths - 1
    names = [t.name for t in s.tendons]
    assert strain[names.index("S_11")] == pytest.approx(1.6261 / 1.9425 - 1, abs=1e-3)
    assert strain[names.index("V_21")] == pytest.approx(1.1014 / 1.9953 - 1, abs=1e-3)
    m = MTCModel(s, mesh_n=3, tendon_elements=1)
    with pytest.raises(ConvergenceError, match="slack"):
        m.equilibrium(start="design", max_iter=80)


def test_two_stage_system_lands_on_its_design():
    # M = 2: free stage-2 bars (only A_1j pinned). With the design-consistent rest lengths
    # (node balance of all 27 free-node equations, 6 bars + 21 tendons) the equilibrium
    # reached from the undeformed membrane is the design; and tmfem.equilibrium's linear
    # design (independent formulation, eq. 3.16) lands within 0.1 mm of it.
    s = load_preset("2-3")      # the final 2-3 configuration of Table 7.7 (docs/validation/errata.md)
    m = MTCModel(s, mesh_n=4, tendon_elements=1, rest_lengths="mtc")
    res = m.equilibrium(start="undeformed")
    st = static_summary(m, res.x)
    assert st["max_deviation_from_design"] < 1e-5
    assert not st["tendon_slack"]
    assert len(st["bar_load_by_stage"]) == 2 and min(st["bar_load_by_stage"]) > 0
    m2 = MTCModel(s, mesh_n=4, tendon_elements=1, rest_lengths="design")
    st2 = static_summary(m2, m2.equilibrium(start="design").x)
    assert st2["max_deviation_from_design"] < 1e-3


def test_mesh_interpolation_is_linear_and_matches_scipy_interpolate():
    # source: closed form (piecewise-linear interpolation reproduces an affine field) and
    # scipy.interpolate.LinearNDInterpolator on the same triangulation (independent code)
    from scipy.interpolate import LinearNDInterpolator
    s = load_preset("1-4")
    coarse, fine = MTCModel(s, mesh_n=3, tendon_elements=1), MTCModel(s, mesh_n=5, tendon_elements=1)
    A = np.array([[1.1, 0.2], [-0.1, 0.9], [0.3, 0.05]])
    xc = coarse.initial_positions("design")
    xc[:, :coarse.topology.n_mesh] = A @ coarse.topology.mesh.p + np.array([[0.1], [0.2], [1.0]])
    xf = fine.interpolate_from(coarse, xc)
    pf = fine.topology.mesh.p
    c = pf.mean(axis=1, keepdims=True)
    pts = c + (1.0 - 1e-9) * (pf - c)
    nm = fine.topology.n_mesh
    inner = np.ones(nm, bool)
    inner[fine.topology.mesh.corners] = False            # corners follow the attachment
    assert np.allclose(xf[:, :nm][:, inner], (A @ pts + np.array([[0.1], [0.2], [1.0]]))[:, inner],
                       rtol=0, atol=1e-12)
    # a non-affine field: the same values as scipy's interpolator
    xc[:, :coarse.topology.n_mesh] = np.sin(3 * coarse.topology.mesh.p[[0, 1, 0]]) \
        + coarse.topology.mesh.p[[1, 0, 1]] ** 2
    xf = fine.interpolate_from(coarse, xc)
    ref = LinearNDInterpolator(coarse.topology.mesh.p.T, xc[:, :coarse.topology.n_mesh].T)(pts.T).T
    ok = np.all(np.isfinite(ref), axis=0) & inner
    assert ok.sum() > 0.8 * nm
    assert np.allclose(xf[:, :nm][:, ok], ref[:, ok], rtol=0, atol=1e-12)


def test_mesh_sequencing_reaches_the_direct_equilibrium():
    # source: the same model solved from the undeformed membrane without sequencing (an
    # independent path to the same equilibrium); the coarse level stops at the looser
    # COARSE_TOL, the finest one at the requested tol
    s = load_preset("1-4")
    m = MTCModel(s, mesh_n=12, tendon_elements=1)
    direct = m.equilibrium(tol=1e-9)
    seq = m.equilibrium(tol=1e-9, sequence=6)
    assert len(seq.level_iterations) == 2
    assert np.abs(seq.x - direct.x).max() <= 1e-9 * np.abs(direct.x).max()
    assert seq.residual_history[-1] <= 1e-9 * m._force_scale(seq.x)


def test_modes_reuse_the_static_tangent(paper_prestress_modes):
    # source: the tangent assembled again at the equilibrium (the same kernels at the same
    # positions: the same entries, bit for bit) and the modes of it (two ARPACK runs on one
    # matrix differ by up to 2e-10 from their random start vectors); a tangent of the wrong
    # kind or size is refused
    m, res, ref = paper_prestress_modes
    _, K = m.residual(m.reduce(res.x))
    assert (res.tangent != K).nnz == 0
    md = m.modes(k=12, at=res)
    assert np.allclose(md.omega2, ref.omega2, rtol=1e-9, atol=0)
    for bad in (res.tangent[:-1, :-1], res.tangent.toarray()):
        with pytest.raises(InputError, match="expected the tangent of this model's static solve"):
            m.modes(k=12, at=replace(res, tangent=bad))
