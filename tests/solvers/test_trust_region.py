"""The trust-region Newton of tmfem.solvers.trust_region on a problem whose round-off floor is
known: a spring whose residual carries a deterministic error of 1e-7 of the force scale."""
import numpy as np
import pytest

from tmfem.errors import ConvergenceError
from tmfem.solvers.trust_region import trust_region_newton

K = 100.0          # spring stiffness [N/m]
F = 1.0            # applied force [N]: the force scale
NOISE = 1e-7       # the residual's floor [N]


def spring(noise):
    """W(u) = K u^2 / 2 - F u (+1 J, so that energy changes are relative to a unit energy) and
    its residual K u - F + noise sign(K u - F): an error that keeps |r| >= noise everywhere,
    as the round-off of stiff elements keeps a residual from falling further."""
    def residual(u):
        d = K * u[0] - F
        return np.array([d + noise * (1.0 if d >= 0 else -1.0)]), np.array([[K]])

    def energy(u):
        return 1.0 + 0.5 * K * u[0] ** 2 - F * u[0]
    return residual, energy


def solve(noise, tol):
    residual, energy = spring(noise)
    return trust_region_newton(residual, energy, np.zeros(1), free=np.ones(1, bool),
                               scale=np.ones(1), force_scale=lambda u: F, tol=tol,
                               newton_first=True)


def test_the_spring_reaches_its_closed_form_equilibrium():
    res = solve(0.0, 1e-12)
    assert res.u[0] == pytest.approx(F / K, rel=1e-14)


def test_a_floor_below_1e3_tol_ends_the_iteration_on_it():
    res = solve(NOISE, 1e-9)            # 1e3 x tol = 1e-6 of F: the floor 1e-7 is accepted
    assert abs(res.u[0] - F / K) <= 2 * NOISE / K
    assert res.residual_history[-1] <= 2 * NOISE


def test_a_floor_above_1e3_tol_is_named_with_the_tol_that_ends_on_it():
    floor = r"round-off floor lies above the 1000 x tol = 1e-09 .* use tol >= 1e-09"
    with pytest.raises(ConvergenceError, match=floor):
        solve(NOISE, 1e-12)             # 1e3 x tol = 1e-9 of F, below the floor 1e-7
