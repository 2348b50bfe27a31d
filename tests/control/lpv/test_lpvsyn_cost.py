"""The size estimate of lpvsyn's SDP and the up-front refusal of plants it cannot hold.

References: the decision-variable count of the assembled problem (``info["sizes"]`` of a
solved design, counted from the cvxpy variable) for the estimate's formula; the 2-3
interconnection of ch. 8 (71 states, 42 exogenous inputs and performance outputs, 21 controls:
``tmfem control lpv --preset 2-3-lpv``, grid 6 x 3, two rate-bounded parameters) for the
refusal, which must come before anything is built.
"""
import time

import numpy as np
import pytest

from tmfem.control.lpv import lpvsyn
from tmfem.control.lpv.cost import lpvsyn_cost
from tmfem.control.lpv.examples import rotating_spring
from tmfem.errors import ResourceLimit
from tmfem.resources import memory_limit


@pytest.mark.parametrize("nmeas, basis, constant", [(0, "affine", "X"), (2, "affine", "X"), (2, "affine", None)])
def test_variable_count_matches_the_assembled_problem(nmeas, basis, constant):
    P = rotating_spring(k0=0.2, k1=1.0, r=1.0, output_feedback=nmeas > 0)
    r = lpvsyn(P, nmeas, 2, grid=np.linspace(-np.pi, np.pi, 5), rate_bounds=0.5, basis=basis,
               constant=constant, backoff=0.05, require_verified=False)
    s = r.info["sizes"]
    n = s["n_x"]
    _, _, _, d = P(np.zeros(1))
    nw, np_ = d.shape[1] - 2, d.shape[0] - nmeas
    c = lpvsyn_cost(n=n, nw=nw, np_=np_, nu=2, ny=nmeas, points=s["grid_points"], vertices=s["rate_vertices"],
                    lyapunov_basis=len(s["basis"]), gain_basis=len(s["gain_basis"]), constant=constant)
    assert c.decision_variables == s["decision_variables"]
    assert c.lmis == s["lmis"] and c.lmi_size == s["lmi_size"]


def test_the_2_3_design_is_refused_up_front_with_the_estimate():
    n, nw, np_, nu, ny = 71, 42, 42, 21, 25
    theta, psi = np.linspace(-0.5, 0.5, 6), np.linspace(-0.2, 0.2, 3)
    for meas in (0, ny):                 # state feedback and output feedback on q and the points
        c = lpvsyn_cost(n=n, nw=nw, np_=np_, nu=nu, ny=meas, points=18, vertices=4, lyapunov_basis=3,
                        gain_basis=3)
        assert c.memory_bytes > memory_limit()
    rng = np.random.default_rng(0)
    A0 = -np.eye(n) + 0.1 * rng.standard_normal((n, n))
    B = rng.standard_normal((n, nw + nu))
    C = rng.standard_normal((np_, n))
    D = np.hstack([np.zeros((np_, nw)), np.vstack([np.zeros((np_ - nu, nu)), np.eye(nu)])])

    def plant(rho):
        return A0 + rho[0] * np.eye(n), B, C, D
    t0 = time.perf_counter()
    with pytest.raises(ResourceLimit, match=r"lpvsyn: 71 states, 18 grid points x 4 rate vertices.*GiB"):
        lpvsyn(plant, 0, nu, grid=[theta, psi], rate_bounds=0.17, basis="affine", method="sdp")
    # with method="auto" the affine state feedback goes to the EIGOPT route (test_lpvsyn_eigopt_route.py);
    # a basis that route does not carry is refused with the estimate and the reason
    with pytest.raises(ResourceLimit, match=r"GiB.*EIGOPT route does not apply: it uses the affine basis"):
        lpvsyn(plant, 0, nu, grid=[theta, psi], rate_bounds=0.17, basis="constant")
    assert time.perf_counter() - t0 < 5.0


def test_an_sdp_over_the_time_limit_is_refused_up_front_on_time_alone():
    # 60 states, one w, u and p, 2 grid points x 2 rate vertices, affine basis: 3,781 variables,
    # 2.2e-7 x 3781^3 ~ 11,900 CPU s by the measured cubic law, cones small enough for the memory
    from tmfem.control.lpv.cost import LPVSYN_SECONDS_PER_VARIABLE_CUBED
    from tmfem.resources import MAX_SYNTHESIS_S
    n = 60
    B, C, D = np.ones((n, 2)), np.eye(1, n), np.array([[0.0, 1.0]])
    c = lpvsyn_cost(n=n, nw=1, np_=1, nu=1, ny=0, points=2, vertices=2, lyapunov_basis=2, gain_basis=2)
    assert c.decision_variables == 2 * n * (n + 1) // 2 + 2 * n + 1 == 3781
    assert c.memory_bytes < memory_limit() and c.seconds == LPVSYN_SECONDS_PER_VARIABLE_CUBED * 3781.0**3
    t0 = time.perf_counter()
    with pytest.raises(ResourceLimit, match=rf"3,781 variables: about [\d.]+ GiB and [\d.]+ h of CPU\) exceeds the "
                                            rf"time limit {MAX_SYNTHESIS_S:g} CPU s; the EIGOPT route does not apply"):
        lpvsyn(lambda rho: (-(1 + rho[0]) * np.eye(n), B, C, D), 0, 1, grid=np.array([0.0, 1.0]), rate_bounds=0.1,
               basis="affine", method="sdp")
    assert time.perf_counter() - t0 < 5.0
