"""Four-node total-Lagrangian beam (tmfem.fem.beam, eqs. 4.19-4.22).

Sources: central finite differences of the energy and of the residual under the same
exponential-map update the solvers use; rigid motions (zero strain by definition); linear
fields of the cubic interpolation (patch tests); closed forms of the Timoshenko cantilever
(delta = P L^3 / (3 EI) + P L / (kappa G A)), of torsion (phi = T L / (G J)), of the
total-Lagrangian bar (P = EA lam (lam^2 - 1) / 2, the truss of 4.3.3); Timoshenko &
Goodier's torsion table of rectangles (beta = J / (c e^3): 0.141, 0.229, 0.263, 0.281,
0.291, 0.312 at c/e = 1, 2, 3, 4, 5, 10); the simply supported Timoshenko beam (exact
modes sin(n pi x / L)) and the Euler-Bernoulli cantilever (cos bL cosh bL = -1).
"""
import numpy as np
import pytest
import scipy.sparse.linalg as spla
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from tmfem.errors import InputError
from tmfem.fem.beam import BeamElement, BeamSection, BeamSet, line_mesh, rectangle_torsion_constant
from tmfem.fem.constraints import ConstraintMap
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import State
from tmfem.solvers import lowest_modes
from tmfem.solvers.newton import newton

SECTIONS = [BeamSection.rectangle(a=0.3, b=0.2), BeamSection.circle(d=0.2)]


def _beam(X, conn, section, *, E=2e7, nu=0.3, rho=7.8e3, integration="reduced", v1=None):
    dm = DofMap(np.full(X.shape[1], 6))
    b = BeamSet(conn=conn, section=section, E=E, nu=nu, rho=rho, v1=v1)
    return BeamElement(b, dm, X=X, integration=integration), dm


def _curved():
    """Two elements on a curved, unevenly spaced axis (a general reference geometry)."""
    s = np.array([0.0, 0.3, 0.7, 1.0, 1.2, 1.55, 2.0])
    X = np.stack([s, 0.15 * s**2, 0.05 * s**3])
    return X, np.array([[0, 3], [1, 4], [2, 5], [3, 6]])


@pytest.mark.parametrize("section", SECTIONS, ids=["rectangle", "circle"])
@pytest.mark.parametrize("integration", ["reduced", "full"])
def test_force_and_tangent_match_finite_differences_at_large_rotations(section, integration):
    X, conn = _curved()
    be, dm = _beam(X, conn, section, E=2e3, integration=integration)
    rng = np.random.default_rng(3)
    s = State(x=X + 0.3 * rng.standard_normal(X.shape),
              R=Rotation.from_rotvec(1.5 * rng.standard_normal((X.shape[1], 3))).as_matrix())
    f, K = be.internal(s)
    K = K.toarray()
    eps = 1e-6
    Kfd, ffd = np.zeros_like(K), np.zeros_like(f)
    for j in range(dm.ndof):
        du = np.zeros(dm.ndof)
        du[j] = eps
        sp_, sm = s.advanced(du, dm), s.advanced(-du, dm)
        Kfd[:, j] = (be.internal(sp_, tangent=False)[0] - be.internal(sm, tangent=False)[0]) / (2 * eps)
        ffd[j] = (be.energy(sp_) - be.energy(sm)) / (2 * eps)
    assert np.abs(f - ffd).max() <= 1e-8 * np.abs(f).max()
    assert np.abs(K - Kfd).max() <= 1e-8 * np.abs(K).max()
    # the finite-rotation tangent is not symmetric away from equilibrium; at the reference it is
    assert np.abs(K - K.T).max() > 1e-3 * np.abs(K).max()
    K0 = be.internal(State.reference(X, dm))[1].toarray()
    assert np.abs(K0 - K0.T).max() <= 1e-12 * np.abs(K0).max()


@pytest.mark.parametrize("section", SECTIONS, ids=["rectangle", "circle"])
def test_rigid_motions_with_large_rotations_give_zero_strain_and_force(section):
    X, conn = _curved()
    be, dm = _beam(X, conn, section)
    Q = Rotation.from_rotvec([0.7, -1.9, 2.2]).as_matrix()          # 3.0 rad
    s = State(x=Q @ X + np.array([[1.0], [-2.0], [3.0]]), R=np.broadcast_to(Q, (X.shape[1], 3, 3)).copy())
    scale = np.abs(be.internal(State.reference(X, dm).advanced(np.full(dm.ndof, 1e-3), dm))[0]).max()
    assert np.abs(be.strains(s)).max() < 1e-14
    assert np.abs(be.internal(s)[0]).max() < 1e-10 * scale
    assert be.energy(s) == pytest.approx(0.0, abs=1e-20)
    # a single element has exactly six zero-energy modes (3-point rule: no spurious mode)
    X1, c1 = line_mesh([0, 0, 0], [1.0, 0.5, 0.2], n_elements=1)
    for integration in ("reduced", "full"):
        be1, dm1 = _beam(X1, c1, section, integration=integration)
        ev = np.linalg.eigvalsh(be1.internal(State.reference(X1, dm1))[1].toarray())
        assert np.sum(np.abs(ev) < 1e-9 * ev.max()) == 6


def _linear_solve(be, dm, X, fixed, load):
    K = be.internal(State.reference(X, dm))[1].tocsc()
    free = np.ones(dm.ndof, bool)
    free[fixed] = False
    u = np.zeros(dm.ndof)
    u[free] = spla.spsolve(K[free][:, free], load[free])
    return u, K


@pytest.mark.parametrize("section", SECTIONS, ids=["rectangle", "circle"])
def test_patch_tests_linear_fields_carry_forces_only_at_the_ends(section):
    """Constant axial strain and twist (fields linear in x) on unevenly spaced nodes,
    constant curvature (w = kappa x^2 / 2) on equally spaced elements of unequal lengths:
    the linear tangent times the field is zero at every interior node and equals the
    section forces EA eps, G J phi', EI kappa at the ends. (Constant transverse shear is
    no patch state: it needs a linearly varying moment.)"""
    E, nu = 2e7, 0.3
    G = E / (2 * (1 + nu))
    s = np.array([0.0, 0.3, 0.62, 1.0, 1.5, 1.9, 2.6])
    X = np.stack([s, np.zeros_like(s), np.zeros_like(s)])
    conn = np.array([[0, 3], [1, 4], [2, 5], [3, 6]])
    be, dm = _beam(X, conn, section, E=E, nu=nu)
    K = be.internal(State.reference(X, dm))[1]
    x = X[0]
    n = X.shape[1]
    for field, dof, end_force in [("axial", 0, E * section.A), ("twist", 3, G * section.J)]:
        u = np.zeros((n, 6))
        u[:, dof] = 1e-3 * x
        f = (K @ u.ravel()).reshape(n, 6)
        assert np.abs(f[1:-1]).max() < 1e-9 * end_force * 1e-3, field
        assert f[-1, dof] == pytest.approx(end_force * 1e-3, rel=1e-10), field
        assert f[0, dof] == pytest.approx(-end_force * 1e-3, rel=1e-10), field
    # constant curvature on equal spacing within elements: w = k x^2 / 2, rotation about -y = k x
    s = np.concatenate([np.linspace(0.0, 0.9, 4), np.linspace(0.9, 2.4, 4)[1:]])
    X = np.stack([s, np.zeros_like(s), np.zeros_like(s)])
    be, dm = _beam(X, conn, section, E=E, nu=nu)
    K = be.internal(State.reference(X, dm))[1]
    k = 1e-3
    u = np.zeros((n, 6))
    u[:, 2], u[:, 4] = 0.5 * k * s**2, -k * s
    f = (K @ u.ravel()).reshape(n, 6)
    M = E * section.I_s * k
    assert np.abs(f[1:-1]).max() < 1e-9 * M
    assert f[-1, 4] == pytest.approx(-M, rel=1e-10) and f[0, 4] == pytest.approx(M, rel=1e-10)


@pytest.mark.parametrize("section", SECTIONS, ids=["rectangle", "circle"])
@pytest.mark.parametrize("n_elements", [1, 4])
@pytest.mark.parametrize("integration", ["reduced", "full"])
def test_cantilever_closed_forms(section, n_elements, integration):
    """Tip load, torque and axial load on a cantilever along an oblique axis: Timoshenko
    deflection, St.Venant twist and axial stretch, exact for one element as for four."""
    E, nu, L = 2e7, 0.3, 2.0
    G = E / (2 * (1 + nu))
    t = np.array([1.0, 2.0, 2.0]) / 3.0
    X, conn = line_mesh([0.0, 0.0, 0.0], L * t, n_elements=n_elements)
    be, dm = _beam(X, conn, section, E=E, nu=nu, integration=integration)
    T = be.triads[0, 0]                                              # [t D1 D2]
    tip = dm.node_dofs([X.shape[1] - 1])[0]
    load = np.zeros(dm.ndof)
    load[tip[:3]] += 1.0 * T[:, 2] + 2.0 * T[:, 0]                   # P along D2, N along t
    load[tip[3:]] += 3.0 * T[:, 0]                                   # torque about t
    u, _ = _linear_solve(be, dm, X, np.arange(6), load)
    kap = section.shear_coefficient(nu)
    w = u[tip[:3]] @ T[:, 2]
    assert w == pytest.approx(L**3 / (3 * E * section.I_s) + L / (kap * G * section.A), rel=1e-10)
    assert u[tip[3:]] @ T[:, 0] == pytest.approx(3.0 * L / (G * section.J), rel=1e-10)
    assert u[tip[:3]] @ T[:, 0] == pytest.approx(2.0 * L / (E * section.A), rel=1e-10)
    # section resultants at the Gauss points (a 1e-3 fraction of the load: linear range)
    st = State.reference(X, dm).advanced(1e-3 * u, dm)
    sf = be.section_forces(st)
    xi = np.einsum("ieg,i->eg", be.gauss_points(), t)                # arc length of the points
    np.testing.assert_allclose(sf["M1"], -1e-3 * (L - xi), rtol=1e-5, atol=1e-9)
    np.testing.assert_allclose(sf["T"], 3e-3, rtol=1e-5)
    np.testing.assert_allclose(sf["N"], 2e-3, rtol=1e-3)                  # + EA w'^2/2: 3e-4
    np.testing.assert_allclose(sf["Q2"], 1e-3, rtol=1e-5)


def test_large_stretch_follows_the_total_lagrangian_bar():
    """P = EA lam (lam^2 - 1) / 2 at a 50 % stretch (Green strain, first Piola force)."""
    sec = BeamSection.circle(d=0.1)
    E, L = 1e6, 3.0
    X, conn = line_mesh([0, 0, 0], [L, 0, 0], n_elements=2)
    be, dm = _beam(X, conn, sec, E=E, nu=0.0)
    lam = 1.5
    P = E * sec.A * lam * (lam**2 - 1) / 2
    cm = ConstraintMap.build(dm, fixed_dofs=dm.node_dofs([0]).ravel())
    fext = np.zeros(dm.ndof)
    fext[dm.node_dofs([X.shape[1] - 1])[0, 0]] = P
    res = newton(lambda s: (cm.residual(be.internal(s)[0] - fext), cm.tangent(be.internal(s)[1])),
                 State.reference(X, dm), free=cm.free, tol=1e-12, line_search=False,
                 update=lambda s, du: s.advanced(cm.full(du), dm))
    assert res.converged
    assert res.u.x[0, -1] == pytest.approx(lam * L, rel=1e-10)
    assert np.allclose(be.section_forces(res.u)["N"], E * sec.A * (lam**2 - 1) / 2, rtol=1e-10)


@pytest.mark.parametrize("ratio, beta", [(1, 0.141), (2, 0.229), (3, 0.263), (4, 0.281), (5, 0.291),
                                         (10, 0.312)])
def test_rectangle_torsion_constant_matches_the_table(ratio, beta):
    assert rectangle_torsion_constant(ratio * 0.1, 0.1) / (ratio * 0.1 * 0.1**3) == pytest.approx(beta, abs=6e-4)
    assert rectangle_torsion_constant(0.1, ratio * 0.1) == rectangle_torsion_constant(ratio * 0.1, 0.1)


def _ss_timoshenko(n, *, L, E, G, rho, A, I, kappa):
    """Exact omega of mode n of the simply supported Timoshenko beam (w = W sin kx,
    theta = Theta cos kx): det [[kGA k^2 - rho A w2, -kGA k], [-kGA k, EI k^2 + kGA - rho I w2]] = 0."""
    k = n * np.pi / L
    kGA = kappa * G * A
    a = rho * A * rho * I
    b = -(rho * A * (E * I * k**2 + kGA) + rho * I * kGA * k**2)
    c = kGA * k**2 * (E * I * k**2 + kGA) - (kGA * k) ** 2
    return np.sqrt((-b - np.sqrt(b * b - 4 * a * c)) / (2 * a))


def test_simply_supported_modes_match_timoshenko():
    E, nu, rho, L = 2.1e11, 0.3, 7850.0, 4.0
    G = E / (2 * (1 + nu))
    sec = BeamSection.rectangle(a=0.15, b=0.1)
    X, conn = line_mesh([0, 0, 0], [L, 0, 0], n_elements=10)
    be, dm = _beam(X, conn, sec, E=E, nu=nu, rho=rho)
    n = X.shape[1]
    fixed = list(dm.translation_dofs([0, n - 1]).ravel()) + [dm.rotation_dofs([0])[0, 0]]
    free = np.ones(dm.ndof, bool)
    free[fixed] = False
    K = be.internal(State.reference(X, dm))[1]
    modes = lowest_modes(K, be.mass(), k=6, free=free)
    kap = sec.shear_coefficient(nu)
    exact = [_ss_timoshenko(m, L=L, E=E, G=G, rho=rho, A=sec.A, I=I, kappa=kap)
             for m in (1, 2, 3) for I in (sec.I_s, sec.I_t)]
    # the first torsion mode, fixed (theta_x at x = 0) - free: omega = pi/(2L) sqrt(G J / (rho I_p))
    exact.append(np.pi / (2 * L) * np.sqrt(G * sec.J / (rho * sec.I_p)))
    np.testing.assert_allclose(modes.omega, sorted(exact)[:6], rtol=5e-5)


def test_cantilever_modes_match_euler_bernoulli():
    E, rho, L, d = 7e10, 2700.0, 5.0, 0.025                          # L / d = 200
    sec = BeamSection.circle(d=d)
    X, conn = line_mesh([0, 0, 0], [0, 0, L], n_elements=8)
    be, dm = _beam(X, conn, sec, E=E, nu=0.33, rho=rho)
    free = np.ones(dm.ndof, bool)
    free[:6] = False
    modes = lowest_modes(be.internal(State.reference(X, dm))[1], be.mass(), k=6, free=free)
    roots = [brentq(lambda b: np.cos(b) * np.cosh(b) + 1, lo, lo + 1.5) for lo in (1.0, 4.0, 7.0)]
    exact = np.repeat([(b / L) ** 2 * np.sqrt(E * sec.I_s / (rho * sec.A)) for b in roots], 2)
    np.testing.assert_allclose(modes.omega, exact, rtol=1e-3)


def test_mass_is_consistent_and_carries_rotary_inertia():
    """Total mass rho A L on each translation; rotary inertia rho I_p L about the axis,
    rho I_t L about V2 and rho I_s L about V1 (rigid rotation of the whole beam)."""
    sec = BeamSection.rectangle(a=0.2, b=0.1)
    rho, L = 1000.0, 3.0
    X, conn = line_mesh([0, 0, 0], [0, L, 0], n_elements=3)
    be, dm = _beam(X, conn, sec, rho=rho)
    M = be.mass()
    n = X.shape[1]
    # axis e_y: V1 = e_z (the e_y-parallel rule of eq. 4.16), V2 = e_y x e_z = e_x
    assert np.allclose(be.triads[0, 0], [[0, 0, 1], [1, 0, 0], [0, 1, 0]])
    for comp, expected in [(0, rho * sec.A * L), (1, rho * sec.A * L), (4, rho * sec.I_p * L),
                           (3, rho * sec.I_t * L), (5, rho * sec.I_s * L)]:
        v = np.zeros((n, 6))
        v[:, comp] = 1.0
        assert v.ravel() @ M @ v.ravel() == pytest.approx(expected, rel=1e-12)
    ev = np.linalg.eigvalsh(M.toarray())
    assert ev.min() > 0


def test_bad_input_is_refused():
    X, conn = line_mesh([0, 0, 0], [1, 0, 0], n_elements=1)
    with pytest.raises(InputError, match="six dofs"):
        BeamElement(BeamSet(conn=conn, section=SECTIONS[0], E=1.0, nu=0.0, rho=1.0), DofMap([6, 3, 6, 6]), X=X)
    with pytest.raises(InputError, match="integration"):
        _beam(X, conn, SECTIONS[0], integration="selective")
    with pytest.raises(InputError, match="not parallel"):
        _beam(X, conn, SECTIONS[0], v1=[2.0, 0, 0])
    with pytest.raises(InputError, match="b > 0"):
        BeamSection.rectangle(a=1.0, b=0.0)
    with pytest.raises(InputError, match="repeats a node"):
        BeamSet(conn=np.array([[0], [1], [1], [2]]), section=SECTIONS[0], E=1.0, nu=0.0, rho=1.0)
    with pytest.raises(InputError, match="folding back"):
        _beam(np.array([[0.0, 0.2, 0.75, 1.0], [0, 0, 0, 0], [0, 0, 0, 0]]), conn, SECTIONS[0])
    with pytest.raises(InputError, match="degenerate axis"):
        _beam(np.zeros((3, 4)), conn, SECTIONS[0])


def _quarter_ring_tip(n_elements, integration, *, h):
    """Tip deflection of a quarter ring (R = 1) clamped at its top, tangential tip load P = 1."""
    E, nu, R = 1e7, 0.3, 1.0
    phi = np.linspace(0.0, np.pi / 2, 3 * n_elements + 1)
    X = np.stack([R * np.sin(phi), np.zeros_like(phi), R * np.cos(phi)])
    conn = 3 * np.arange(n_elements)[None, :] + np.arange(4)[:, None]
    sec = BeamSection.rectangle(a=h, b=h)
    be, dm = _beam(X, conn, sec, E=E, nu=nu, integration=integration, v1=[0, 1, 0])
    load = np.zeros(dm.ndof)
    tip = dm.node_dofs([X.shape[1] - 1])[0]
    load[tip[2]] = 1.0
    u, _ = _linear_solve(be, dm, X, np.arange(6), load)
    return u[tip[2]], (3 * np.pi / 4 - 2) * R**3 / (E * sec.I_s)


def test_curved_beam_reduced_integration_avoids_membrane_locking():
    """Quarter ring, h/R = 1e-3, tangential tip load: the inextensible closed form
    delta = (3 pi / 4 - 2) P R^3 / EI (Castigliano, M = P R (1 - sin phi)). Reduced
    integration (the dissertation's choice, 4.3.2) is within 0.1 % on 4 curved elements and
    1 % on one; full integration locks (membrane locking of the curved element: about 61 %
    of the deflection on one element)."""
    w4, exact = _quarter_ring_tip(4, "reduced", h=1e-3)
    assert w4 == pytest.approx(exact, rel=1e-3)
    w1, _ = _quarter_ring_tip(1, "reduced", h=1e-3)
    assert w1 == pytest.approx(exact, rel=1e-2)
    w1_full, _ = _quarter_ring_tip(1, "full", h=1e-3)
    assert w1_full < 0.7 * exact
