"""Linear plane-stress membrane (tmfem.fem.plane_stress), eq. 5.8 and the corner loads of 3.2-3.3.

Sources of the reference numbers:
- patch test / equal-biaxial stretch: a linear displacement field is an exact solution of
  plane-stress elasticity with stress given by eq. 5.8 (closed form); bilinear quads
  reproduce it exactly on any mesh.
- boundary reactions: the consistent nodal loads of the traction sigma . n on the boundary
  (independent scikit-fem FacetBasis LinearForm), whose edge resultants are sigma . n h L.
- corner singularity: the Flamant wedge solution (point force P on the apex of a wedge of
  half angle alpha, along its bisector) has sigma_r = -P cos(t) / (h r (alpha + sin(alpha) cos(alpha))),
  so the apex displacement grows like P k ln(1/r) / (E h), k = 1 / (alpha + sin(alpha) cos(alpha)).
  With the mesh size ~ 1/n as cut-off, 1 / F_Delta is linear in ln n with slope k / (E h Delta).
"""
import numpy as np
import pytest

from tmfem.errors import InputError, SlackMembrane
from tmfem.fem.plane_stress import (PlaneStressMembrane, principal_stresses,
                                    symmetric_corner_force, von_mises)
from tmfem.system import MembraneMaterial, load_preset, membrane_corners_regular

KAPTON = MembraneMaterial(E=165e6, nu=0.34, rho=1400.0, h=51e-6)   # Table 6.1


def _impose_linear_field(m, G, c=(0.0, 0.0)):
    """Solve with u = G (x - c) prescribed on every boundary node; returns DOF vector, f = K x."""
    from skfem import condense, solve
    nd = m.basis.nodal_dofs
    p = m.mesh.p
    exact = G @ (p - np.asarray(c)[:, None])
    x = np.zeros(m.basis.N)
    x[nd] = exact
    D = m.basis.get_dofs().all()
    x = solve(*condense(m.K, np.zeros(m.basis.N), x=x, D=D))
    return x, exact


@pytest.mark.parametrize("N", [3, 4, 5])
def test_patch_test_constant_stress_is_exact_on_distorted_quads(N):
    # triangle and pentagon patches are meshed with non-parallelogram quads
    m = PlaneStressMembrane(corners=membrane_corners_regular(N, 1.3), material=KAPTON, n=4)
    G = np.array([[2e-3, 0.7e-3], [-0.3e-3, -1e-3]])
    x, exact = _impose_linear_field(m, G)
    np.testing.assert_allclose(x[m.basis.nodal_dofs], exact, atol=1e-15)
    s = m.stresses(x)
    E, nu = KAPTON.E, KAPTON.nu
    exx, eyy, exy = G[0, 0], G[1, 1], 0.5 * (G[0, 1] + G[1, 0])
    ref = [E / (1 - nu**2) * (exx + nu * eyy), E / (1 - nu**2) * (eyy + nu * exx), E / (1 + nu) * exy]
    for k in range(3):   # eq. 5.8
        np.testing.assert_allclose(s[k], ref[k], rtol=1e-10, atol=1e-9 * abs(ref[0]))


def test_boundary_reactions_equal_consistent_edge_loads_square():
    from skfem import FacetBasis, LinearForm, asm
    m = PlaneStressMembrane(corners=membrane_corners_regular(4, np.sqrt(2)), material=KAPTON, n=5)
    G = np.array([[1e-3, 0.4e-3], [0.4e-3, 2e-3]])
    x, _ = _impose_linear_field(m, G)
    sig = m.stresses(x)[:, 0, 0]
    S = np.array([[sig[0], sig[2]], [sig[2], sig[1]]])
    h = KAPTON.h
    fb = FacetBasis(m.skmesh, m.basis.elem)

    @LinearForm
    def traction(v, w):
        t = np.einsum("ab,b...->a...", S, w.n)
        return h * (t[0] * v[0] + t[1] * v[1])

    f_ref = asm(traction, fb)
    f = m.K @ x
    np.testing.assert_allclose(f, f_ref, atol=1e-10 * np.abs(f_ref).max())
    # resultant on each edge of the square [0,2]^2 (edge length 2): sigma . n h L; the corner
    # nodes split their reaction between two edges by the consistent loads, so compare the
    # total over the boundary half x = 2 excluding shared corners with the open-edge share
    p = m.mesh.p
    right = np.isclose(p[0], 2.0)
    corners = np.zeros(p.shape[1], bool)
    corners[m.mesh.corners] = True
    nd = m.basis.nodal_dofs
    open_edge = right & ~corners
    Lh = 2.0 / (2 * m.mesh.n)   # element edge length along the square side
    # open edge carries L - 2 * (Lh / 2) of the uniform traction
    np.testing.assert_allclose(f[nd[0, open_edge]].sum(), S[0, 0] * h * (2.0 - Lh), rtol=1e-10)
    np.testing.assert_allclose(f[nd[1, open_edge]].sum(), S[1, 0] * h * (2.0 - Lh), rtol=1e-10)


def test_equal_biaxial_stretch_closed_form():
    # u = eps (x - centre): sigma_xx = sigma_yy = E eps / (1 - nu), sigma_xy = 0; p1 = p2, vM = p1
    m = PlaneStressMembrane(corners=membrane_corners_regular(6, 2.0), material=KAPTON, n=3)
    eps = 1.5e-3
    x, _ = _impose_linear_field(m, eps * np.eye(2), c=m.corners.mean(axis=1))
    s = m.stresses(x)
    ref = KAPTON.E * eps / (1 - KAPTON.nu)
    np.testing.assert_allclose(s[0], ref, rtol=1e-10)
    np.testing.assert_allclose(s[1], ref, rtol=1e-10)
    np.testing.assert_allclose(s[2], 0.0, atol=1e-9 * ref)
    p = principal_stresses(s)
    np.testing.assert_allclose(p[:2], ref, rtol=1e-10)
    np.testing.assert_allclose(p[2], 0.0)
    np.testing.assert_allclose(von_mises(s), ref, rtol=1e-10)   # eq. 5.30 with p3 = 0


def test_von_mises_of_pure_shear_and_uniaxial():
    # closed forms: pure shear tau -> p = (tau, 0, -tau), vM = sqrt(3) tau; uniaxial s -> vM = s
    tau, s = 2.0, 3.0
    np.testing.assert_allclose(principal_stresses(np.array([0.0, 0.0, tau])), [tau, 0.0, -tau])
    assert von_mises(np.array([0.0, 0.0, tau])) == pytest.approx(np.sqrt(3) * tau)
    assert von_mises(np.array([s, 0.0, 0.0])) == pytest.approx(s)
    assert von_mises(np.array([-s, 0.0, 0.0])) == pytest.approx(s)


def test_stiffness_symmetric_psd_with_three_rigid_modes():
    m = PlaneStressMembrane(corners=membrane_corners_regular(3, 1.0), material=KAPTON, n=3)
    K = m.K.toarray()
    np.testing.assert_allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    ev = np.linalg.eigvalsh(K)
    tol = 1e-10 * ev[-1]
    assert np.sum(np.abs(ev) < tol) == 3 and ev[3] > 1e3 * tol
    assert ev.min() > -tol
    # condensed corner stiffness: same properties, null space = rigid motions of the corners
    S = m.corner_stiffness()
    ev = np.linalg.eigvalsh(S)
    assert np.sum(np.abs(ev) < 1e-9 * ev[-1]) == 3 and ev[3] > 1e-6 * ev[-1]
    c = m.corners
    rigid = [np.tile([1.0, 0.0], m.N), np.tile([0.0, 1.0], m.N), np.column_stack([-c[1], c[0]]).ravel()]
    for r in rigid:
        np.testing.assert_allclose(S @ r, 0.0, atol=1e-9 * np.abs(S).max())


def test_corner_forces_of_full_solve_equal_condensed_stiffness():
    # independent formulations: reactions K u of the full solve vs the Schur complement
    m = PlaneStressMembrane(corners=membrane_corners_regular(4, 1.4142), material=KAPTON, n=4)
    rng = np.random.default_rng(0)
    delta = 1e-3 * rng.standard_normal((2, 4))
    sol = m.solve(delta)
    np.testing.assert_allclose(sol.corner_forces.T.ravel(), m.corner_stiffness() @ delta.T.ravel(),
                               rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(sol.u[:, m.mesh.corners], delta)
    # the corner forces are self-equilibrated (no other loads): zero resultant and moment
    F = sol.corner_forces
    np.testing.assert_allclose(F.sum(axis=1), 0.0, atol=1e-10 * np.abs(F).max())
    moment = np.sum(m.corners[0] * F[1] - m.corners[1] * F[0])
    assert abs(moment) < 1e-10 * np.abs(F).max()
    assert sol.stress_resultants.shape == sol.sigma.shape == (3,) + sol.dx.shape
    assert sol.dx.shape[0] == 64 and sol.qp.shape == (2,) + sol.dx.shape
    np.testing.assert_allclose(sol.stress_resultants, KAPTON.h * sol.sigma)
    assert sol.dx.sum() == pytest.approx(2 * 1.4142**2)   # area of the square


@pytest.mark.parametrize("N", [3, 4, 6])
def test_symmetric_corner_forces_are_radial_and_equal(N):
    m = PlaneStressMembrane(corners=membrane_corners_regular(N, 1.5), material=KAPTON, n=6)
    r = m.symmetric_response(1e-3)
    assert r.F_Delta > 0
    assert r.asymmetry < 1e-10   # eq. 3.21 symmetry, up to round-off of the gmsh mesh
    # radial directions equal (cos beta_i, sin beta_i) of eq. 3.21
    from tmfem.system.geometry import beta
    b = beta(N)
    np.testing.assert_allclose(m.radial_directions(), [np.cos(b), np.sin(b)], atol=1e-12)


@pytest.mark.parametrize("N, ns, rel", [(3, [5, 10, 20], 0.01), (4, [5, 10, 20], 0.01),
                                        (6, [10, 20, 40], 0.04)])   # hexagon: slower onset
def test_F_Delta_mesh_dependence_matches_flamant_wedge(N, ns, rel):
    # F_Delta does not converge: 1/F_Delta = a + k ln(n) / (E h Delta) (Flamant wedge, see header)
    Delta = 1e-3
    ns = np.array(ns)
    F = np.array([PlaneStressMembrane(corners=membrane_corners_regular(N, 1.5), material=KAPTON, n=int(n))
                  .symmetric_response(Delta).F_Delta for n in ns])
    assert np.all(np.diff(F) < 0)
    slope, _ = np.polyfit(np.log(ns), 1.0 / F, 1)
    alpha = 0.5 * (np.pi - 2 * np.pi / N)   # half the interior angle of the regular N-gon
    k = 1.0 / (alpha + np.sin(alpha) * np.cos(alpha))
    assert slope == pytest.approx(k / (KAPTON.E * KAPTON.h * Delta), rel=rel)


def test_peak_stress_grows_with_mesh_refinement():
    # corner point attachments make the peak stress mesh-dependent (singular like 1/r):
    # the maximum von Mises stress at the corner elements grows with n, close to the rate n/ln n
    Delta = 1e-3
    ns = np.array([5, 10, 20])
    vm = np.array([PlaneStressMembrane(corners=membrane_corners_regular(4, 1.4142), material=KAPTON, n=int(n))
                   .symmetric_response(Delta).solution.max_von_mises for n in ns])
    rate = np.polyfit(np.log(ns), np.log(vm), 1)[0]
    assert 0.6 < rate < 1.0


def test_symmetric_corner_force_of_preset_1_4():
    s = load_preset("1-4")
    Delta = s.symmetric.membrane_delta(4, s.r_mb)
    F = symmetric_corner_force(s, n=10)
    m = PlaneStressMembrane(corners=s.membrane_corners, material=s.membrane, n=10)
    # linear in Delta: compare with the condensed stiffness applied to the eq. 3.21 pattern
    e = m.radial_directions()
    f = m.corner_stiffness() @ m.symmetric_delta(Delta).T.ravel()
    assert F == pytest.approx(np.mean(np.sum(f.reshape(4, 2).T * e, axis=0)), rel=1e-10)
    assert F > 0


def test_slack_membrane_and_bad_input_raise():
    s = load_preset("1-4")
    with pytest.raises(SlackMembrane, match="Delta"):
        symmetric_corner_force(s, Delta=-1e-3, n=2)
    assert symmetric_corner_force(s, Delta=-1e-3, n=2, allow_slack=True) < 0
    m = PlaneStressMembrane(corners=s.membrane_corners, material=s.membrane, n=2)
    with pytest.raises(InputError, match="shape"):
        m.solve(np.zeros((2, 3)))
