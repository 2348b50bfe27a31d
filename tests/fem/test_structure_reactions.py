"""Support reactions and their resultants (tmfem.fem.structure.reactions).

Sources: statics. The internal forces of every element set are invariant under rigid
motions, so at an equilibrium the reactions balance the applied nodal loads in force and in
moment about any point, in the deformed configuration (free-body check); a cantilever's
clamp carries -P and -(L x P) - M (closed form).
"""
import meshio
import numpy as np
import pytest
from skfem import MeshQuad

from tests.fem.test_structure import plate_with_pinned_bar
from tmfem.fem.beam import BeamElement, BeamSection, BeamSet, line_mesh
from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure


def _free_body(s, st, scale, *, tol):
    """Force and moment balance of reactions and applied loads about two points."""
    R = s.reactions(st)
    F, M = s.applied(st)
    for about in ((0.0, 0.0, 0.0), (3.0, -2.0, 5.0)):
        a = np.reshape(about, (3, 1))
        fr, mr = R.resultant(about=about)
        np.testing.assert_allclose(fr + F.sum(axis=1), 0.0, atol=tol * scale)
        ma = np.cross((R.x - a).T, F.T).sum(axis=0) + M.sum(axis=1)
        np.testing.assert_allclose(mr + ma, 0.0, atol=tol * scale * 10)
    return R


def _panel():
    """A cylindrical panel (R = 2, 60 deg, length 2) clamped along one straight edge, with a
    follower pressure, an oblique point force and a point moment at a free corner."""
    m = MeshQuad.init_tensor(np.linspace(0, 2, 7), np.linspace(-np.pi / 6, np.pi / 6, 7))
    x, th = m.p
    p = np.vstack([x, 2 * np.sin(th), 2 * np.cos(th)])
    s = Structure.shell((p, m.t), section=ShellSection(E=1e7, nu=0.3, thickness=0.05),
                        normals=np.vstack([0 * x, np.sin(th), np.cos(th)]))
    s.node_set("clamp", s.nodes_where(lambda x, y, z: np.isclose(x, 0)))
    s.fix("clamp")
    s.pressure(-200.0, follower=True)
    corner = s.nodes_where(lambda x, y, z: np.isclose(x, 2) & (y > 0.99))
    s.point_load(corner, force=(30.0, -50.0, 80.0), moment=(5.0, 7.0, -3.0))
    return s


def test_shell_reactions_balance_the_loads_linear_and_nonlinear():
    s = _panel()
    _free_body(s, s.solve_linear(), 800.0, tol=1e-9)
    path = s.solve(steps=3, tol=1e-10)
    R = _free_body(s, path[-1], 800.0, tol=1e-8)
    # only the clamped nodes react, and the resultant of the set is the total
    clamp = s.node_sets["clamp"]
    rest = np.setdiff1d(np.arange(s.n_nodes), clamp)
    assert np.abs(R.force[:, rest]).max() < 1e-6
    np.testing.assert_allclose(s.resultant(path[-1], "clamp")[0], R.resultant()[0], atol=1e-12)
    assert np.linalg.norm(s.displacements(path[-1])) > 0.05          # nonlinear range


def test_cantilever_beam_clamp_reactions_closed_form():
    L = 4.0
    X, conn = line_mesh([0, 0, 0], [L, 0, 0], n_elements=6)
    s = Structure(points=X, dofs=6)
    s.add(BeamElement(BeamSet(conn=conn, section=BeamSection.rectangle(a=0.2, b=0.1), E=2e9,
                              nu=0.3, rho=0.0, v1=[0, 1, 0]), s.dofmap, X=X))
    s.fix([0])
    P, M = np.array([10.0, -20.0, 30.0]), np.array([1.0, 2.0, -4.0])
    s.point_load([X.shape[1] - 1], force=P, moment=M)
    st = s.solve_linear()
    R = s.reactions(st)
    np.testing.assert_allclose(R.force[:, 0], -P, atol=1e-9)
    np.testing.assert_allclose(R.moment[:, 0], -np.cross([L, 0, 0], P) - M, atol=1e-8)
    _free_body(s, s.solve(steps=2, tol=1e-9)[-1], 50.0, tol=1e-8)


def test_mixed_shell_and_truss_free_body_and_meshio_fields(tmp_path):
    """A bar (3-dof nodes) pinned to the corner of a clamped plate, its other end on a
    roller and loaded: reactions at the plate's clamp and at the roller balance the load."""
    s = plate_with_pinned_bar()
    s.point_load([4], force=(1.0, 2.0, -3.0))
    st = s.solve(steps=2, tol=1e-9)[-1]
    R = _free_body(s, st, 5.0, tol=1e-8)
    assert np.abs(R.force[:, 9]).max() == 0.0                   # the pinned node carries none
    mesh = s.to_meshio(st)
    np.testing.assert_allclose(mesh.point_data["reaction_force [N]"], R.force.T)
    mesh.write(tmp_path / "r.vtu")
    back = meshio.read(tmp_path / "r.vtu")
    np.testing.assert_allclose(back.point_data["reaction_moment [N m]"], R.moment.T)


def test_reactions_of_a_state_made_elsewhere_come_from_its_residual():
    s = _panel()
    st = s.solve(steps=2, tol=1e-10)[-1]
    again = type(st)(state=st.state, lam=st.lam)
    np.testing.assert_allclose(s.reactions(again).force, s.reactions(st).force, atol=1e-7)
    with pytest.raises(Exception, match="frame 'global' or 'local'"):
        s.reactions(st, frame="nodal")
