"""Cutting-plane refinement of a gridded LPV state feedback that fails between its design
points (tmfem.control.lpv.refinement): an oscillator whose stiffness 1 - 3 sin(pi rho) is
negative between the two design points rho = 0 and 1, where the design's affine P(rho),
Q(rho) (eq. 5.99) do not hold the LMI of eq. 5.95; with a disturbance three times stronger
there, a point whose own state-feedback optimum lies above the design's gamma. Independent
checks: the frozen closed loops' poles and H-infinity norms by python-control."""
import control
import numpy as np
import pytest

from tmfem.control.lpv.bisect import bisect_gamma
from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.refinement import refine_state_feedback
from tmfem.control.lpv.verify import verify
from tmfem.errors import InputError


def stiffness(rho):
    return 1.0 - 3.0 * np.sin(np.pi * rho)


def oscillator(rho, *, gust=0.0):
    """x'' + 0.1 x' + k(rho) x = u + (1 + gust sin(pi rho)) w, p = [x; 0.3 u], rates |rho'| <= 0.2."""
    rho = np.asarray(rho, dtype=float)
    s = (rho.size,)
    A = np.array([[[0.0, 1.0], [-stiffness(r), -0.1]] for r in rho])
    B = np.broadcast_to([[0.0], [1.0]], s + (2, 1))
    B1 = np.array([[[0.0], [1.0 + gust * np.sin(np.pi * r)]] for r in rho])
    return GeneralizedLPV.from_matrices(
        axes=[rho], parameter_names=["r"], rate_bounds=[[-0.2, 0.2]], A=A, B1=B1, B2=B,
        C1=np.broadcast_to([[1.0, 0.0], [0.0, 0.0]], s + (2, 2)), D11=np.zeros(s + (2, 1)),
        D12=np.broadcast_to([[0.0], [0.3]], s + (2, 1)))


@pytest.fixture(scope="module")
def coarse_design():
    design, _ = bisect_gamma(oscillator([0.0, 1.0]), lower=0.1, upper=20.0, rtol=0.05, time_budget=60)
    return design


def frozen_loop(design, rho):
    gp = oscillator([rho])
    A, B, C = gp.A[0], gp.B1[0], gp.C1[0]
    D12 = np.array([[0.0], [0.3]])
    K = design.gain([rho])
    return control.ss(A + B @ K, B, C + D12 @ K, np.zeros((2, 1)))


def test_a_design_that_fails_between_its_points_is_refined_until_the_finer_grid_passes(coarse_design):
    fine = oscillator(np.linspace(0.0, 1.0, 5))
    before = verify(coarse_design, fine, allow_failure=True)
    assert not before.passed and before.max_lmi_eig_at == [0.5]       # the negative stiffness
    refined, record = refine_state_feedback(coarse_design, fine)
    assert record["passed"] and record["stopped"] == "passed" and record["points_added"] >= 1
    # the level: the design's gamma, or 1.05 x the pointwise optimum of the added points when higher
    optima = pointwise_state_feedback_bound(fine)
    added = [optima.gamma[list(fine.axes[0]).index(rho)] for (rho,) in record["rounds"][0]["added_at"]]
    assert record["design_gamma"] == coarse_design.gamma
    assert refined.gamma == record["gamma"] == pytest.approx(max(coarse_design.gamma, 1.05 * max(added)), rel=1e-4)
    assert refined.min_P_eig > 0
    assert verify(refined, fine).passed
    assert verify(refined, oscillator([0.0, 1.0])).passed            # the design points still hold
    # independent: every frozen loop of the finer grid is stable and its norm below gamma (the
    # LMI of eq. 5.95 at zero rate bounds the frozen norm)
    for rho in fine.axes[0]:
        loop = frozen_loop(refined, rho)
        assert np.max(loop.poles().real) < 0
        assert control.norm(loop, p="inf") <= refined.gamma * (1 + 1e-6)


def test_the_level_rises_above_a_new_points_own_optimum():
    # a disturbance three times stronger at rho = 0.5 than at the design points: no controller
    # reaches the design's gamma there (its pointwise state-feedback optimum, a lower bound of
    # any gridded design, tmfem.control.lpv.bounds), so the re-solve's level is 1.05 times it
    design, _ = bisect_gamma(oscillator([0.0, 1.0], gust=2.0), lower=0.1, upper=20.0, rtol=0.05, time_budget=60)
    fine = oscillator(np.linspace(0.0, 1.0, 5), gust=2.0)
    optimum = pointwise_state_feedback_bound(fine)
    assert optimum.lower_bound > 2 * design.gamma and optimum.at == [0.5]
    refined, record = refine_state_feedback(design, fine)
    assert record["passed"] and record["design_gamma"] == design.gamma
    assert refined.gamma == record["gamma"] == pytest.approx(1.05 * optimum.lower_bound, rel=1e-4)
    assert verify(refined, fine).passed


def test_no_round_leaves_the_design_and_reports_the_failure(coarse_design):
    fine = oscillator(np.linspace(0.0, 1.0, 5))
    same, record = refine_state_feedback(coarse_design, fine, max_rounds=0)
    assert same is coarse_design
    assert not record["passed"] and record["stopped"] == "rounds" and record["points_added"] == 0
    assert record["rounds"][0]["failing"] >= 1 and record["rounds"][0]["fine_max_eig_at"] == [0.5]


@pytest.mark.parametrize("kwargs, msg", [
    ({"fine": lambda: oscillator(np.linspace(0.1, 1.0, 4))}, "contain every design point"),
    ({"per_round": 0}, "per_round >= 1"),
    ({"max_rounds": -1}, "max_rounds >= 0"),
])
def test_bad_refinements_are_refused(coarse_design, kwargs, msg):
    fine = kwargs.pop("fine", lambda: oscillator(np.linspace(0.0, 1.0, 5)))()
    with pytest.raises(InputError, match=msg):
        refine_state_feedback(coarse_design, fine, **kwargs)
