"""The EIGOPT route of lpvsyn: the route choice, its refusals, its optimum against the conic
solve of the same LMIs, and the 2-3 plant of ch. 8 against the gamma bisection called directly."""
import numpy as np
import pytest

import tmfem.control.lpv.cost
from tmfem.control.lpv import Basis, lpvsyn
from tmfem.control.lpv.bisect import bisect_gamma
from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.errors import InputError, ResourceLimit
from tests.control.lpv.test_lpvsyn import oscillator_gp


@pytest.fixture
def tiny_memory(monkeypatch):
    """An SDP memory estimate over any machine's limit (the auto route must leave the SDP)."""
    monkeypatch.setattr(tmfem.control.lpv.cost, "BYTES_PER_SCALING_ENTRY", 1e15)


def test_auto_takes_eigopt_when_the_sdp_does_not_fit_and_matches_the_conic_optimum(monkeypatch):
    # the conic program of eq. 5.99 (synthesize_state_feedback, Clarabel) is the optimum of the
    # same LMIs: the EIGOPT bisection ends within its bracket width above it, never below
    gp = oscillator_gp()
    ref = synthesize_state_feedback(gp).gamma
    monkeypatch.setattr(tmfem.control.lpv.cost, "BYTES_PER_SCALING_ENTRY", 1e15)     # as tiny_memory
    r = lpvsyn(gp, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine", gamma_rtol=0.01)
    assert r.info["method"] == "eigopt" and "GiB" in r.info["route_reason"]
    assert ref * (1 - 1e-5) <= r.gamma <= ref * 1.01 / (1 - 0.01)
    assert r.info["pointwise_lower_bound"] <= ref * (1 + 1e-6)
    assert r.verification["passed"]
    # the certificate's gain is the eq. 5.99 design's K = Q P^-1 at every rho
    for rho in ([0.0, 0.0], [0.35, 0.6]):
        np.testing.assert_allclose(r.controller.at(rho)[3], r.design.gain(rho), rtol=1e-9, atol=1e-12)


def test_auto_takes_the_sdp_when_it_fits():
    gp = oscillator_gp()
    r = lpvsyn(gp, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine")
    assert r.info["method"] == "sdp" and r.design is None
    with pytest.raises(InputError, match="EIGOPT route"):
        lpvsyn(gp, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine", gamma_rtol=0.01)


def test_structures_the_eigopt_route_does_not_carry_are_refused_with_the_reason(tiny_memory):
    gp = oscillator_gp()
    with pytest.raises(ResourceLimit, match=r"GiB.*EIGOPT route does not apply: it uses the affine basis"):
        lpvsyn(gp, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="constant")
    with pytest.raises(InputError, match="found gain_basis"):
        lpvsyn(gp, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine",
               gain_basis=Basis.trigonometric(), method="eigopt")
    # output feedback: the plant with its state measured as y
    A, B, C = gp.A, np.concatenate([gp.B1, gp.B2], axis=-1), gp.C1
    n = A.shape[-1]
    Cy = np.concatenate([C, np.broadcast_to(np.eye(n), A.shape)], axis=-2)
    D = np.zeros(Cy.shape[:-1] + (B.shape[-1],))
    D[..., :C.shape[-2], :] = np.concatenate([gp.D11, gp.D12], axis=-1)
    with pytest.raises(ResourceLimit, match="found output feedback with nmeas = 2"):
        lpvsyn((A, B, Cy, D), 2, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine")
    with pytest.raises(InputError, match="method"):
        lpvsyn(gp, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine", method="lmi")


@pytest.mark.slow
def test_2_3_plant_on_a_2_x_1_grid_reproduces_the_bisection():
    # the design of `tmfem control lpv --preset 2-3-lpv` (EIGOPT bisection, its default rtol,
    # budget and upper level) on the 2 x 1 grid of the design21 fixture: lpvsyn chooses the EIGOPT
    # route by itself (the SDP would need ~184 GiB) and gives the bisection's gamma and gains
    from tmfem.control.lpv.defaults import GAMMA_RTOL
    from tmfem.control.lpv.generalized_plant import interconnection_8_1
    from tmfem.control.lpv.plant import com_lpv_plant
    from tmfem.reference.tables import deployment_bases
    from tmfem.system import load_preset
    s = load_preset("2-3-lpv")
    pl = com_lpv_plant(s, theta=np.radians([63.0, 77.32]), psi=np.radians([8.36]), bases=deployment_bases(s),
                       rate_bounds=np.radians([[-10.0, 10.0], [-10.0, 10.0]]))
    gp = interconnection_8_1(pl, tracked=s.q_names)
    lb = pointwise_state_feedback_bound(gp).lower_bound
    ref, _ = bisect_gamma(gp, lower=lb, upper=2 * lb, rtol=GAMMA_RTOL)
    r = lpvsyn(gp, 0, gp.sizes["n_u"], grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine",
               verify_refine=1)
    assert r.info["method"] == "eigopt"
    assert r.gamma == pytest.approx(ref.gamma, rel=1e-12)
    assert r.gamma == pytest.approx(4.7394, rel=1e-4)           # docs/guides/lpvsyn.md
    for rho in ([np.radians(63.0), np.radians(8.36)], [np.radians(70.0), np.radians(8.36)]):
        K = ref.gain(rho)
        np.testing.assert_allclose(r.controller.at(rho)[3], K, rtol=1e-8, atol=1e-10 * np.abs(K).max())
    assert r.verification["passed"]                              # at the design points


def test_options_of_the_other_route_are_refused():
    gp = oscillator_gp()
    with pytest.raises(InputError, match=r"\['backoff'\] belong to the SDP route"):
        lpvsyn(gp, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine", method="eigopt", backoff=0.1)
