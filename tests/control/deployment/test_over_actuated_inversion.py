"""Eq. 5.46 for an over-actuated system (more tendons than bar coordinates, a wide B_q of full
row rank): the exact inversion closest to a reference, the bounded problem regularised toward
it, the condition number of a wide B_q, and the square case unchanged."""
import numpy as np
import pytest
from scipy.optimize import lsq_linear, minimize

from tmfem.control.deployment.pfl import (REFERENCE_WEIGHT, PFLTerms, bounded_inversion,
                                          check_input_matrix, exact_inversion)


def wide_terms(nq=4, nt=6, seed=0):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((nq, nq))
    M_q = A @ A.T + nq * np.eye(nq)
    B_q = rng.standard_normal((nq, nt))
    return PFLTerms(M_q=M_q, F_q=np.zeros(nq), B_q=B_q, M12=np.zeros((nq, 0)),
                    M22=np.zeros((0, 0)), F2=np.zeros(0)), rng


def test_exact_inversion_of_a_wide_B_q_is_the_closest_solution_to_the_reference():
    """u = u_ref + B^T (B B^T)^-1 (v - B u_ref) (the normal equations of the minimum-norm
    problem, an independent formula): B u = v, and u - u_ref is orthogonal to the null space
    of B, so every other solution is farther from u_ref."""
    terms, rng = wide_terms()
    B = terms.B_q
    v, u_ref = rng.standard_normal(4), rng.standard_normal(6)
    u = exact_inversion(B, v, u_ref=u_ref)
    assert np.allclose(u, u_ref + B.T @ np.linalg.solve(B @ B.T, v - B @ u_ref), atol=1e-12)
    assert np.allclose(B @ u, v, atol=1e-12)
    null = np.linalg.svd(B)[2][4:].T                       # an orthonormal basis of N(B)
    assert np.allclose(null.T @ (u - u_ref), 0, atol=1e-12)
    other = u + null @ rng.standard_normal(2)
    assert np.linalg.norm(other - u_ref) > np.linalg.norm(u - u_ref)


def test_exact_inversion_of_a_square_B_q_is_its_inverse_bit_for_bit():
    rng = np.random.default_rng(3)
    B, v = rng.standard_normal((5, 5)), rng.standard_normal(5)
    assert np.array_equal(exact_inversion(B, v, u_ref=rng.standard_normal(5)), np.linalg.solve(B, v))


def test_condition_number_of_a_wide_B_q():
    terms, _ = wide_terms()
    s = np.linalg.svd(terms.B_q, compute_uv=False)
    assert check_input_matrix(terms.B_q) == pytest.approx(s[0] / s[3], rel=1e-12)


def test_bounded_inversion_of_a_wide_B_q_finds_the_admissible_exact_solution_nearest_the_reference():
    """Limits that cut off the unconstrained solution but leave exact solutions: the bounded
    problem (regularised toward u_ref with eps = 1e-6 s_1) returns the one nearest u_ref,
    compared with SLSQP on min |u - u_ref|^2 subject to B u = v and the limits (an independent
    formulation); its acceleration misses v by at most eps |u* - u_ref| in the M_q metric."""
    terms, rng = wide_terms(seed=1)
    B = terms.B_q
    u_star = rng.uniform(0.2, 0.8, 6)
    null = np.linalg.svd(B)[2][4:].T
    v, u_ref = B @ u_star, u_star + 1.5 * null[:, 0] + 0.1 * rng.standard_normal(6)
    free = exact_inversion(B, v, u_ref=u_ref)
    lower, upper = np.zeros(6), np.ones(6)
    assert not np.all((free >= lower) & (free <= upper))
    u, active = bounded_inversion(terms, v, lower=lower, upper=upper, u_ref=u_ref)
    assert active and np.all((u >= lower) & (u <= upper))
    ref = minimize(lambda x: np.sum((x - u_ref) ** 2), u_star, jac=lambda x: 2 * (x - u_ref),
                   bounds=list(zip(lower, upper)), method="SLSQP", options={"ftol": 1e-14},
                   constraints=[{"type": "eq", "fun": lambda x: B @ x - v, "jac": lambda x: B}])
    assert ref.success
    assert np.allclose(u, ref.x, atol=1e-5)
    R = np.linalg.cholesky(terms.M_q).T
    eps = REFERENCE_WEIGHT * np.linalg.norm(R @ B, 2)
    assert np.linalg.norm(R @ (B @ u - v)) <= eps * np.linalg.norm(ref.x - u_ref) * (1 + 1e-6) + 1e-12


def test_bounded_inversion_of_a_wide_B_q_without_an_admissible_exact_solution():
    """Limits no exact solution meets: the closest acceleration in the M_q metric, as
    lsq_linear's BVLS of the unregularised problem finds it (to the regularisation's size)."""
    terms, rng = wide_terms(seed=2)
    v = 50 * rng.standard_normal(4)
    lower, upper = -np.ones(6), np.ones(6)
    u, active = bounded_inversion(terms, v, lower=lower, upper=upper, u_ref=np.zeros(6))
    R = np.linalg.cholesky(terms.M_q).T
    best = lsq_linear(R @ terms.B_q, R @ v, bounds=(lower, upper), method="bvls").cost
    assert active and 0.5 * np.sum((R @ (terms.B_q @ u - v)) ** 2) == pytest.approx(best, rel=1e-9)


def test_bounded_inversion_of_a_square_B_q_is_unchanged_bit_for_bit():
    """The square case ignores u_ref: BVLS of eq. 5.46 on R B_q u = R v as before."""
    terms, rng = wide_terms(nq=4, nt=4, seed=4)
    v = 20 * rng.standard_normal(4)
    lower, upper = -np.ones(4), np.ones(4)
    u, active = bounded_inversion(terms, v, lower=lower, upper=upper, u_ref=rng.standard_normal(4))
    R = np.linalg.cholesky(0.5 * (terms.M_q + terms.M_q.T)).T
    old = np.clip(lsq_linear(R @ terms.B_q, R @ v, bounds=(lower, upper), method="bvls").x, lower, upper)
    assert active and np.array_equal(u, old)


def test_path_rest_lengths_at_the_ends_are_the_designed_ones():
    """u_d(s) of the 3-3 (the reference of its inversion) at the deployed and the packaged
    configurations against the rest lengths the equilibrium design gives those two systems
    (tmfem.reference.deployments.checked_configurations, an independent design routine)."""
    from tmfem.control.deployment.run import path_rest_length_reference
    from tmfem.control.deployment.reference_trajectory import DeploymentReference
    from tmfem.reference.deployments import checked_configurations
    from tmfem.system import load_system
    from tests.cli.test_own_system import SYSTEMS
    final = checked_configurations(load_system(SYSTEMS / "tower-3-3.toml"))
    packaged = final.problem.packaged
    ref = DeploymentReference(initial=packaged.symmetric, final=final.symmetric, N=final.N,
                              q_names=list(final.q_names), omega_r=0.5)
    u_d = path_rest_length_reference(final, ref)
    assert np.allclose(u_d(0.0), packaged.rest_lengths, rtol=1e-10)
    assert np.allclose(u_d(1e3), final.rest_lengths, rtol=1e-10)
    # a square system has no reference (its B_q leaves no freedom)
    assert path_rest_length_reference(load_system(SYSTEMS / "pentagon-2-5.toml"), ref) is None
