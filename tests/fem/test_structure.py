"""The general structure API (tmfem.fem.structure).

Sources: the pinched hemisphere of MacNeal & Harder (1985), radial displacement 0.0924 under
the load (our check: mesh convergence towards it, docs/guides/shells.md); Euler's load of a pinned
strut and a prestressed membrane's closed-form frequencies f = (1/2a) sqrt(N/(rho h)) sqrt(m^2+n^2)
(benchmarks.json rectangular_membrane_uniform_tension); the truss closed form of a pinned bar;
follower versus dead pressure on a small deflection (equal to first order).
"""
import meshio
import numpy as np
import pytest
from skfem import MeshQuad

from tmfem.errors import InputError
from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure
from tmfem.fem.truss import TrussElement, TrussSet


def pinched_hemisphere(n):
    """Quarter hemisphere with an 18 deg hole (R = 10, t = 0.04, E = 6.825e7, nu = 0.3),
    forces +-1 at the equator on the x and y axes (the worked example of docs/guides/shells.md)."""
    R = 10.0
    m = MeshQuad.init_tensor(np.linspace(0, np.pi / 2, n + 1), np.linspace(np.deg2rad(18), np.pi / 2, n + 1))
    theta, psi = m.p
    p = R * np.vstack([np.sin(psi) * np.cos(theta), np.sin(psi) * np.sin(theta), np.cos(psi)])
    s = Structure.shell((p, m.t), section=ShellSection(E=6.825e7, nu=0.3, thickness=0.04), normals=-p / R)
    s.symmetry(s.nodes_where(lambda x, y, z: np.isclose(y, 0)), normal="y")
    s.symmetry(s.nodes_where(lambda x, y, z: np.isclose(x, 0, atol=1e-9)), normal="x")
    A = s.nodes_where(lambda x, y, z: np.isclose(x, R) & np.isclose(y, 0))
    B = s.nodes_where(lambda x, y, z: np.isclose(y, R) & np.isclose(x, 0, atol=1e-9))
    s.fix(A, "uz")
    s.point_load(A, force=(1.0, 0, 0))
    s.point_load(B, force=(0, -1.0, 0))
    return s, int(A[0])


def test_pinched_hemisphere_converges_to_the_reference():
    u = []
    for n in (4, 8, 16):
        s, A = pinched_hemisphere(n)
        u.append(s.displacements(s.solve_linear())[0, A])
    assert u[-1] == pytest.approx(0.0924, rel=0.02)
    assert abs(u[2] - 0.0924) < abs(u[1] - 0.0924) < abs(u[0] - 0.0924)


def test_results_as_meshio_mesh(tmp_path):
    s, A = pinched_hemisphere(4)
    st = s.solve_linear()
    m = s.to_meshio(st)
    assert isinstance(m, meshio.Mesh) and m.points.shape == (25, 3)
    assert m.point_data["displacement"].shape == (25, 3)
    for key in ("N", "M", "Q"):
        assert m.cell_data[key][0].shape[0] == 16
    assert np.all(m.cell_data["von_mises_top"][0] >= 0)
    m.write(tmp_path / "hemisphere.vtu")
    assert (tmp_path / "hemisphere.vtu").stat().st_size > 0


def plate_with_pinned_bar():
    """A 2 x 2 clamped plate (5-dof nodes) with a truss bar (3-dof nodes) pinned to its corner
    (1, 1, 0), the bar's other end (node 10) on a roller in x, y and loaded by 5 N in z."""
    xs = np.linspace(0, 1, 3)
    m = MeshQuad.init_tensor(xs, xs)
    p = np.hstack([np.vstack([m.p, np.zeros(9)]), [[1.0, 1.0], [1.0, 1.0], [0.0, 1.0]]])
    s = Structure(points=p, dofs=[5] * 9 + [3, 3])
    s.add_shell(m.t, section=ShellSection(E=1e9, nu=0.3, thickness=0.1))
    corner = int(s.nodes_where(lambda x, y, z: np.isclose(x, 1) & np.isclose(y, 1) & np.isclose(z, 0))[0])
    s.add(TrussElement(TrussSet(conn=np.array([[9], [10]]), L=np.array([1.0]), EA=1e3, rhoA=0.0,
                                tension_only=np.array([False])), s.dofmap))
    s.pin(9, to=corner)
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) & (z == 0)))
    s.fix([10], ["ux", "uy"])
    s.point_load([10], force=(0, 0, 5.0))
    return s


def test_pinned_truss_on_a_shell_corner_and_mixed_dof_counts():
    """A bar (3-dof nodes) pinned to the corner of a stiff clamped plate: the bar force of a
    tip load P at the bar's free end is P (truss closed form, N = EA E l / L at equilibrium)."""
    s = plate_with_pinned_bar()
    st = s.solve(steps=2)[-1]
    d = st.x[:, 10] - st.x[:, 9]
    corner = int(s.nodes_where(lambda x, y, z: np.isclose(x, 1) & np.isclose(y, 1) & np.isclose(z, 0))[0])
    assert np.allclose(st.x[:, 9], st.x[:, corner])
    l = np.linalg.norm(d)
    assert 1e3 * (l**2 - 1) / 2 * l == pytest.approx(5.0, rel=1e-6)


def test_prestressed_thin_membrane_modes_by_displacement_control():
    """A 51 um shell square stretched by prescribed edge displacements (displacement control),
    then its modes about the prestressed state: f_11 and f_12 of the prestressed membrane."""
    a, n, E, nu, h, rho, strain = 1.0, 10, 1.65e8, 0.34, 51e-6, 1400.0, 1e-3
    xs = np.linspace(0, a, n + 1)
    s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=E, nu=nu, thickness=h, rho=rho))
    edge = s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(x, a) | np.isclose(y, 0) | np.isclose(y, a))
    for k in edge:
        s.prescribe([k], "ux", strain * s.X[0, k])
        s.prescribe([k], "uy", strain * s.X[1, k])
        s.prescribe([k], "uz", 0.0)
    st = s.solve(steps=1)[-1]
    m = s.modes(k=3, at=st)
    Eg = ((1 + strain) ** 2 - 1) / 2
    N = E / (1 - nu) * Eg * h
    f11 = np.sqrt(N / (rho * h)) / (2 * a) * np.sqrt(2)
    assert m.freq_hz[0] == pytest.approx(f11, rel=0.02)
    assert m.freq_hz[1] == pytest.approx(f11 * np.sqrt(5 / 2), rel=0.03)


def _pressed_plate(follower, backend="scipy"):
    xs = np.linspace(0, 1, 5)
    s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=1e6, nu=0.3, thickness=0.01),
                        backend=backend)
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(x, 1) | np.isclose(y, 0) | np.isclose(y, 1)),
          ["ux", "uy", "uz"])
    s.pressure(0.5, follower=follower)
    return s, int(s.nodes_where(lambda x, y, z: np.isclose(x, 0.5) & np.isclose(y, 0.5))[0])


def test_arc_length_and_follower_pressure_agree_with_load_control():
    s, c = _pressed_plate(False)
    last = s.solve_arc_length(dl=0.01, n_steps=200, lam_max=1.0)[-1]
    w_load = s.displacements(s.solve(steps=4, lam_end=last.lam)[-1])[2, c]
    assert s.displacements(last)[2, c] == pytest.approx(w_load, rel=1e-6)
    w_dead = s.displacements(s.solve(steps=4)[-1])[2, c]
    s, c = _pressed_plate(True)
    w_follower = s.displacements(s.solve(steps=4)[-1])[2, c]
    arc = s.solve_arc_length(dl=0.01, max_steps=200, lam_max=1.0)[-1]      # follower load stiffness
    assert s.displacements(arc)[2, c] == pytest.approx(
        s.displacements(s.solve(steps=4, lam_end=arc.lam)[-1])[2, c], rel=1e-6)
    # w/a = 1 %: the follower load differs from the dead one by the small rotations only
    assert w_follower == pytest.approx(w_dead, rel=0.02) and w_follower != w_dead


def test_structure_refusals():
    xs = np.linspace(0, 1, 3)
    s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=1, nu=0, thickness=0.1))
    with pytest.raises(InputError, match="normal 'x', 'y', 'z' or a 3-vector"):
        s.symmetry([0], normal="w")
    with pytest.raises(InputError, match="parallel to the director"):
        s.symmetry([0], normal="z")
    s.pressure(1.0, follower=True)
    s.prescribe([0], "ux", 0.1)
    with pytest.raises(InputError, match="no prescribed displacements"):
        s.solve_arc_length(dl=0.1)
    with pytest.raises(InputError, match="steps >= 1"):
        s.solve(steps=0)
    with pytest.raises(InputError, match="quad cells"):
        Structure.shell(meshio.Mesh(np.zeros((3, 3)), [("triangle", np.array([[0, 1, 2]]))]),
                        section=ShellSection(E=1, nu=0, thickness=0.1))


def test_gmsh_model_and_meshio_file_give_the_same_structure(tmp_path):
    """A transfinite recombined gmsh rectangle read from the live model and from its .msh file:
    same nodes and quads, and the same linear tip deflection P L^3/(3 EI) of a clamped strip."""
    gmsh = pytest.importorskip("gmsh")
    from tmfem.fem.structure import gmsh_quad_mesh
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("strip")
        gmsh.model.occ.addRectangle(0, 0, 0, 4.0, 0.5)
        gmsh.model.occ.synchronize()
        for c in gmsh.model.getEntities(1):
            gmsh.model.mesh.setTransfiniteCurve(c[1], 9 if c[1] in (1, 3) else 2)
        gmsh.model.mesh.setTransfiniteSurface(1)
        gmsh.model.mesh.setRecombine(2, 1)
        gmsh.model.mesh.generate(2)
        live = gmsh_quad_mesh()
        gmsh.write(str(tmp_path / "strip.msh"))
    finally:
        gmsh.finalize()
    tips = []
    for mesh in (live, tmp_path / "strip.msh"):
        s = Structure.shell(mesh, section=ShellSection(E=1e7, nu=0.0, thickness=0.05))
        s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0)))
        tip = s.nodes_where(lambda x, y, z: np.isclose(x, 4.0))
        s.point_load(tip, force=(0, 0, 1e-3 / tip.size))
        tips.append(s.displacements(s.solve_linear())[2, tip].mean())
    EI = 1e7 * 0.5 * 0.05**3 / 12
    assert tips[0] == pytest.approx(tips[1], rel=1e-12)
    assert abs(tips[0]) == pytest.approx(1e-3 * 4.0**3 / (3 * EI), rel=0.01)


def test_shell_started_from_the_membrane_equilibrium_converges_at_once():
    """4.5.4 at 51 um: the membrane element's equilibrium, turned into a shell state
    (positions, directors along the deformed normals), is within the shell's bending effect of
    the shell equilibrium: Newton from it converges in at most 3 iterations to the shell solution
    of the load-stepped run."""
    from tmfem.reference.benchmarks.shell_square_membrane import shell_square_membrane
    from tmfem.reference.element_benchmarks import square_membrane
    from tmfem.solvers.newton import newton
    s, st, _, _, mesh = shell_square_membrane(n=5)
    mem = square_membrane(n=5)
    start = s.state_from_positions(s.X + mem.u)
    r = newton(lambda q: s.residual(q, 1.0), start.state, free=s.constraints.free, tol=1e-8, scale=0.1,
               line_search=False, update=s.advance)
    assert r.iterations <= 3
    assert np.abs(r.u.x - st.x).max() <= 1e-6 * np.abs(mem.u[2]).max()


def test_point_moment_does_not_depend_on_the_order_of_symmetry_and_load():
    """Half of a clamped strip (symmetry plane y = 0 turns the triads of its nodes) under an end
    moment about y: the same tip rotation M L/(EI) whether the moment is given before or after
    the symmetry plane (beam closed form, nu = 0, linear)."""
    tips = []
    for order in ("load first", "symmetry first"):
        m = MeshQuad.init_tensor(np.linspace(0, 2.0, 5), np.linspace(0, 0.5, 2))
        s = Structure.shell(m, section=ShellSection(E=1e4, nu=0.0, thickness=0.02))
        tip = s.nodes_where(lambda x, y, z: np.isclose(x, 2.0))
        sym = s.nodes_where(lambda x, y, z: np.isclose(y, 0.0))
        s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0.0)))
        if order == "load first":
            s.point_load(tip, moment=(0, 1e-4 / 2, 0))
            s.symmetry(sym, normal="y")
        else:
            s.symmetry(sym, normal="y")
            s.point_load(tip, moment=(0, 1e-4 / 2, 0))
        tips.append(s.rotation_vectors(s.solve_linear())[1, tip])
    EI = 1e4 * 0.5 * 0.02**3 / 12
    np.testing.assert_allclose(tips[0], tips[1], rtol=1e-12)
    np.testing.assert_allclose(np.abs(tips[0]), 1e-4 * 2.0 / EI, rtol=1e-8)


class _CountingBackend:
    """The scipy backend, counting the calls that reach it."""

    name = "counting"

    def __init__(self):
        from tmfem.solvers.backends import ScipyBackend
        self.inner, self.calls = ScipyBackend(), {"factorize": 0, "eigsh": 0}

    def factorize(self, A):
        self.calls["factorize"] += 1
        return self.inner.factorize(A)

    def eigsh(self, K, M, k, sigma, v0=None):
        self.calls["eigsh"] += 1
        return self.inner.eigsh(K, M, k, sigma, v0=v0)


def test_every_solve_of_a_structure_goes_through_its_backend():
    # source: the same solves on the default backend (results equal), and the call counts
    be = _CountingBackend()
    s, c = _pressed_plate(False, backend=be)
    ref, _ = _pressed_plate(False)
    w = s.displacements(s.solve_linear())[2, c]
    assert be.calls["factorize"] == 1
    assert w == ref.displacements(ref.solve_linear())[2, c]
    s.solve(steps=2)
    s.solve_arc_length(dl=0.05, n_steps=2)
    assert be.calls["factorize"] > 3
    xs = np.linspace(0, 1, 4)
    plates = [Structure.shell(MeshQuad.init_tensor(xs, xs), backend=b,
                              section=ShellSection(E=1e6, nu=0.3, thickness=0.01, rho=1e3))
              for b in (be, "scipy")]
    for p in plates:
        p.fix(p.nodes_where(lambda x, y, z: np.isclose(x, 0)), "all")
    assert np.array_equal(plates[0].modes(k=3).omega2, plates[1].modes(k=3).omega2)
    assert be.calls["eigsh"] == 1
