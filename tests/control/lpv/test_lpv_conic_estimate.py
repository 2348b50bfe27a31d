"""The conic LPV state-feedback synthesis (``tmfem control lpv --solver SCS|CLARABEL``,
tmfem.control.lpv.synthesis) estimates its memory and CPU time from the problem size and
refuses, before anything is built, what exceeds the memory limit or its time budget.

References: the decision-variable count of a 2-6 two-stage interconnection on a 2 x 2 grid
(134 states, 42 tendon inputs: 3 (134 * 135 / 2 + 42 * 134) + 1 = 44,020 variables, the affine
basis of eq. 5.99), which held about 7 GB under SCS and did not finish in 20 minutes; the
cubic time law and its constant measured by benchmarks/bench_lpvsyn.py --conic-states."""
import time

import numpy as np
import pytest

from tmfem.control.lpv.cost import SECONDS_PER_VARIABLE_CUBED, conic_cost
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.errors import ResourceLimit
from tmfem.resources import MAX_SYNTHESIS_S, memory_limit


def plant(n: int, nw: int, nu: int, npp: int) -> GeneralizedLPV:
    """A stable plant of these sizes on a 2 x 2 grid (x' = -(1 + rho_1 + rho_2) x + B1 w + B2 u)."""
    rng = np.random.default_rng(0)
    shp = (2, 2)
    A = np.stack([[-(1.0 + 0.1 * (i + j)) * np.eye(n) for j in range(2)] for i in range(2)])
    tile = lambda M: np.broadcast_to(M, shp + M.shape).copy()          # noqa: E731
    return GeneralizedLPV.from_matrices(
        axes=[np.array([0.0, 1.0])] * 2, parameter_names=["theta_13", "psi_13"],
        rate_bounds=[[-0.17, 0.17]] * 2, A=A, B1=tile(rng.standard_normal((n, nw))),
        B2=tile(rng.standard_normal((n, nu))), C1=tile(np.eye(npp, n)), D11=np.zeros(shp + (npp, nw)),
        D12=tile(np.vstack([np.zeros((npp - nu, nu)), np.eye(nu)])))


def test_the_user_sized_problem_is_refused_up_front_with_its_estimate():
    gp = plant(134, 42, 42, 84)
    t0 = time.perf_counter()
    with pytest.raises(ResourceLimit) as exc:
        synthesize_state_feedback(gp, solver="SCS")
    msg = str(exc.value)
    assert time.perf_counter() - t0 < 5.0                                # nothing built
    assert "LPV state-feedback synthesis (SCS): 134 states, 4 grid points x 4 rate vertices" in msg
    assert "16 LMIs of order 260" in msg and "44,020 variables" in msg
    days = SECONDS_PER_VARIABLE_CUBED * 44020.0**3 / 86400
    assert f"{days:.3g} days of CPU" in msg
    assert f"the time limit {MAX_SYNTHESIS_S:g} CPU s (time_budget, `tmfem control lpv --time-budget` " \
           "raises it)" in msg
    # more than the ~7 GB the run that did not finish had reached
    scs = conic_cost({"decision_variables": 44020, "n_x": 134, "n_u": 42, "n_w": 42, "n_p": 84,
                      "grid_points": 4, "rate_vertices": 4}, solver="SCS")
    assert scs.memory_bytes > 7e9
    assert ("exceeds the memory limit" in msg) == (scs.memory_bytes > memory_limit())


def test_the_interior_point_solver_is_refused_on_memory_whatever_the_time_budget():
    with pytest.raises(ResourceLimit, match=r"LPV state-feedback synthesis \(CLARABEL\): 134 states.*exceeds "
                                            r"the memory limit [\d.]+ GiB \(60% of this machine's"):
        synthesize_state_feedback(plant(134, 42, 42, 84), solver="CLARABEL", time_budget=1e12)


def test_a_small_problem_runs_within_its_estimate_and_a_tight_budget_refuses_it():
    gp = plant(4, 1, 1, 2)
    with pytest.raises(ResourceLimit, match=r"4 LMIs|16 LMIs"):
        synthesize_state_feedback(gp, solver="CLARABEL", time_budget=1e-9)
    c0 = time.process_time()
    r = synthesize_state_feedback(gp, solver="CLARABEL")
    assert r.gamma > 0 and r.sizes["decision_variables"] == 3 * (4 * 5 // 2 + 4) + 1
    est = conic_cost(r.sizes, solver="CLARABEL")
    assert est.decision_variables == r.sizes["decision_variables"]
    # the estimate is a fit of larger sizes (157 to 1333 variables); at 43 variables the
    # solve is dominated by fixed costs, so only its order is checked
    assert est.seconds < 1.0 and time.process_time() - c0 < 30.0
