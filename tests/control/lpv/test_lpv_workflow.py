"""The LPV design workflow as library functions (tmfem.control.lpv.workflow) on a plant
with known answers: the oscillator x'' + 0.1 x' + (1 + rho) x = u, A affine in rho (so the
multilinear interpolation is exact and a refined grid is the true plant)."""
import dataclasses

import control
import numpy as np
import pytest

from tmfem.control.lpv import (interconnection_8_1, pointwise_state_feedback_bound,
                               synthesize_state_feedback)
from tmfem.control.lpv.defaults import W_E, W_U
from tmfem.control.lpv.workflow import (output_feedback_design, saved_design_plant, synthesize_design,
                                        verify_design)
from tmfem.errors import InfeasibleController, InputError
from tmfem.system import load_preset
from tests.control.lpv.test_lpv_output_feedback import oscillator


def measured_oscillator(**kw):
    """The oscillator with its output named as its first state, x: the tracked and measured
    position (as the COM's q, outputs and the first states, eq. 5.17)."""
    return dataclasses.replace(oscillator(**kw), output_names=["x"])


@pytest.fixture(scope="module")
def problem():
    pl = measured_oscillator()
    gp = interconnection_8_1(pl, tracked=["x"])
    return pl, gp, pointwise_state_feedback_bound(gp), synthesize_state_feedback(gp)


def test_gamma_bisection_reaches_the_conic_optimum(problem):
    # Clarabel's optimum of the same LMIs is the reference: the bisection's gamma is feasible
    # (>= it) and within its tolerance 1e-3 (+ the gap of the proven bound) above it
    pl, gp, bound, conic = problem
    ctrl, info = synthesize_design(gp, bound=bound, solver="EIGOPT", rtol=1e-3)
    assert conic.gamma * (1 - 1e-5) <= ctrl.gamma <= conic.gamma * (1 + 1.5e-3)
    assert info["gamma"] == ctrl.gamma and info["solver"] == "EIGOPT" and info["gamma_levels"]
    assert info["gamma_lower_bound_proven"] == bound.lower_bound <= conic.gamma * (1 + 1e-5)
    # the conic solvers through the same function: their minimum, no bisection entries
    ctrl2, info2 = synthesize_design(gp, bound=bound, solver="CLARABEL")
    assert ctrl2.gamma == pytest.approx(conic.gamma, rel=1e-6) and "gamma_levels" not in info2
    # one level: a feasible point at that gamma
    ctrl3, _ = synthesize_design(gp, bound=bound, solver="EIGOPT", fixed_gamma=True, gamma=1.2 * conic.gamma)
    assert ctrl3.gamma == pytest.approx(1.2 * conic.gamma)


def test_synthesis_refusals_name_the_lower_bound(problem):
    pl, gp, bound, conic = problem
    with pytest.raises(InputError, match="expected an upper level above the pointwise lower bound"):
        synthesize_design(gp, bound=bound, solver="EIGOPT", gamma=0.9 * bound.lower_bound)
    with pytest.raises(InfeasibleController, match="pointwise state-feedback lower bound of gamma"):
        synthesize_design(gp, bound=bound, solver="EIGOPT", fixed_gamma=True, gamma=0.5 * bound.lower_bound)


def test_verification_on_the_refined_grid_is_the_frozen_closed_loop(problem):
    # the worst closed-loop eigenvalue over the 4x finer grid, computed here from A + B2 K of
    # the interconnection at each point, is the verification's; a plant made unstable by a
    # shift of A that K cannot stabilise fails
    pl, gp, bound, conic = problem
    fine = pl.resampled(pl.refined(4))
    v = verify_design(conic, fine, tracked=["x"])
    fgp = interconnection_8_1(fine, tracked=["x"])
    want = max(np.linalg.eigvals(fgp.A[i] + fgp.B2[i] @ conic.gain([r])).real.max()
               for i, r in enumerate(fine.axes[0]))
    assert v.passed and v.grid == (9,) and v.max_cl_real == pytest.approx(want, rel=1e-12)
    with pytest.raises(InfeasibleController):
        verify_design(conic, measured_oscillator(shift=3.0).resampled(pl.refined(4)), tracked=["x"])


def test_output_feedback_gamma_is_the_largest_frozen_norm(problem):
    # python-control's H-infinity norm of every frozen loop of the fine grid, from the
    # design's own loop matrices with the measured position x: the JSON gamma is their maximum
    pl, gp, bound, conic = problem
    fine = pl.resampled(pl.refined(2))
    d, info = output_feedback_design(conic, pl, fine, tracked=["x"], noise=0.01)
    C = np.array([[1.0, 0.0]])                                   # the measured x (eq. 5.17's q)
    norms = [control.norm(control.ss(*d.frozen_closed_loop(fine.A[i], fine.B[i], C, [r], W_e=W_E, W_u=W_U)),
                          p="inf") for i, r in enumerate(fine.axes[0])]
    assert info["gamma"] == pytest.approx(max(norms), rel=1e-4)
    assert info["measured"] == ["x"] and info["state_feedback_gamma"] == conic.gamma
    assert info["noise_weight"] == 0.01 and info["estimator_grid"] == [3]
    assert info["guarantee"].startswith("frozen-parameter")


def test_a_saved_design_on_other_parameters_is_refused(problem):
    pl, gp, bound, conic = problem
    with pytest.raises(InputError, match=r"expected a design scheduled on \['theta_13', 'psi_13'\] \(the 3-bar"):
        saved_design_plant(conic, system=load_preset("2-3-lpv"), bases=None)
