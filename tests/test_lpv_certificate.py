"""Rate-bounded certificate of the output-feedback LPV loop (tmfem.control.lpv_certificate) on
the oscillator of docs/lpv.md (not a tensegrity): against the bounded real lemma solved by
cvxpy/Clarabel and assembled here from the frozen loops."""
import itertools

import cvxpy as cp
import numpy as np
import pytest

from test_lpv_output import W_E, W_U, oscillator
from tmfem.control.lpv_certificate import rate_bounded_certificate
from tmfem.control.lpv_output import design_output_feedback, verify_output_feedback
from tmfem.control.lpv_synthesis import interconnection_8_1, synthesize_state_feedback
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
