"""Dof map with per-node fields, the element interface and the constraint map.

Sources: the node-interleaved numbering dof = 3 node + component that every 3-dof kernel
used before (element_dofs), the MTC attachment map built by a Kronecker product of the
node-level map (the construction this replaced), scipy's rotation composition, and the
closed forms of a two-bar truss and of a linear torsion spring (theta = M / k).
"""
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.spatial.transform import Rotation

from tmfem.errors import InputError
from tmfem.fem.assembly import element_dofs
from tmfem.fem.constraints import ConstraintMap
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import State, assemble
from tmfem.fem.truss import TrussElement, TrussSet
from tmfem.solvers.newton import newton


def test_numbering_of_mixed_nodes():
    dm = DofMap([3, 6, 3, 5])
    assert dm.ndof == 17 and dm.offset.tolist() == [0, 3, 9, 12, 17]
    assert dm.translation_dofs([1, 3]).tolist() == [[3, 4, 5], [12, 13, 14]]
    assert dm.rotation_dofs([1]).tolist() == [[6, 7, 8]]
    assert dm.rotation_dofs([3]).tolist() == [[15, 16]]
    assert dm.element_dofs(np.array([[0], [1]])).tolist() == [[0, 1, 2, 3, 4, 5]]
    assert dm.element_dofs(np.array([[1]]), rotations=True).tolist() == [[3, 4, 5, 6, 7, 8]]
    with pytest.raises(InputError, match="dof counts in"):
        DofMap([3, 4])
    with pytest.raises(InputError, match="common number of rotations"):
        dm.rotation_dofs([0])


def test_translational_map_is_the_interleaved_numbering():
    conn = np.array([[0, 2, 5], [1, 3, 4]])
    assert np.array_equal(DofMap.translations(6).element_dofs(conn), element_dofs(conn, 3))


def _triangle_truss():
    """Two bars from pinned supports at (-1, 0, 0) and (1, 0, 0) to an apex at (0, 1, 0)."""
    X = np.array([[-1.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    ts = TrussSet(conn=np.array([[0, 1], [2, 2]]), L=np.full(2, np.sqrt(2.0)), EA=1e4, rhoA=1.0,
                  tension_only=np.zeros(2, bool))
    return X, ts


class _TorsionSpring:
    """Test element: a linear torsion spring k between the rotation of a 6-dof node and the
    ground, about a fixed axis a: W = k theta^2 / 2 with R = exp(theta a). Exact for
    rotations about a (increments about one axis add)."""

    def __init__(self, node, k, axis, dofmap):
        self.node, self.k, self.axis, self.dofmap = node, k, np.asarray(axis, float), dofmap

    def _theta(self, state):
        return float(Rotation.from_matrix(state.R[self.node]).as_rotvec() @ self.axis)

    def internal(self, state, *, tangent=True):
        d = self.dofmap.rotation_dofs([self.node])[0]
        f = np.zeros(self.dofmap.ndof)
        f[d] = self.k * self._theta(state) * self.axis
        K = sp.csr_matrix((self.k * np.outer(self.axis, self.axis).ravel(),
                           (np.repeat(d, 3), np.tile(d, 3))), shape=(self.dofmap.ndof,) * 2)
        return f, (K if tangent else None)

    def energy(self, state):
        return 0.5 * self.k * self._theta(state) ** 2

    def mass(self):
        return sp.csr_matrix((self.dofmap.ndof,) * 2)


def test_model_mixing_3_and_6_dof_nodes():
    """The apex of a two-bar truss carries rotations (6 dofs) held by a torsion spring; the
    supports have 3 dofs. Under a vertical load P and a moment M about z the truss part must
    match the 3-dof model and the closed form, the rotation must be theta = M / k."""
    X, ts = _triangle_truss()
    P, M, k = -50.0, 0.3, 2.0
    results = {}
    for counts in ([3, 3, 3], [3, 3, 6]):
        dm = DofMap(counts)
        elements = [TrussElement(ts, dm)]
        if dm.counts[2] == 6:
            elements.append(_TorsionSpring(2, k, [0, 0, 1], dm))
        cm = ConstraintMap.build(dm, fixed_nodes=[0, 1])
        fext = np.zeros(dm.ndof)
        fext[dm.translation_dofs([2])[0, 1]] = P
        if dm.counts[2] == 6:
            fext[dm.rotation_dofs([2])[0, 2]] = M
        state0 = State.reference(X, dm)

        def residual(state):
            f, K = assemble(elements, state)
            return cm.residual(f - fext), cm.tangent(K)

        free = cm.free.copy()
        free[cm.reduced_of[dm.translation_dofs([2])[0, 2]]] = False      # keep the truss planar
        if dm.counts[2] == 6:                                            # the spring acts about z
            free[cm.reduced_of[dm.rotation_dofs([2])[0, :2]]] = False
        res = newton(residual, state0, free=free, tol=1e-12,
                     update=lambda s, du: s.advanced(cm.full(du), dm))
        results[tuple(counts)] = res.u
        assert res.converged
    s3, s6 = results[(3, 3, 3)], results[(3, 3, 6)]
    assert np.allclose(s3.x, s6.x, rtol=0, atol=1e-13)
    # closed form: internal = external at the apex, 2 N y / l = P, N = EA E l / L, E = (l^2 - L^2)/(2 L^2)
    y = s3.x[1, 2]
    l2, L2 = 1 + y**2, 2.0
    N_over_l = 1e4 * (l2 - L2) / (2 * L2) / np.sqrt(L2)
    assert 2 * N_over_l * y == pytest.approx(P, rel=1e-10)
    assert Rotation.from_matrix(s6.R[2]).as_rotvec() == pytest.approx([0, 0, M / k], abs=1e-12)


def test_finite_rotation_update_composes_rotations():
    dm = DofMap([6, 5])
    frames = np.stack([np.eye(3), Rotation.from_rotvec([0.2, -0.1, 0.4]).as_matrix()])
    s = State.reference(np.zeros((3, 2)), dm, frames=frames)
    a, b = np.array([0.3, -1.2, 0.5]), np.array([2.0, 0.1, -0.7])
    du1 = np.zeros(dm.ndof)
    du1[3:6] = a
    du1[9:11] = [0.4, -0.3]
    du2 = np.zeros(dm.ndof)
    du2[3:6] = b
    s2 = s.advanced(du1, dm).advanced(du2, dm)
    expected = (Rotation.from_rotvec(b) * Rotation.from_rotvec(a)).as_matrix()
    assert np.allclose(s2.R[0], expected, atol=1e-14)
    # a 5-dof node rotates about its current V1, V2: its normal Vn stays orthogonal to the
    # rotation axis 0.4 V1 - 0.3 V2 (the director turns, it does not spin about itself)
    s1 = s.advanced(du1, dm)
    V0 = frames[1]
    axis = 0.4 * V0[:, 0] - 0.3 * V0[:, 1]
    assert np.allclose(s1.R[1], Rotation.from_rotvec(axis).as_matrix(), atol=1e-14)


def test_constraint_map_reproduces_the_mtc_attachment_map():
    """ConstraintMap.build equals the node-level map kron I_3 the MTC topology used before."""
    from tmfem.models.fe.topology import build_topology
    from tmfem.system import load_preset
    topo = build_topology(load_preset("1-4"), mesh_n=4, tendon_elements=2, attachment="point")
    n, N = topo.n_nodes, topo.top_nodes.size
    dependent = np.zeros(n, bool)
    dependent[topo.top_nodes] = True
    rows, cols, vals = [np.flatnonzero(~dependent)], [topo.red_node[~dependent]], [np.ones(n - N)]
    for j, (nodes, w) in enumerate(topo.weights):
        rows.append(np.full(nodes.size, topo.top_nodes[j]))
        cols.append(topo.red_node[nodes])
        vals.append(w)
    Tn = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                       shape=(n, n - N))
    T_old = sp.kron(Tn, sp.identity(3), format="csr")
    assert abs(T_old - topo.T).max() == 0.0
    free_old = np.ones(3 * (n - N), bool)
    for node in topo.fixed_nodes:
        free_old[3 * topo.red_node[node]:3 * topo.red_node[node] + 3] = False
    assert np.array_equal(free_old, topo.constraints.free)
