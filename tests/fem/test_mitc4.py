"""MITC4 shell element checks.

Sources: finite differences of the residual (tangent) and of the strain energy (internal
force); rigid-body motions (zero strain, zero residual); the constant-strain and
constant-curvature patch tests (exact linear fields); beam theory for a single element
(u = P L/(E A), tip rotation M L/(E I)); the mass of the plate rho h A and its rotary inertia
rho h^3 A/12; Kirchhoff's simply supported plate (w_c = 0.00406 q a^4/D, Timoshenko &
Woinowsky-Krieger Table 8; f_11 = (pi/a^2) sqrt(D/(rho h)) ... per mode (m, n)).
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from skfem import MeshQuad

from tmfem.errors import InputError
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import State
from tmfem.fem.mitc4 import MITC4Shell, ShellPressure, ShellSection, director_frames
from tmfem.fem.structure import Structure


def _curved_patch(nx=3, ny=2, seed=0):
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 0.7, ny + 1), indexing="ij")
    xs = xs + 0.04 * rng.standard_normal(xs.shape)
    X = np.vstack([xs.ravel(), ys.ravel(), 0.2 * xs.ravel() ** 2 + 0.1 * ys.ravel()])
    idx = np.arange((nx + 1) * (ny + 1)).reshape(nx + 1, ny + 1)
    conn = np.array([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    return X, conn


def _shell(X, conn, shear="mitc", **kw):
    dm = DofMap(np.full(X.shape[1], 5))
    sec = ShellSection(**{"E": 1e3, "nu": 0.3, "thickness": 0.05, "rho": 2.0, **kw})
    sh = MITC4Shell(X=X, conn=conn, section=sec, dofmap=dm, shear=shear)
    return sh, dm, State.reference(X, dm, frames=sh.frames)


def _fd_tangent(fun, s, dm, eps=1e-6):
    cols = []
    for j in range(dm.ndof):
        e = np.zeros(dm.ndof)
        e[j] = eps
        cols.append((fun(s.advanced(e, dm)) - fun(s.advanced(-e, dm))) / (2 * eps))
    return np.array(cols).T


def _large_state(s, dm, seed=1, scale=0.1, rot=1.0):
    rng = np.random.default_rng(seed)
    du = scale * rng.standard_normal(dm.ndof)
    du[dm.rotation_dofs(np.arange(dm.n_nodes))] = rot * rng.standard_normal((dm.n_nodes, 2))
    return s.advanced(du, dm)


@pytest.mark.parametrize("shear", ["mitc", "direct"])
def test_tangent_is_the_derivative_of_the_residual_at_large_rotations(shear):
    X, conn = _curved_patch()
    sh, dm, s0 = _shell(X, conn, shear=shear)
    s = _large_state(s0, dm)                     # rotations of about 1 rad per node
    f, K = sh.internal(s)
    Kfd = _fd_tangent(lambda t: sh.internal(t, tangent=False)[0], s, dm)
    K = K.toarray()
    assert np.abs(K - Kfd).max() <= 1e-7 * np.abs(K).max()
    assert np.abs(K - K.T).max() <= 1e-12 * np.abs(K).max()   # rotations about V1, V2: symmetric


def test_internal_force_is_the_gradient_of_the_strain_energy():
    X, conn = _curved_patch(seed=3)
    sh, dm, s0 = _shell(X, conn)
    s = _large_state(s0, dm, seed=4)
    f, _ = sh.internal(s, tangent=False)
    g = _fd_tangent(lambda t: np.array([sh.energy(t)]), s, dm)[0]
    assert np.abs(g - f).max() <= 1e-7 * np.abs(f).max()


def test_rigid_body_motion_gives_zero_strain_and_residual():
    X, conn = _curved_patch()
    sh, dm, s0 = _shell(X, conn)
    f_ref = np.abs(sh.internal(_large_state(s0, dm), tangent=False)[0]).max()
    for rv in ([1.0, -2.0, 0.7], [0.0, np.pi - 1e-3, 0.0], [2.5, 0.3, -0.4]):
        Rr = Rotation.from_rotvec(rv).as_matrix()
        s = State(x=Rr @ X + np.array([[3.0], [1.0], [-2.0]]), R=np.broadcast_to(Rr, (dm.n_nodes, 3, 3)).copy(),
                  frames=sh.frames)
        f, _ = sh.internal(s, tangent=False)
        assert np.abs(f).max() <= 1e-12 * f_ref
        assert sh.energy(s) <= 1e-24 * f_ref


def _distorted_plate(L=2.0, b=1.0, nx=4, ny=2):
    m = MeshQuad.init_tensor(np.linspace(0, L, nx + 1), np.linspace(0, b, ny + 1))
    p = m.p.copy()
    inner = (p[0] > 0) & (p[0] < L)
    rng = np.random.default_rng(7)
    p[0, inner] += 0.15 * L / nx * rng.uniform(-1, 1, inner.sum())
    mid = inner & (p[1] > 0) & (p[1] < b)
    p[1, mid] += 0.15 * b / ny * rng.uniform(-1, 1, mid.sum())
    return p, m.t


def test_membrane_patch_test_on_a_distorted_mesh():
    """Boundary displacements of a constant strain field: every node exact, N constant."""
    p, t = _distorted_plate()
    s = Structure.shell((p, t), section=ShellSection(E=2e5, nu=0.3, thickness=0.01))
    ex, ey, gxy = 1e-4, -2e-4, 3e-4
    boundary = s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(x, 2) | np.isclose(y, 0) | np.isclose(y, 1))
    for n in boundary:
        x, y = s.X[:2, n]
        s.prescribe([n], "ux", ex * x + 0.5 * gxy * y)
        s.prescribe([n], "uy", ey * y + 0.5 * gxy * x)
        s.prescribe([n], "uz", 0.0)
    st = s.solve_linear()
    u = s.displacements(st)
    x, y = s.X[:2]
    assert np.allclose(u[0], ex * x + 0.5 * gxy * y, atol=1e-12)
    assert np.allclose(u[1], ey * y + 0.5 * gxy * x, atol=1e-12)
    N = s.shells[0].stresses(st.state)["N"]
    c = 2e5 * 0.01 / (1 - 0.09)
    # Green-Lagrange strain of the linear field F = I + H: E = (H + H^T + H^T H) / 2
    H = np.array([[ex, gxy / 2], [gxy / 2, ey]])
    Eg = 0.5 * (H + H.T + H.T @ H)
    ex, ey, gxy = Eg[0, 0], Eg[1, 1], 2 * Eg[0, 1]
    # results frame of eq. 4.16: e1 = -x, e2 = y for the director -z (init_tensor is clockwise)
    assert np.allclose(N[:, 0], c * (ex + 0.3 * ey), rtol=1e-6)
    assert np.allclose(N[:, 1], c * (ey + 0.3 * ex), rtol=1e-6)
    assert np.allclose(N[:, 2], -2e5 / 2.6 * 0.01 * gxy, rtol=1e-6)


def test_bending_patch_and_single_element_beam_closed_forms():
    """Cantilever plate (nu = 0) with an end moment and with an end force: tip rotation
    M L / EI on a distorted mesh (constant curvature, exact), and u = P L / (E A)."""
    for p, t in (_distorted_plate(), (np.array([[0, 2, 2, 0], [0, 0, 1, 1.0]]), np.array([[0], [1], [2], [3]]))):
        s = Structure.shell((p, t), section=ShellSection(E=1e4, nu=0.0, thickness=0.02))
        root = s.nodes_where(lambda x, y, z: np.isclose(x, 0))
        tip = s.nodes_where(lambda x, y, z: np.isclose(x, 2))
        s.fix(root)
        M, P = 1e-4, 3.0
        ny = tip.size - 1
        w = np.full(tip.size, 1.0 / ny)
        w[[0, -1]] = 0.5 / ny                        # consistent edge weights (uniform spacing)
        for n, wi in zip(tip, w):
            s.point_load([n], moment=(0.0, M * wi, 0.0), force=(P * wi, 0, 0))
        st = s.solve_linear()
        EI, EA = 1e4 * 1.0 * 0.02**3 / 12, 1e4 * 0.02
        rot = s.rotation_vectors(st)[1, tip]
        assert np.allclose(np.abs(rot), M * 2.0 / EI, rtol=1e-8)
        assert np.allclose(s.displacements(st)[0, tip], P * 2.0 / EA, rtol=1e-8)


def test_mass_translation_and_rotary_inertia():
    X = np.array([[0, 2, 2, 0], [0, 0, 1, 1.0], [0, 0, 0, 0]])
    sh, dm, _ = _shell(X, np.array([[0], [1], [2], [3]]), rho=7.0, thickness=0.1)
    M = sh.mass()
    v = np.zeros(dm.ndof)
    v[dm.translation_dofs(np.arange(4))[:, 2]] = 1.0
    assert v @ M @ v == pytest.approx(7.0 * 0.1 * 2.0, rel=1e-12)
    r = np.zeros(dm.ndof)
    r[dm.rotation_dofs(np.arange(4))[:, 0]] = 1.0
    assert r @ M @ r == pytest.approx(7.0 * 0.1**3 / 12 * 2.0, rel=1e-12)


def test_pressure_total_force_and_follower_load_stiffness():
    X, conn = _curved_patch()
    dm = DofMap(np.full(X.shape[1], 5))
    sh = MITC4Shell(X=X, conn=conn, section=ShellSection(E=1.0, nu=0.0, thickness=0.1), dofmap=dm)
    s0 = State.reference(X, dm, frames=sh.frames)
    flat = np.array([[0, 3, 3, 0], [0, 0, 2, 2.0], [0, 0, 0, 0]])
    dmf = DofMap(np.full(4, 5))
    f, _ = ShellPressure(X=flat, conn=np.array([[0], [1], [2], [3]]), dofmap=dmf, p=2.0, follower=False).load(None)
    assert f[dmf.translation_dofs(np.arange(4))].sum(axis=0) == pytest.approx([0, 0, 12.0])
    pl = ShellPressure(X=X, conn=conn, dofmap=dm, p=3.0, follower=True)
    s = _large_state(s0, dm, seed=5)
    _, K = pl.load(s)
    Kfd = _fd_tangent(lambda t: pl.load(t, tangent=False)[0], s, dm)
    assert np.abs(K.toarray() - Kfd).max() <= 1e-7 * np.abs(Kfd).max()
    with pytest.raises(InputError, match="no potential"):
        pl.energy(s)


def test_director_frames_eq_4_16_including_the_e_y_parallel_case():
    F = director_frames(np.array([[0, 0, 0.0], [0, 1, -1.0], [1, 0, 0.0]]))
    assert np.allclose(F[0], np.eye(3))                               # V1 = e_y x e_z = e_x
    assert np.allclose(F[1][:, 0], [0, 0, 1]) and np.allclose(F[2][:, 0], [0, 0, 1])   # V1 = e_z
    for f in F:
        assert np.allclose(f.T @ f, np.eye(3)) and np.linalg.det(f) == pytest.approx(1.0)


def _ss_plate_ratio(thickness, shear="mitc"):
    a, n, E, nu, q = 2.0, 16, 1e9, 0.3, 1.0
    xs = np.linspace(0, a, n + 1)
    s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=E, nu=nu, thickness=thickness),
                        shear=shear)
    edge = s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(x, a) | np.isclose(y, 0) | np.isclose(y, a))
    s.fix(edge, "uz")
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) & np.isclose(y, 0)), ["ux", "uy"])
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, a) & np.isclose(y, 0)), "uy")
    s.pressure(q, follower=False)
    c = int(s.nodes_where(lambda x, y, z: np.isclose(x, a / 2) & np.isclose(y, a / 2))[0])
    w = abs(s.displacements(s.solve_linear())[2, c])
    D = E * thickness**3 / (12 * (1 - nu**2))
    return w / (0.00406235 * q * a**4 / D)


@pytest.mark.parametrize("thickness", [1e-2, 5e-5])
def test_thin_plate_has_no_shear_locking(thickness):
    """Simply supported square plate under pressure, linear: w_c = 0.00406 q a^4 / D (Kirchhoff),
    also at h/a = 2.5e-5 (the dissertation's membrane); 16 x 16 full plate. Without the MITC
    tying (shear at the Gauss points) the element locks: w/w_Kirchhoff ~ (h/l)^2."""
    assert _ss_plate_ratio(thickness) == pytest.approx(1.0, abs=0.01)
    if thickness < 1e-3:
        assert _ss_plate_ratio(thickness, shear="direct") < 1e-4


def test_simply_supported_plate_modes():
    """Lowest frequency of a simply supported square plate: omega_11 = 2 pi^2/a^2 sqrt(D/(rho h))."""
    a, n, E, nu, h, rho = 1.0, 12, 7e10, 0.3, 0.01, 2700.0
    xs = np.linspace(0, a, n + 1)
    s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=E, nu=nu, thickness=h, rho=rho))
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(x, a) | np.isclose(y, 0) | np.isclose(y, a)),
          ["ux", "uy", "uz"])
    m = s.modes(k=3)
    D = E * h**3 / (12 * (1 - nu**2))
    w11 = 2 * np.pi**2 / a**2 * np.sqrt(D / (rho * h))
    assert m.omega[0] == pytest.approx(w11, rel=0.02)
    assert m.omega[1] == pytest.approx(2.5 * w11, rel=0.04)      # (1, 2) and (2, 1): 5/2 of (1, 1)


def test_bad_input_is_refused_with_numbers():
    X, conn = _curved_patch()
    dm = DofMap(np.full(X.shape[1], 6))
    with pytest.raises(InputError, match="expected 5 dofs"):
        MITC4Shell(X=X, conn=conn, section=ShellSection(E=1, nu=0, thickness=1), dofmap=dm)
    with pytest.raises(InputError, match="thickness > 0"):
        ShellSection(E=1, nu=0, thickness=0.0)
    with pytest.raises(InputError, match="consistently oriented"):
        Structure.shell((X, np.column_stack([conn[:, :1], conn[::-1, 1:2]])),
                        section=ShellSection(E=1, nu=0, thickness=0.1))
    s = Structure.shell((X, conn), section=ShellSection(E=1, nu=0, thickness=0.1))
    with pytest.raises(InputError, match="expected names"):
        s.fix([0], "r3")
    with pytest.raises(InputError, match="loads or prescribed"):
        s.solve()
