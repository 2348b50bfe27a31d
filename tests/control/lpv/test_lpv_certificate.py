"""Rate-bounded certificate of the output-feedback LPV loop (tmfem.control.lpv.certificate) on
the oscillator of docs/guides/lpv.md (not a tensegrity): against the bounded real lemma solved by
cvxpy/Clarabel and assembled here from the frozen loops."""
import itertools

import cvxpy as cp
import numpy as np
import pytest

from tests.control.lpv.test_lpv_output_feedback import W_E, W_U, oscillator
from tmfem.control.lpv.certificate import rate_bounded_certificate
from tmfem.control.lpv.output_feedback import design_output_feedback, verify_output_feedback
from tmfem.control.lpv.generalized_plant import interconnection_8_1
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.errors import InfeasibleController, InputError


def make_design(plant):
    sf = synthesize_state_feedback(interconnection_8_1(plant, tracked=["y"], W_e=W_E, W_u=W_U))
    return design_output_feedback(sf, plant, tracked=["y"], measured=["y"], W_d=0.3, W_n=0.01)


def loops(d, plant):
    """(rho, A_cl, B_cl, C_cl, D_cl) of the frozen loops of ``plant``'s grid."""
    return [(rho, *d.frozen_closed_loop(plant.A[idx], plant.B[idx], plant.C[idx], rho, W_e=W_E, W_u=W_U))
            for idx, rho in plant.points()]


def brl(X, dX, A, B, C, D, g):
    """The bounded real lemma matrix of the module docstring, eq. 5.95 on the loop (numpy or cvxpy)."""
    H = A @ X + X @ A.T - dX
    blocks = [[H, B, X @ C.T], [B.T, -g * np.eye(B.shape[1]), D.T], [C @ X, D, -g * np.eye(C.shape[0])]]
    return np.block(blocks) if isinstance(X, np.ndarray) else cp.bmat(blocks)


def conic_optimum(d, plant):
    """min gamma of the LMI with X(rho) = X0 + rho_n X1 (rho_n = rho - 1 on [0, 2]) at
    every grid point and both rate vertices, by cvxpy (Clarabel)."""
    n = d.nx + 1 + d.nx
    X0, X1 = cp.Variable((n, n), symmetric=True), cp.Variable((n, n), symmetric=True)
    g = cp.Variable()
    rate = plant.rate_bounds[0, 1]
    cons = []
    for rho, A, B, C, D in loops(d, plant):
        X = X0 + (rho[0] - 1.0) * X1
        cons.append(X >> 1e-6 * np.eye(n))
        for v in (-rate, rate):
            M = brl(X, v * X1, A, B, C, D, g)
            cons.append((M + M.T) / 2 << -1e-7 * np.eye(M.shape[0]))
    cp.Problem(cp.Minimize(g), cons).solve(solver="CLARABEL")
    return float(g.value)


@pytest.fixture(scope="module")
def design():
    pl = oscillator()
    return pl, make_design(pl)


def test_certificate_holds_the_primal_lmi_and_is_near_the_conic_optimum(design):
    pl, d = design
    c = rate_bounded_certificate(d, pl, W_e=W_E, W_u=W_U, rtol=1e-2)
    assert c.found and c.bracket.converged
    # the separation start (the state feedback's P with a rate-bounded Z of the estimation error)
    # already holds the LMI at the upper level: no iteration there
    assert c.start["start_max_eig"] < 0 and c.start["estimator_error_gamma"] > 0
    assert c.bracket.levels[0]["start"] == "given design" and c.bracket.levels[0]["evaluations"] == 0
    # the proven lower bound is the largest frozen-loop norm of the grid (python-control norm)
    import control
    frozen = max(control.norm(control.ss(*lp[1:]), p="inf") for lp in loops(d, pl))
    assert c.lower_bound == pytest.approx(frozen, rel=1e-6)
    # X(rho) of the certificate in the LMI, assembled here from the frozen loops: negative
    # at every grid point and rate vertex, X > 0
    X = c.lyapunov
    for (rho, A, B, C, D), v in itertools.product(loops(d, pl), (-0.2, 0.2)):
        dX = v / X.half_width[0] * X.P[1]
        assert np.linalg.eigvalsh(brl(X.P_of(rho), dX, A, B, C, D, c.gamma)).max() < 0
        assert np.linalg.eigvalsh(X.P_of(rho)).min() > 0
    # the gamma found is feasible (not below the conic optimum) and within the bisection's 1 %
    g_opt = conic_optimum(d, pl)
    assert frozen <= g_opt * (1 + 1e-6)
    assert g_opt * (1 - 1e-5) <= c.gamma <= g_opt * 1.015


def test_verify_output_feedback_rechecks_the_certificate_on_the_finer_grid(design):
    # A affine in rho: the 9-point grid holds the true plants between the design points
    pl, d = design
    c = rate_bounded_certificate(d, pl, W_e=W_E, W_u=W_U, rtol=1e-2)
    fine = oscillator(np.linspace(0, 2, 9))
    v = verify_output_feedback(d, fine, W_e=W_E, W_u=W_U, dt=0.01, certificate=c)
    out = v.to_dict()
    assert v.passed and out["rate_bounded_certificate"] and out["rate_bounded_gamma"] == c.gamma
    assert out["rate_bounded_verification_max_eig"] < 0
    # the frozen norms of the finer grid cannot exceed the certified L2 gain
    assert v.max_hinf <= c.gamma
    # the same X(rho) and gamma on the plant shifted by +0.05/s (true plants the design does not
    # know): the frozen loops stay stable, the LMI fails there and the controller is refused
    shifted = oscillator(np.linspace(0, 2, 9), shift=0.05)
    vs = verify_output_feedback(d, shifted, W_e=W_E, W_u=W_U, certificate=c, allow_failure=True)
    assert vs.max_cl_real < 0 and vs.certificate_check.max_lmi_eig > 0 and not vs.passed
    with pytest.raises(InfeasibleController, match="rate-bounded LMI"):
        verify_output_feedback(d, shifted, W_e=W_E, W_u=W_U, certificate=c)


def test_certificate_not_found_and_refusals(design):
    pl, d = design
    # no time for the first level: reported as not found, with the reason (no proof either way)
    c = rate_bounded_certificate(d, pl, W_e=W_E, W_u=W_U, time_budget=1e-9)
    assert not c.found and c.gamma is None and "time budget" in c.message
    assert c.to_dict()["rate_bounded_certificate"] is False and c.lower_bound > 0
    with pytest.raises(InputError, match="above the largest frozen norm"):
        rate_bounded_certificate(d, pl, W_e=W_E, W_u=W_U, upper=0.5)
    # the controller on a destabilised plant: a frozen loop is unstable, no certificate can exist
    with pytest.raises(InfeasibleController, match="unstable"):
        rate_bounded_certificate(d, oscillator(shift=3.0), W_e=W_E, W_u=W_U)


# --------------------------------------------------------------------- cutting-plane refinement
def nonlinear_oscillator(rho):
    """x'' + 0.1 x' + (1 + rho^2) x = u about x_e = 0.5 (stiffness nonlinear in rho: between grid
    points the multilinear interpolation of the design plant is not the true plant)."""
    from tmfem.control.lpv.plant import GriddedLPV
    rho = np.asarray(rho, dtype=float)
    k = rho.size
    return GriddedLPV(axes=[rho], parameter_names=["rho"], A=np.array([[[0, 1], [-(1 + r * r), -0.1]] for r in rho]),
                      B=np.broadcast_to([[0.0], [1.0]], (k, 2, 1)), C=np.broadcast_to([[1.0, 0.0]], (k, 1, 2)),
                      D=np.zeros((k, 1, 1)), rate_bounds=[[-0.2, 0.2]], state_names=["x", "v"], input_names=["u"],
                      output_names=["y"], x_e=np.array([[0.5, 0.0]] * k),
                      u_e=np.array([[(1 + r * r) * 0.5] for r in rho]), y_e=np.array([[0.5]] * k))


@pytest.fixture(scope="module")
def nonlinear():
    pl = nonlinear_oscillator([0.0, 2.0])
    d = make_design(pl)
    cert = rate_bounded_certificate(d, pl, W_e=W_E, W_u=W_U, rtol=1e-2)
    return pl, d, cert, nonlinear_oscillator(np.linspace(0, 2, 5))


def largest_brl(X, gamma, d, plant):
    """Largest eigenvalue of the LMI assembled here (``brl``) with X(rho) over the frozen loops of
    ``plant``'s grid and both rate vertices, and the smallest eigenvalue of X(rho) there."""
    lmi, minX = -np.inf, np.inf
    for (rho, A, B, C, D), v in itertools.product(loops(d, plant), (-0.2, 0.2)):
        lmi = max(lmi, np.linalg.eigvalsh(brl(X.P_of(rho), v / X.half_width[0] * X.P[1], A, B, C, D, gamma)).max())
        minX = min(minX, np.linalg.eigvalsh(X.P_of(rho)).min())
    return lmi, minX


def test_refinement_makes_a_design_grid_certificate_hold_on_the_finer_grid(nonlinear):
    from tmfem.control.lpv.certificate import refine_certificate
    pl, d, c, fine = nonlinear
    assert c.found
    # the estimator's model at rho = 1 interpolates stiffness 3; the true plant has 2
    assert pl.at([1.0])[0][1, 0] == pytest.approx(-3.0) and fine.A[2][1, 0] == pytest.approx(-2.0)
    # the design-grid certificate fails between the grid points (the LMI assembled here, and the
    # re-check of verify_output_feedback, which refuses it), although every frozen loop is stable
    before, _ = largest_brl(c.lyapunov, c.gamma, d, fine)
    assert before > 0
    v = verify_output_feedback(d, fine, W_e=W_E, W_u=W_U, certificate=c, allow_failure=True)
    assert not v.passed and v.max_cl_real < 0 and v.certificate_check.max_lmi_eig_at == [1.0]
    # a certificate at this gamma exists on the fine grid: cvxpy/Clarabel's optimum there is below it
    assert conic_optimum(d, fine) <= c.gamma
    # one cut (the worst point, rho = 1) is enough: the other failing points (0.5, 1.5) pass after it
    r = refine_certificate(c, d, fine, W_e=W_E, W_u=W_U, per_round=1)
    ref = r.refinement
    assert ref["passed"] and ref["stopped"] == "passed" and ref["points_added"] == 1
    assert ref["rounds"][0]["added_at"] == [[1.0]] and ref["rounds"][0]["failing"] == 3
    # the re-solve started where the cut fails (scaled eigenvalue > 0) and ended below -margin
    assert ref["rounds"][0]["start_scaled_eig"] > 0 > -1e-8 > ref["rounds"][0]["largest_scaled_eig"]
    assert r.gamma == c.gamma and r.lower_bound == c.lower_bound
    after, minX = largest_brl(r.lyapunov, r.gamma, d, fine)
    assert after < 0 and minX > 0
    v = verify_output_feedback(d, fine, W_e=W_E, W_u=W_U, certificate=r)
    assert v.passed and v.to_dict()["rate_bounded_refinement_passed"] is True
    assert v.to_dict()["rate_bounded_verification_max_eig"] < 0


def test_spline_estimator_on_a_finer_grid_carries_the_certificate_off_the_design_grid(nonlinear):
    """The stiffness 1 + rho^2 is a parabola: an estimator on the grid [0, 1, 2] with
    ``interpolation="spline"`` has the true plant as its model between its points (the
    multilinear one on the same points: stiffness 1.5 at rho = 0.5 against 1.25), and the
    design-grid certificate of that loop (K(rho) of the 2-point design, X(rho) on [0, 2], the
    estimator's gains taken at the design points) holds on the 5-point grid: the LMI
    assembled here and verify_output_feedback. (The 2-point design's own estimator fails
    there: the refinement test above.)"""
    pl, d, c, fine = nonlinear
    est = nonlinear_oscillator([0.0, 1.0, 2.0])
    de = design_output_feedback(d.state_feedback, est, tracked=["y"], measured=["y"], W_d=0.3,
                                W_n=0.01, interpolation="spline")
    dl = design_output_feedback(d.state_feedback, est, tracked=["y"], measured=["y"], W_d=0.3, W_n=0.01)
    np.testing.assert_allclose(de.estimator.at([0.5])[0], fine.A[1], atol=1e-12)
    assert dl.estimator.at([0.5])[0][1, 0] == pytest.approx(-1.5)
    ce = rate_bounded_certificate(de, pl, W_e=W_E, W_u=W_U, rtol=1e-2)
    assert ce.found
    lmi, minX = largest_brl(ce.lyapunov, ce.gamma, de, fine)
    assert lmi < 0 and minX > 0
    assert verify_output_feedback(de, fine, W_e=W_E, W_u=W_U, certificate=ce).passed
    # an estimator grid without the design points is refused (the separation start needs them)
    off = design_output_feedback(d.state_feedback, nonlinear_oscillator([-0.1, 1.0, 2.0]), tracked=["y"],
                                 measured=["y"], W_d=0.3, W_n=0.01, interpolation="spline")
    with pytest.raises(InputError, match="contain the design points"):
        rate_bounded_certificate(off, pl, W_e=W_E, W_u=W_U, rtol=1e-2)


def test_refinement_budgets_and_refusals(nonlinear):
    from tmfem.control.lpv.certificate import refine_certificate
    pl, d, c, fine = nonlinear
    # no round allowed: the certificate is returned as it was, with the failing points counted
    r = refine_certificate(c, d, fine, W_e=W_E, W_u=W_U, max_rounds=0)
    assert not r.refinement["passed"] and r.refinement["stopped"] == "rounds"
    assert r.refinement["rounds"][0]["failing"] == 3 and r.lyapunov is c.lyapunov
    # a certificate that already holds on the fine grid: no round, nothing added
    lin = oscillator()
    dl = make_design(lin)
    cl = rate_bounded_certificate(dl, lin, W_e=W_E, W_u=W_U, rtol=1e-2)
    rl = refine_certificate(cl, dl, oscillator(np.linspace(0, 2, 9)), W_e=W_E, W_u=W_U)
    assert rl.refinement["passed"] and rl.refinement["points_added"] == 0 and rl.lyapunov is cl.lyapunov
    with pytest.raises(InputError, match="contain every design point"):
        refine_certificate(c, d, nonlinear_oscillator(np.linspace(0, 1.9, 5)), W_e=W_E, W_u=W_U)
    with pytest.raises(InputError, match="per_round"):
        refine_certificate(c, d, fine, W_e=W_E, W_u=W_U, per_round=0)
    with pytest.raises(InputError, match="level gamma >="):
        refine_certificate(c, d, fine, W_e=W_E, W_u=W_U, gamma=0.9 * c.gamma)
    # at a higher level the result is certified there (the LMI assembled in the test, at that gamma)
    r = refine_certificate(c, d, fine, W_e=W_E, W_u=W_U, per_round=1, gamma=1.2 * c.gamma)
    assert r.refinement["passed"] and r.gamma == pytest.approx(1.2 * c.gamma) == r.lyapunov.gamma
    assert largest_brl(r.lyapunov, r.gamma, d, fine)[0] < 0
    none = rate_bounded_certificate(d, pl, W_e=W_E, W_u=W_U, time_budget=1e-9)
    with pytest.raises(InputError, match="found none"):
        refine_certificate(none, d, fine, W_e=W_E, W_u=W_U)
