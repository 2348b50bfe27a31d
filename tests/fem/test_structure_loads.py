"""Loads of a structure: line loads, gravity, follower line loads, load cases
(tmfem.fem.structure.loads).

Sources: Timoshenko beam closed forms (cantilever under a uniform load: tip deflection
q L^4 / (8 EI) + q L^2 / (2 k G A), Cowper's k; a cantilever strip under an end line load
q b: P L^3 / (3 EI)); statics (a simply supported span under a triangular load 0 -> q0:
reactions q0 L / 6 and q0 L / 3; the weight of a model equals the sum of rho V g);
finite differences of the follower line load; superposition of linear load cases.
"""
import numpy as np
import pytest
from skfem import MeshQuad

from tmfem.errors import InputError
from tmfem.fem.beam import BeamElement, BeamSection, BeamSet, line_mesh
from tmfem.fem.element import State
from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure
from tmfem.fem.structure.loads import LineLoad


def _beam(L=4.0, n=8, rho=0.0):
    X, conn = line_mesh([0, 0, 0], [L, 0, 0], n_elements=n)
    s = Structure(points=X, dofs=6)
    sec = BeamSection.rectangle(a=0.2, b=0.1)
    beam = BeamElement(BeamSet(conn=conn, section=sec, E=2e9, nu=0.3, rho=rho, v1=[0, 1, 0]), s.dofmap, X=X)
    s.add(beam)
    return s, beam, sec


def test_uniform_line_load_on_a_cantilever_beam():
    L, q = 4.0, -150.0
    s, beam, sec = _beam(L)
    s.fix([0])
    s.line_load(beam, (0.0, 0.0, q))
    st = s.solve_linear()
    E, nu = 2e9, 0.3
    G = E / (2 * (1 + nu))
    w = q * L**4 / (8 * E * sec.I_s) + q * L**2 / (2 * sec.shear_coefficient(nu) * G * sec.A)
    assert s.displacements(st)[2, -1] == pytest.approx(w, rel=2e-3)
    F, M = s.resultant(st, [0])
    np.testing.assert_allclose(F, [0, 0, -q * L], atol=1e-9)
    np.testing.assert_allclose(M, [0, q * L**2 / 2, 0], atol=1e-8)


def test_triangular_line_load_reactions_on_a_simple_span():
    """Pinned at x = 0, on a roller at x = L: q(x) = q0 x / L along -z."""
    L, q0 = 4.0, 300.0
    s, beam, _ = _beam(L, n=3)
    s.fix([0], ["ux", "uy", "uz", "rx"])
    s.fix([s.n_nodes - 1], ["uy", "uz"])
    s.line_load(beam, lambda x, y, z: np.vstack([0 * x, 0 * x, -q0 * x / L]))
    st = s.solve_linear()
    R = s.reactions(st)
    assert R.force[2, 0] == pytest.approx(q0 * L / 6, rel=1e-9)
    assert R.force[2, -1] == pytest.approx(q0 * L / 3, rel=1e-9)


def test_edge_line_load_on_a_cantilever_strip():
    """A strip (L = 4, b = 0.5, nu = 0) clamped at x = 0 with q [N/m] along its free edge:
    the end shear P = q b, tip deflection P L^3 / (3 EI)."""
    L, b, h, E, q = 4.0, 0.5, 0.05, 1e7, -2e-3
    s = Structure.shell(MeshQuad.init_tensor(np.linspace(0, L, 17), np.linspace(0, b, 3)),
                        section=ShellSection(E=E, nu=0.0, thickness=h))
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0)))
    s.node_set("tip", s.nodes_where(lambda x, y, z: np.isclose(x, L)))
    s.line_load("tip", (0, 0, q))
    st = s.solve_linear()
    w = s.displacements(st)[2, s.node_sets["tip"]]
    assert w.mean() == pytest.approx(q * b * L**3 / (3 * E * b * h**3 / 12), rel=0.01)
    assert s.loads.cases["default"].force.sum() == pytest.approx(q * b, rel=1e-12)


def test_gravity_on_a_shell_with_a_beam_balances_the_weight():
    """A clamped plate (rho h A) carrying a beam (rho A L) pinned to its free corner."""
    rho, h = 7800.0, 0.01
    m = MeshQuad.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    Xb, cb = line_mesh([1.0, 1.0, 0.0], [1.0, 1.0, -2.0], n_elements=2)
    s = Structure(points=np.hstack([np.vstack([m.p, np.zeros(25)]), Xb]), dofs=[5] * 25 + [6] * Xb.shape[1])
    s.add_shell(m.t, section=ShellSection(E=2e11, nu=0.3, thickness=h, rho=rho))
    sec = BeamSection.circle(d=0.05)
    s.add(BeamElement(BeamSet(conn=cb + 25, section=sec, E=2e11, nu=0.3, rho=rho, v1=[1, 0, 0]), s.dofmap, X=s.X))
    corner = int(s.nodes_where(lambda x, y, z: np.isclose(x, 1) & np.isclose(y, 1) & (z == 0))[0])
    s.pin(25, to=corner)
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) & (z == 0)))
    s.fix([25], ["rz"])                                    # the beam's spin about its axis
    s.gravity((0, 0, -9.81))
    W = rho * 9.81 * (h * 1.0 + sec.A * 2.0)
    for st in (s.solve_linear(), s.solve(steps=2)[-1]):
        F, _ = s.resultant(st)
        np.testing.assert_allclose(F, [0, 0, W], rtol=1e-8, atol=1e-8 * W)


def test_follower_line_load_stiffness_against_finite_differences():
    m = MeshQuad.init_tensor(np.linspace(0, 1, 4), np.linspace(0, 0.5, 3))
    s = Structure.shell(m, section=ShellSection(E=1e6, nu=0.3, thickness=0.02))
    edge = s.nodes_where(lambda x, y, z: np.isclose(x, 1))
    ld = LineLoad(X=s.X, lines=s._lines(edge), dofmap=s.dofmap, q=3.0, follower=True, frames=s.frames)
    f0, _ = ld.load(s.reference_state())
    d = s.frames[edge[0], :, 2]
    np.testing.assert_allclose(f0[s.dofmap.translation_dofs(edge)].sum(axis=0), 3.0 * 0.5 * d, atol=1e-14)
    rng = np.random.default_rng(3)
    st = s.reference_state().advanced(rng.normal(scale=0.3, size=s.dofmap.ndof), s.dofmap)
    f, K = ld.load(st)
    K = K.toarray()
    eps = 1e-6
    for j in rng.choice(np.flatnonzero(np.abs(K).sum(axis=0) > 0), size=12, replace=False):
        du = np.zeros(s.dofmap.ndof)
        du[j] = eps
        fp, _ = ld.load(st.advanced(du, s.dofmap), tangent=False)
        fm, _ = ld.load(st.advanced(-du, s.dofmap), tangent=False)
        np.testing.assert_allclose((fp - fm) / (2 * eps), K[:, j], atol=1e-6)


def test_load_cases_combine_linearly_and_refuse_unknown_names():
    s, beam, _ = _beam()
    s.fix([0])
    s.line_load(beam, (0, 0, -100.0), case="dead")
    s.point_load([s.n_nodes - 1], force=(0, 50.0, 0), case="live")
    u = {}
    for name in ("dead", "live"):
        s.combine(**{name: 1.0})
        u[name] = s.displacements(s.solve_linear())
    s.combine(dead=1.35, live=1.5)
    np.testing.assert_allclose(s.displacements(s.solve_linear()), 1.35 * u["dead"] + 1.5 * u["live"], atol=1e-15)
    s.combine()
    np.testing.assert_allclose(s.displacements(s.solve_linear()), u["dead"] + u["live"], atol=1e-15)
    with pytest.raises(InputError, match=r"load cases from \['dead', 'live'\], found \['wind'\]"):
        s.combine(wind=1.0)
    with pytest.raises(InputError, match="3 components"):
        s.line_load(beam, (1.0, 2.0))
    with pytest.raises(InputError, match="massless"):
        s.gravity()
    assert isinstance(s.reference_state(), State)
