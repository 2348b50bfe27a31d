"""Follower line loads on beams (tmfem.fem.structure.loads.BeamFollowerLoad).

Sources: the inextensible elastica of a cantilever under a uniformly distributed load that
stays normal to its axis (a pressure on a line: per unit current length, turning with the
sections), EI theta' = M, M' = -(t x N), N' = -p with p = q0 (sin theta, -cos theta),
clamped at s = 0, N = M = 0 at the free end: a boundary-value problem solved by
scipy.integrate.solve_bvp to 1e-10, an independent formulation of the beam (no stretching,
no shear); the same elastica with the dead load p = (0, -q0) for the contrast; central
finite differences of the nodal load for its load stiffness.
"""
import numpy as np
import pytest
from scipy.integrate import solve_bvp

from tmfem.errors import InputError
from tmfem.fem.beam import BeamElement, BeamSection, BeamSet, line_mesh
from tmfem.fem.element import State
from tmfem.fem.structure import Structure
from tmfem.fem.structure.loads import BeamFollowerLoad

LENGTH, SIDE, E_MOD = 1.0, 0.01, 1.0e7
EI = E_MOD * SIDE**4 / 12
Q0 = 4.0 * EI / LENGTH**3                       # q0 L^3 / EI = 4: tip rotation of about 60 deg


def elastica(q, *, follower: bool):
    """Tip (x, z) of the inextensible cantilever along x under the load q per unit length,
    downward at the reference, normal to the axis (``follower``) or fixed."""
    def rhs(s, y):
        x, z, th, nx, nz, m = y
        px, pz = (q * np.sin(th), -q * np.cos(th)) if follower else (0 * th, -q + 0 * th)
        return np.vstack([np.cos(th), np.sin(th), m / EI, -px, -pz, -(np.cos(th) * nz - np.sin(th) * nx)])

    def bc(y0, y1):
        return np.array([y0[0], y0[1], y0[2], y1[3], y1[4], y1[5]])
    s = np.linspace(0.0, LENGTH, 201)
    y = np.zeros((6, s.size))
    y[0] = s
    sol = solve_bvp(rhs, bc, s, y, tol=1e-10, max_nodes=100000)
    assert sol.success, sol.message
    return sol.y[0, -1], sol.y[1, -1]


def cantilever(*, follower: bool = True, n_elements: int = 8):
    X, conn = line_mesh([0, 0, 0], [LENGTH, 0, 0], n_elements=n_elements)
    s = Structure(points=X, dofs=6)
    beam = BeamElement(BeamSet(conn=conn, section=BeamSection.rectangle(a=SIDE, b=SIDE), E=E_MOD, nu=0.0, rho=0.0,
                               v1=[0, 1, 0]), s.dofmap, X=X)
    s.add(beam)
    s.fix([0], "all")
    s.line_load(beam, (0.0, 0.0, -Q0), follower=follower)
    return s, X.shape[1] - 1


def test_cantilever_under_a_follower_normal_load_follows_the_elastica():
    s, tip = cantilever()
    path = s.solve(steps=8).check()
    for st in path[2::2]:
        x, z = elastica(st.lam * Q0, follower=True)
        assert st.x[0, tip] == pytest.approx(x, abs=2e-4 * LENGTH)
        assert st.x[2, tip] == pytest.approx(z, abs=2e-4 * LENGTH)
    # consistent load stiffness: Newton converges quadratically on every step
    assert np.all(path.iterations[1:] <= 6)
    # the dead load of the same size bends the beam differently (0.048 L, 100 times the tolerance)
    xd, zd = elastica(Q0, follower=False)
    assert np.hypot(path[-1].x[0, tip] - xd, path[-1].x[2, tip] - zd) > 0.03 * LENGTH
    dead, _ = cantilever(follower=False)
    end = dead.solve(steps=8).check()[-1]
    assert end.x[0, tip] == pytest.approx(xd, abs=2e-4 * LENGTH) and end.x[2, tip] == pytest.approx(zd, abs=2e-4)


def test_follower_load_stiffness_equals_finite_differences():
    # a curved two-element beam in a deformed, rotated state
    t = np.linspace(0.0, 1.2, 7)
    X = np.vstack([np.cos(t), np.sin(t), 0.3 * t])
    s = Structure(points=X, dofs=6)
    conn = np.array([[0, 3], [1, 4], [2, 5], [3, 6]])
    ld = BeamFollowerLoad(lines=conn, dofmap=s.dofmap, q=(0.3, -1.0, 2.0))
    rng = np.random.default_rng(3)
    st = State.reference(X, s.dofmap).advanced(0.2 * rng.standard_normal(s.dofmap.ndof), s.dofmap)
    f, K = ld.load(st)
    K = K.toarray()
    eps = 1e-6
    for j in range(s.dofmap.ndof):
        d = np.zeros(s.dofmap.ndof)
        d[j] = eps
        fd = (ld.load(st.advanced(d, s.dofmap), tangent=False)[0]
              - ld.load(st.advanced(-d, s.dofmap), tangent=False)[0]) / (2 * eps)
        np.testing.assert_allclose(K[:, j], fd, atol=1e-7 * np.abs(K).max())


def test_follower_load_on_beams_refuses_bad_input():
    s, _ = cantilever()
    with pytest.raises(InputError, match="3 components"):
        s.line_load(s.elements[0], 5.0, follower=True)
    X = np.vstack([np.linspace(0, 1, 4), np.zeros(4), np.zeros(4)])
    t = Structure(points=X, dofs=3)
    with pytest.raises(InputError, match="six dofs"):
        BeamFollowerLoad(lines=np.arange(4)[:, None], dofmap=t.dofmap, q=(0, 0, 1.0))
