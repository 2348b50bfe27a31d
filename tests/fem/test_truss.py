"""Two-node total-Lagrangian truss (tmfem.fem.truss, dissertation 4.3.3, eqs. 4.23-4.24)."""
import numpy as np
import pytest
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.truss import TrussSet, truss_internal, truss_mass


def rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    Kx = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * Kx + (1 - np.cos(angle)) * Kx @ Kx


def random_net(rng, nn=7, ne=12, tension_only=False):
    x0 = rng.normal(size=(3, nn))
    conn = np.array([(i, j) for i in range(nn) for j in range(i + 1, nn)]).T
    conn = conn[:, rng.choice(conn.shape[1], ne, replace=False)]
    L = np.linalg.norm(x0[:, conn[1]] - x0[:, conn[0]], axis=0)
    return x0, TrussSet(conn=conn, L=L, EA=rng.uniform(1e3, 1e4, ne), rhoA=rng.uniform(0.1, 1, ne),
                        tension_only=np.full(ne, tension_only))


def test_single_bar_closed_form():
    # source: closed form of the module docstring; E = (l^2 - L^2)/(2L^2), N = EA E l / L
    L, EA, l = 2.0, 1.0e5, 2.1
    ts = TrussSet(conn=[[0], [1]], L=[L], EA=[EA], rhoA=[1.0], tension_only=[True])
    x = np.array([[0.0, l * 0.6], [0.0, l * 0.8], [0.0, 0.0]])
    r = truss_internal(x, ts)
    E = (l**2 - L**2) / (2 * L**2)
    assert r.strain[0] == pytest.approx(E, rel=1e-14)
    assert r.N[0] == pytest.approx(EA * E * l / L, rel=1e-14)
    assert not r.slack[0]
    np.testing.assert_allclose(r.f[3:6], r.N[0] * np.array([0.6, 0.8, 0.0]), rtol=1e-13)
    np.testing.assert_allclose(r.f[0:3], -r.f[3:6], rtol=1e-13)
    # axial stiffness of the tangent: d N / d l along the bar = EA (3 l^2 - L^2) / (2 L^3)
    e = np.array([0.6, 0.8, 0.0])
    assert e @ r.K.toarray()[3:6, 3:6] @ e == pytest.approx(EA * (3 * l**2 - L**2) / (2 * L**3), rel=1e-12)


@pytest.mark.parametrize("tension_only", [False, True])
def test_tangent_matches_finite_differences(tension_only):
    # source: independent formulation -- central differences of the residual
    rng = np.random.default_rng(1)
    x0, ts = random_net(rng, tension_only=tension_only)
    ts.L = ts.L * rng.uniform(0.9, 1.1, ts.ne)     # mixed tension/compression
    x = x0 + 0.05 * rng.normal(size=x0.shape)
    r = truss_internal(x, ts)
    K = r.K.toarray()
    assert np.allclose(K, K.T, atol=1e-9 * abs(K).max())
    eps = 1e-6
    for _ in range(4):
        v = rng.normal(size=x.size)
        V = v.reshape(-1, 3).T
        fp = truss_internal(x + eps * V, ts, tangent=False).f
        fm = truss_internal(x - eps * V, ts, tangent=False).f
        fd = (fp - fm) / (2 * eps)
        np.testing.assert_allclose(K @ v, fd, atol=1e-6 * abs(fd).max())
    if tension_only:
        assert r.slack.any() and (~r.slack).any()   # both regimes exercised


def test_initial_stress_part_is_the_string_stiffness():
    # source: closed form -- a taut string of tension T has transverse stiffness T/l per unit
    # displacement (K_NL = (EA E / L) I = (N / l) I)
    L, EA = 1.0, 1e4
    ts = TrussSet(conn=[[0], [1]], L=[L], EA=[EA], rhoA=[1.0], tension_only=[True])
    x = np.array([[0.0, 1.05], [0.0, 0.0], [0.0, 0.0]])
    r = truss_internal(x, ts)
    K = r.K.toarray()
    assert K[4, 4] == pytest.approx(r.N[0] / 1.05, rel=1e-13)
    assert K[5, 5] == pytest.approx(r.N[0] / 1.05, rel=1e-13)


def test_rigid_body_motion_gives_zero_residual():
    # source: objectivity of the Green-Lagrange strain -- a rigid motion of the rest state is
    # stress free, and a rigid motion of a stressed state rotates the nodal forces
    rng = np.random.default_rng(2)
    x0, ts = random_net(rng)
    R = rotation([1.0, 2.0, -0.5], 1.3)
    c = np.array([[3.0], [-1.0], [0.5]])
    x = R @ x0 + c
    r = truss_internal(x, ts)
    assert abs(r.f).max() < 1e-10 * ts.EA.max()
    np.testing.assert_allclose(r.strain, 0.0, atol=1e-13)
    xs = x0 * 1.02
    f_ref = truss_internal(xs, ts).f.reshape(-1, 3).T
    f_rot = truss_internal(R @ xs + c, ts).f.reshape(-1, 3).T
    np.testing.assert_allclose(f_rot, R @ f_ref, atol=1e-10 * abs(f_ref).max())


def test_tension_only_slack_and_compression_bar():
    # a tendon shorter than its rest length carries nothing; a bar (not tension-only) pushes
    x = np.array([[0.0, 0.9, 0.0, 0.9], [0.0, 0.0, 1.0, 1.0], [0.0, 0.0, 0.0, 0.0]])
    ts = TrussSet(conn=[[0, 2], [1, 3]], L=[1.0, 1.0], EA=[1e3, 1e3], rhoA=[1.0, 1.0],
                  tension_only=[True, False])
    r = truss_internal(x, ts)
    assert r.slack.tolist() == [True, False]
    assert r.N[0] == 0.0
    E = (0.81 - 1.0) / 2.0
    assert r.N[1] == pytest.approx(1e3 * E * 0.9, rel=1e-13) and r.N[1] < 0
    K = r.K.toarray()
    assert np.all(K[:6, :6] == 0.0) and np.all(r.f[:6] == 0.0)
    assert abs(K[6:, 6:]).max() > 0


def test_mass_consistent_and_lumped():
    # source: closed form -- total mass rho A L; consistent mass (rhoAL/6)[[2,1],[1,2]] gives the
    # exact kinetic energy of a linearly varying velocity: m (v1^2 + v1 v2 + v2^2) / 3
    rng = np.random.default_rng(3)
    x0, ts = random_net(rng)
    nn = x0.shape[1]
    m_tot = np.sum(ts.rhoA * ts.L)
    for lumped in (False, True):
        M = truss_mass(ts, nn, lumped=lumped)
        assert sp.issparse(M) and M.shape == (3 * nn, 3 * nn)
        ones_x = np.zeros(3 * nn)
        ones_x[0::3] = 1.0
        assert ones_x @ M @ ones_x == pytest.approx(m_tot, rel=1e-13)   # a zero matrix would fail
        assert np.count_nonzero(M @ ones_x) > 0
    M = truss_mass(ts, nn).toarray()
    one = TrussSet(conn=[[0], [1]], L=[2.0], EA=[1.0], rhoA=[3.0], tension_only=[False])
    Mo = truss_mass(one, 2).toarray()
    v = np.array([1.0, 0, 0, 4.0, 0, 0])
    assert v @ Mo @ v == pytest.approx(6.0 * (1 + 4 + 16) / 3, rel=1e-14)
    Ml = truss_mass(one, 2, lumped=True).toarray()
    assert np.count_nonzero(Ml - np.diag(np.diag(Ml))) == 0
    assert np.all(np.linalg.eigvalsh(M) > -1e-12)


def test_invalid_input_messages():
    with pytest.raises(InputError, match="rest lengths L > 0"):
        TrussSet(conn=[[0], [1]], L=[0.0], EA=[1.0], rhoA=[1.0], tension_only=[True])
    with pytest.raises(InputError, match="to itself"):
        TrussSet(conn=[[1], [1]], L=[1.0], EA=[1.0], rhoA=[1.0], tension_only=[True])
    ts = TrussSet(conn=[[0], [5]], L=[1.0], EA=[1.0], rhoA=[1.0], tension_only=[True])
    with pytest.raises(InputError, match="node indices < 3"):
        truss_internal(np.zeros((3, 3)), ts)
