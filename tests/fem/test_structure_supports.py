"""Supports that compose (tmfem.fem.structure.supports): symmetry planes, fixed and
prescribed dofs, skew frames, pins, release and copy.

Sources: the pinched cylinder with rigid diaphragms (MacNeal & Harder, Finite Elem. Anal.
Des. 1 (1985); w = 1.8248e-5 under the load, Belytschko et al. CMAME 51 (1985)), the simply
supported square plate under uniform pressure (Timoshenko & Woinowsky-Krieger, table 8:
w = 0.00406 q a^4 / D, nu = 0.3), a bar on a skew roller (statics: the guide takes the
force component normal to the bar, the bar the rest, u = F_t L / EA), and the same model
built with every rotation fixed by hand.
"""
import numpy as np
import pytest
from skfem import MeshQuad

from tmfem.errors import InputError
from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure
from tmfem.fem.truss import TrussElement, TrussSet
from tmfem.reference.benchmarks.shell_pinched_cylinder import model as pinched_cylinder

def _w(s, A):
    return -s.displacements(s.solve_linear())[2, A]


def test_a_node_on_two_symmetry_planes_gets_both_conditions():
    w = {}
    for how, order in (("symmetry", ("x", "y")), ("symmetry", ("y", "x")), ("by hand", ("x", "y"))):
        s, A = pinched_cylinder(n=16, how=how, order=order)
        w[how, order] = _w(s, A)
    ref = w["by hand", ("x", "y")]
    assert w["symmetry", ("x", "y")] == pytest.approx(ref, rel=1e-10)
    assert w["symmetry", ("y", "x")] == pytest.approx(ref, rel=1e-10)


def test_pinched_cylinder_octant_converges_to_the_published_value():
    ratio = []
    for n in (8, 16, 32):
        s, A = pinched_cylinder(n=n)
        ratio.append(_w(s, A) / 1.8248e-5)
    # MITC4 converges from below: 0.75, 0.93, 0.989
    assert ratio[0] < ratio[1] < ratio[2] < 1.0
    assert ratio[2] == pytest.approx(1.0, abs=0.02)


def test_plate_quarter_with_the_centre_on_both_planes():
    """Quarter of a simply supported square plate (a = 1, h = 0.01) under pressure: the
    centre node is on both symmetry planes."""
    E, nu, h, a, q, n = 1e7, 0.3, 0.01, 1.0, 1.0, 12
    xs = np.linspace(0, a / 2, n + 1)

    def model(by_hand):
        s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=E, nu=nu, thickness=h))
        c = s.nodes_where(lambda x, y, z: np.isclose(x, a / 2) & np.isclose(y, a / 2))
        for ax, k in (("x", 0), ("y", 1)):
            nodes = s.nodes_where(lambda *X: np.isclose(X[k], a / 2))
            s.symmetry(np.setdiff1d(nodes, c) if by_hand else nodes, normal=ax)
        if by_hand:
            s.fix(c, ["ux", "uy", "r1", "r2"])
        s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(y, 0)), "uz")
        s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) & np.isclose(y, 0)), ["ux", "uy"])
        s.pressure(-q, follower=False)
        return s, int(c[0])
    w = []
    for by_hand in (False, True):
        s, c = model(by_hand)
        w.append(abs(s.displacements(s.solve_linear())[2, c]))
    D = E * h**3 / (12 * (1 - nu**2))
    assert w[0] == pytest.approx(w[1], rel=1e-10)
    assert w[0] == pytest.approx(0.00406 * q * a**4 / D, rel=0.01)


def test_bar_on_a_skew_roller():
    """A bar from the origin to (1, 1, 0)/sqrt(2) m, its end guided along the bar by a roller
    in the node's local frame (e1 along the bar), loaded by F = (3, 1, 2) N: the end moves
    F.e1 L / EA along e1, the guide takes the rest of F (local reactions)."""
    e1 = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    axes = np.column_stack([e1, [-e1[1], e1[0], 0.0], [0.0, 0.0, 1.0]])
    s = Structure(points=np.column_stack([np.zeros(3), e1]), dofs=3)
    EA = 1e6
    s.add(TrussElement(TrussSet(conn=np.array([[0], [1]]), L=np.array([1.0]), EA=EA, rhoA=0.0,
                                tension_only=np.array([False])), s.dofmap))
    s.fix([0])
    s.local_frame([1], axes)
    s.fix([1], ["uy", "uz"])
    F = np.array([3.0, 1.0, 2.0])
    s.point_load([1], force=F)
    st = s.solve_linear()
    u = s.displacements(st)[:, 1]
    np.testing.assert_allclose(u, (F @ e1) / EA * e1, atol=1e-14)
    loc = s.reactions(st, frame="local").force[:, 1]
    np.testing.assert_allclose(loc, [0.0, -(F @ axes[:, 1]), -F[2]], atol=1e-10)
    # a nonlinear solve agrees (small load) and the supports are the same object
    stn = s.solve(steps=1)[-1]
    np.testing.assert_allclose(s.displacements(stn)[:, 1], u, rtol=1e-5)


def test_conflicting_and_redundant_constraints_are_refused_with_the_node_and_dof():
    xs = np.linspace(0, 1, 3)
    s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=1, nu=0, thickness=0.1))
    s.fix([0], "ux")
    s.fix([0], "ux")                                   # a support twice: nothing new
    s.symmetry([0], normal="x")                        # ux again, plus a rotation: composes
    with pytest.raises(InputError, match=r"node 0: .*conflicting one: ux = 0.1 against ux \(fix"):
        s.prescribe([0], "ux", 0.1)
    with pytest.raises(InputError, match=r"node 0: .*redundant one: ux = 0"):
        s.prescribe([0], "ux", 0.0)
    s.prescribe([1], "ux", 0.2)
    with pytest.raises(InputError, match=r"node 1: .*conflicting one: ux = 0 against ux \(prescribe"):
        s.fix([1], "ux")
    with pytest.raises(InputError, match=r"node 1: .*redundant one"):
        s.prescribe([1], "ux", 0.2)
    with pytest.raises(InputError, match="node 4 has supports"):
        s.fix([4], "ux")
        s.pin(4, to=8)
    s.pin(5, to=8)
    with pytest.raises(InputError, match="node 5 is pinned already"):
        s.pin(5, to=7)
    with pytest.raises(InputError, match="node 5: its translations follow"):
        s.fix([5], "uy")
    with pytest.raises(InputError, match="chain"):
        s.pin(6, to=5)
    with pytest.raises(InputError, match="rotation about a shell director is not a dof"):
        s.fix([2], "rz")
    with pytest.raises(InputError, match="expected a support along uy"):
        s.release([0], "uy")


def test_prescribed_values_from_a_function_of_position():
    """In-plane stretch u_x = eps x of a free strip (plane stress, nu = 0.3): the end
    reaction is E h b eps for every eps law given per node or as a function."""
    E, h, eps = 2e5, 0.01, 1e-4
    m = MeshQuad.init_tensor(np.linspace(0, 2, 5), np.linspace(0, 1, 3))
    s = Structure.shell(m, section=ShellSection(E=E, nu=0.3, thickness=h))
    s.node_set("left", s.nodes_where(lambda x, y, z: np.isclose(x, 0)))
    s.node_set("right", s.nodes_where(lambda x, y, z: np.isclose(x, 2)))
    s.fix("left", "ux")
    s.fix([0], ["uy"])
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(y, 0) | np.isclose(y, 1)), "uz")
    s.prescribe("right", "ux", lambda x, y, z: eps * x)
    st = s.solve_linear()
    F, _ = s.resultant(st, "right")
    assert F[0] == pytest.approx(E * h * 1.0 * eps, rel=1e-8)
    np.testing.assert_allclose(s.displacements(st)[0], eps * s.X[0], atol=1e-14)


def test_release_and_copy():
    """A copy is independent; releasing a support and supporting again gives the model
    built that way from the start."""
    xs = np.linspace(0, 1, 9)

    def base():
        s = Structure.shell(MeshQuad.init_tensor(xs, np.linspace(0, 0.25, 2)),
                            section=ShellSection(E=1e6, nu=0.0, thickness=0.05))
        s.point_load(s.nodes_where(lambda x, y, z: np.isclose(x, 1)), force=(0, 0, -1.0))
        return s
    clamped = base()
    clamped.fix(clamped.nodes_where(lambda x, y, z: np.isclose(x, 0)))
    other = clamped.copy()
    other.release(other.nodes_where(lambda x, y, z: np.isclose(x, 0)), ["r1", "r2"])
    other.release(other.nodes_where(lambda x, y, z: np.isclose(x, 0)))
    other.fix(other.nodes_where(lambda x, y, z: np.isclose(x, 1)))
    other.point_load(other.nodes_where(lambda x, y, z: np.isclose(x, 0)), force=(0, 0, -1.0))
    fresh = base()
    fresh.fix(fresh.nodes_where(lambda x, y, z: np.isclose(x, 1)))
    fresh.point_load(fresh.nodes_where(lambda x, y, z: np.isclose(x, 0)), force=(0, 0, -1.0))
    w_other = other.displacements(other.solve_linear())
    np.testing.assert_allclose(w_other, fresh.displacements(fresh.solve_linear()), atol=1e-15)
    # the original is untouched: the cantilever closed form P L^3 / 3 EI of its tip
    w = clamped.displacements(clamped.solve_linear())[2, -1]
    EI = 1e6 * 0.25 * 0.05**3 / 12
    assert w == pytest.approx(-2.0 * 1.0 / (3 * EI), rel=0.01)


def test_bad_input_to_the_new_calls_is_refused_in_one_line():
    xs = np.linspace(0, 1, 3)
    s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=1, nu=0, thickness=0.1))
    with pytest.raises(InputError, match=r"one per node|finite value per node"):
        s.prescribe([0, 1], "ux", [1.0, 2.0, 3.0])
    with pytest.raises(InputError, match=r"axes of shape \(3, 3\)"):
        s.local_frame([0], np.eye(2))
    with pytest.raises(InputError, match="orthonormal"):
        s.local_frame([0], 2 * np.eye(3))
    s.point_load([4], force=(0, 0, 1.0), case="live")
    with pytest.raises(InputError, match="finite factors"):
        s.combine(live="x")
    with pytest.raises(InputError, match="node set"):
        s.fix("nowhere")
    with pytest.raises(InputError, match="first step dl"):
        s.solve_arc_length(dl=-1.0)
    with pytest.raises(InputError, match="expected a free dof"):
        s.fix([8], "uz")
        s.solve_displacement_control(node=8, dof="uz", increment=0.1)
    with pytest.raises(InputError, match="shell element edges"):
        s.line_load([0, 8], (0, 0, 1.0))
