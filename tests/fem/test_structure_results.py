"""Nodal stresses and section forces (tmfem.fem.structure.results).

Sources: a linear stress field (patch test): the displacement u_x = c x y on a rectangular
mesh (exactly bilinear) has the strains e_xx = c y, g_xy = c x, so the plane-stress law gives
s11 = E c y / (1 - nu^2), s22 = nu s11, s12 = G c x at every point, which Gauss-point
extrapolation and nodal averaging must return at the nodes; beam statics: a cantilever
under a tip force P has the bending moment P (L - x) and the shear force P, and a strip of
width b the moment per unit width P (L - x) / b with surface stresses -+ 6 M / h^2.
"""
import meshio
import numpy as np
from skfem import MeshQuad

from tmfem.fem.beam import BeamElement, BeamSection, BeamSet, line_mesh
from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure, StructureState


def test_linear_stress_field_is_recovered_at_the_nodes():
    E, nu, h, c = 2e5, 0.3, 0.02, 1e-7
    m = MeshQuad.init_tensor(np.array([0.0, 0.3, 0.7, 1.2, 2.0]), np.array([0.0, 0.4, 0.5, 1.0]))
    n = m.p.shape[1]
    s = Structure.shell(m, section=ShellSection(E=E, nu=nu, thickness=h), orient=(0, 0, 1))
    x, y, _ = s.X
    du = np.zeros(s.dofmap.ndof)
    du[s.dofmap.translation_dofs(np.arange(n))[:, 0]] = c * x * y
    st = StructureState(state=s.reference_state().advanced(du, s.dofmap), lam=1.0)
    r = s.stresses(st)
    s11 = E * c * y / (1 - nu**2)
    s12 = E / (2 * (1 + nu)) * c * x
    exact = np.column_stack([s11, nu * s11, s12, 0 * x, 0 * x])
    scale = np.abs(exact).max()
    for surf in ("bottom", "mid", "top"):
        np.testing.assert_allclose(r[f"sigma_{surf}"], exact, atol=1e-6 * scale)
        centre, rad = 0.5 * (1 + nu) * s11, np.hypot(0.5 * (1 - nu) * s11, s12)
        np.testing.assert_allclose(r[f"principal_{surf}"], np.column_stack([centre + rad, centre - rad]),
                                   atol=1e-6 * scale)
        vm = np.sqrt(s11**2 - nu * s11**2 + (nu * s11)**2 + 3 * s12**2)
        np.testing.assert_allclose(r[f"von_mises_{surf}"], vm, atol=1e-6 * scale)
    np.testing.assert_allclose(r["N"], h * exact[:, :3], atol=1e-6 * scale * h)
    np.testing.assert_allclose(r["M"], 0.0, atol=1e-6 * scale * h**2)


def test_cantilever_strip_moments_and_surface_stresses():
    L, b, h, E, P = 4.0, 0.5, 0.05, 1e7, -1e-3
    m = MeshQuad.init_tensor(np.linspace(0, L, 17), np.linspace(0, b, 3))
    s = Structure.shell(m, section=ShellSection(E=E, nu=0.0, thickness=h), orient=(0, 0, 1))
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0)))
    s.line_load(s.nodes_where(lambda x, y, z: np.isclose(x, L)), (0, 0, P / b))
    st = s.solve_linear()
    r = s.stresses(st)
    x = s.X[0]
    Mx = -P * (L - x) / b                      # M11 with e_3 = +z: tension at the top for P < 0
    # the element's moment is constant along x: the average of two neighbours is exact at
    # interior nodes; at the two ends it is half an element's jump off
    inner = (x > 0) & (x < L)
    dM = abs(P) * (L / 16) / b
    np.testing.assert_allclose(r["M"][inner, 0], Mx[inner], atol=1e-6 * dM)
    np.testing.assert_allclose(r["M"][~inner, 0], Mx[~inner] - np.sign(L / 2 - x[~inner]) * dM / 2, atol=1e-6 * dM)
    top = 6 * r["M"][:, 0] / h**2
    np.testing.assert_allclose(r["sigma_top"][:, 0], top, atol=1e-6 * top.max())
    np.testing.assert_allclose(r["sigma_bottom"][:, 0], -top, atol=1e-6 * top.max())
    np.testing.assert_allclose(r["Q"][:, 0], P / b * np.ones_like(x), rtol=1e-6)      # Q1 = dM11/dx


def test_beam_section_forces_at_the_nodes_and_in_the_meshio_file(tmp_path):
    L, P = 3.0, np.array([0.0, 0.0, -40.0])
    X, conn = line_mesh([0, 0, 0], [L, 0, 0], n_elements=4)
    s = Structure(points=X, dofs=6)
    s.add(BeamElement(BeamSet(conn=conn, section=BeamSection.rectangle(a=0.2, b=0.1), E=2e9, nu=0.3,
                              rho=0.0, v1=[0, 1, 0]), s.dofmap, X=X))
    s.fix([0])
    s.point_load([X.shape[1] - 1], force=P)
    st = s.solve_linear()
    r = s.stresses(st)
    x = X[0]
    np.testing.assert_allclose(np.abs(r["beam_M1"]), 40.0 * (L - x), atol=1e-5 * 40 * L)
    np.testing.assert_allclose(np.abs(r["beam_Q2"]), 40.0, rtol=1e-6)
    np.testing.assert_allclose(r["beam_N"], 0.0, atol=1e-6)
    mesh = s.to_meshio(st)
    mesh.write(tmp_path / "beam.vtu")
    back = meshio.read(tmp_path / "beam.vtu")
    np.testing.assert_allclose(back.point_data["beam_M1 [N m]"], r["beam_M1"])
    assert back.cells[0].type == "line" and back.cells[0].data.shape == (3 * 4, 2)
