"""General method of 3.2: corner constraints (3.5), A(q) of 3.16, symmetric reduction (3.3.2)."""
import numpy as np
import pytest

from tmfem.equilibrium.general import (corner_state, delta_gradient, equilibrium_matrix,
                                       euler_R_derivatives, expand_symmetric_forces,
                                       node_jacobian, positive_null_vector, solve_corner_constraints,
                                       symmetric_matrix, tendon_length_gradient)
from tmfem.errors import ConvergenceError
from tmfem.system import load_preset
from tmfem.system.geometry import SymmetricConfig, rotation_ef

rng = np.random.default_rng(3)
H = 1e-6


def perturbed(name, amp=0.02):
    s = load_preset(name)
    return s, s.q + amp * rng.standard_normal(s.q.size)


def fd(f, q):
    """Central differences of f at q, (n_q, ...) -- the independent check of the analytic derivatives."""
    return np.array([(f(q + H * e) - f(q - H * e)) / (2 * H) for e in np.eye(q.size)])


def test_euler_angles_3_2_1_and_derivatives():
    g = rng.uniform(-1, 1, 3)
    c1, s1 = np.cos(g[0]), np.sin(g[0])
    c2, s2 = np.cos(g[1]), np.sin(g[1])
    c3, s3 = np.cos(g[2]), np.sin(g[2])
    Rz = np.array([[c1, -s1, 0], [s1, c1, 0], [0, 0, 1]])
    Ry = np.array([[c2, 0, s2], [0, 1, 0], [-s2, 0, c2]])
    Rx = np.array([[1, 0, 0], [0, c3, -s3], [0, s3, c3]])
    np.testing.assert_allclose(rotation_ef(g), Rz @ Ry @ Rx, atol=1e-15)   # eq. 3.3
    dR = fd(rotation_ef, g)                                                 # (3, 3, 3) k first
    np.testing.assert_allclose(np.moveaxis(dR, 0, -1), euler_R_derivatives(g), atol=1e-8)


@pytest.mark.parametrize("name", ["1-4", "2-3"])
def test_corner_state_closed_form_matches_newton_on_eq_3_5(name):
    s, q = perturbed(name)
    a = corner_state(s, q)
    b = solve_corner_constraints(s, q)
    np.testing.assert_allclose(a.R, b.R, atol=1e-10)
    np.testing.assert_allclose(a.free, b.free, atol=1e-10)
    # eq. 3.5 holds: B_Mi - B_MN = R (P_i + Delta_i)
    B = s.membrane_corners_inertial(q)
    P = np.vstack([s.membrane_corners, np.zeros((1, s.N))])
    np.testing.assert_allclose(B - B[:, [-1]], a.R @ (P + a.delta), atol=1e-12)
    # constrained components of 3.2 are zero: Delta_v1 = Delta_w1 = Delta_w,N-1 = 0
    assert a.delta[1, 0] == 0 or abs(a.delta[1, 0]) < 1e-13
    assert abs(a.delta[2, 0]) < 1e-13 and abs(a.delta[2, s.N - 2]) < 1e-13


def test_newton_reports_non_convergence():
    s, q = perturbed("1-4")
    with pytest.raises(ConvergenceError, match="eq. 3.5"):
        solve_corner_constraints(s, q, maxiter=1)


@pytest.mark.parametrize("name", ["1-4", "2-3"])
def test_derivatives_against_finite_differences(name):
    s, q = perturbed(name)
    np.testing.assert_allclose(node_jacobian(s, q).transpose(2, 0, 1), fd(s.nodes, q), atol=1e-7)
    np.testing.assert_allclose(tendon_length_gradient(s, q), fd(s.tendon_lengths, q), atol=1e-7)
    np.testing.assert_allclose(delta_gradient(s, q), fd(lambda x: corner_state(s, x).free, q),
                               atol=1e-7)


def test_1ND_node_jacobian_includes_H_points():
    from tmfem.system import System, TendonSection
    base = load_preset("1-4")
    cfg = SymmetricConfig(theta=[0.9], psi=[0.3], sigma=[0], z=[0], r=[0.5], l=[2.2])
    s = System.symmetric_system(name="d", N=4, config=cfg, r_mb=1.0, membrane=base.membrane,
                                bar=base.bar, tendon_sections={"*": TendonSection(E=2e9, d=1e-3)},
                                deployable=True, k_H=0.3)
    q = s.q + 0.02 * rng.standard_normal(s.q.size)
    np.testing.assert_allclose(tendon_length_gradient(s, q), fd(s.tendon_lengths, q), atol=1e-7)


def test_matrix_shapes_of_3_16_and_3_3_2():
    for name, M, N in [("1-4", 1, 4), ("2-3", 2, 3)]:
        s = load_preset(name)
        E = equilibrium_matrix(s)
        assert E.A.shape == ((5 * M - 3) * N, (6 * M - 2) * N - 6)    # eqs. 3.15-3.16
        S = symmetric_matrix(s)
        assert S.A.shape == (5 * M - 3, 6 * M - 4)                      # 3.3.2


def test_reduced_null_vector_is_a_null_vector_of_the_full_matrix():
    # 2-3: 7 x 8 reduced matrix, 1-dimensional null space (3.3.2); expanding it with the
    # symmetry of eqs. 3.21, 3.23 must annihilate all 21 rows of A(q), not only bar b_iN's
    s = load_preset("2-3")
    S = symmetric_matrix(s)
    nv = positive_null_vector(S.A)
    assert nv.dim == 1
    x = nv.x / np.abs(nv.x).max()
    E = equilibrium_matrix(s)
    Tq = expand_symmetric_forces(s, x[:-1], x[-1])
    assert np.abs(E.A @ Tq).max() < 1e-10 * np.abs(E.A).max()


def test_virtual_work_vanishes_for_a_null_vector():
    # independent of A: delta U = sum T d|d| + F dDelta along random dq (finite differences
    # of the lengths and of the closed-form corner state) is zero for T_q in the null space
    s = load_preset("2-3")
    S = symmetric_matrix(s)
    x = positive_null_vector(S.A).x
    Tq = expand_symmetric_forces(s, x[:-1], x[-1])
    nF = 3 * s.N - 6

    def work(qq):
        return Tq[nF:] @ s.tendon_lengths(qq) + Tq[:nF] @ corner_state(s, qq).free

    for _ in range(3):
        dq = rng.standard_normal(s.q.size)
        dW = (work(s.q + H * dq) - work(s.q - H * dq)) / (2 * H)
        assert abs(dW) < 1e-7 * np.abs(Tq).max()


def test_positive_null_vector_lp():
    # A = [1, 1, -1]: null space spanned by (1, 0, 1), (0, 1, 1); best min entry with sum 1
    # over all entries: x = (1/4, 1/4, 1/2), margin 1/4 (by hand)
    nv = positive_null_vector(np.array([[1.0, 1.0, -1.0]]))
    assert nv.dim == 2 and nv.margin == pytest.approx(0.25)
    np.testing.assert_allclose(nv.x, [0.25, 0.25, 0.5], atol=1e-9)
    # A = [1, 1]: null vector (1, -1) cannot be positive
    assert not positive_null_vector(np.array([[1.0, 1.0]])).exists
    # nonsingular: no null space
    nv = positive_null_vector(np.eye(2))
    assert nv.dim == 0 and not nv.exists


def test_design_of_a_non_symmetric_2_3_makes_virtual_work_vanish():
    # general (non-symmetric) q: A_T is square for 2-3, so tendon forces exist for the FE
    # corner forces; check delta U = T . d|d| + F . dDelta = 0 by finite differences
    from tmfem.equilibrium.design import design_equilibrium, free_forces
    s, q = perturbed("2-3", amp=0.01)
    s = s.replace(q=q, symmetric=None, rest_lengths=None)
    d = design_equilibrium(s, mesh_n=3, strict=False)
    assert d.Delta is None and d.residual < 1e-9
    F = free_forces(d.corner_forces)

    def work(qq):
        return d.tendon_forces @ s.tendon_lengths(qq) + F @ corner_state(s, qq).free

    for _ in range(3):
        dq = rng.standard_normal(q.size)
        dW = (work(q + H * dq) - work(q - H * dq)) / (2 * H)
        assert abs(dW) < 1e-6 * np.abs(d.tendon_forces).max()


def test_non_coplanar_corners_are_reported():
    # a general 1-4 with one bar tilted: the four corners leave the plane of B_4, B_1, B_3
    from tmfem.equilibrium.design import design_equilibrium
    from tmfem.errors import InfeasibleDesign
    s = load_preset("1-4")
    q = s.q.copy()
    q[2] += 0.05                                   # theta_12
    s = s.replace(q=q, symmetric=None, rest_lengths=None)
    d = design_equilibrium(s, mesh_n=3, strict=False)
    bad = [c for c in d.failed if c.name == "membrane corners coplanar"]
    assert bad and bad[0].value > 1e-3
    with pytest.raises(InfeasibleDesign):
        design_equilibrium(s, mesh_n=3)


@pytest.mark.parametrize("N", [5, 6])
def test_corner_constraints_and_derivatives_for_larger_N(N):
    # N >= 5: corners 2..N-2 have free out-of-plane displacements Delta_w (3.2)
    from tmfem.system import System, TendonSection
    base = load_preset("1-4")
    cfg = SymmetricConfig(theta=[1.0], psi=[0.2], sigma=[0], z=[0], r=[0.6], l=[2.0])
    s = System.symmetric_system(name="n", N=N, config=cfg, r_mb=1.0, membrane=base.membrane,
                                bar=base.bar, tendon_sections={"*": TendonSection(E=2e9, d=1e-3)})
    q = s.q + 0.02 * rng.standard_normal(s.q.size)
    a, b = corner_state(s, q), solve_corner_constraints(s, q)
    np.testing.assert_allclose(a.free, b.free, atol=1e-10)
    assert np.abs(a.delta[2]).max() > 1e-4          # non-coplanar corners after perturbation
    np.testing.assert_allclose(delta_gradient(s, q), fd(lambda x: corner_state(s, x).free, q),
                               atol=1e-7)
    assert equilibrium_matrix(s, q).A.shape == (2 * N, 4 * N - 6)
