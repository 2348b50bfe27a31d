"""Continuation in the grid of the gamma bisection (tmfem.control.lpv.bisect): with the
sampled-loop LMI the bisection first runs on the grid with the last parameter collapsed to its
middle value and starts the full grid from that design (docs/guides/lpv.md)."""
import numpy as np
import pytest

from tmfem.control.lpv.bisect import bisect_gamma, collapsed
from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
from tmfem.control.lpv.coordinates import Coordinates
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.verify import verify
from tmfem.errors import InputError


def two_parameter_oscillator(n_a=3, n_b=3):
    """x'' + (0.1 + 0.2 b) x' + (1 + a) x = u + w, p = [x, 0.3 u], a in [0, 2], b in [0, 1],
    |a'|, |b'| <= 0.5/s: A affine in (a, b), so any grid of the box holds the true plants."""
    a, b = np.linspace(0, 2, n_a), np.linspace(0, 1, n_b)
    s = (n_a, n_b)
    A = np.array([[[[0, 1], [-(1 + ai), -0.1 - 0.2 * bj]] for bj in b] for ai in a])
    B = np.broadcast_to([[0.0], [1.0]], s + (2, 1))
    gp = GeneralizedLPV.from_matrices(
        axes=[a, b], parameter_names=["a", "b"], rate_bounds=[[-0.5, 0.5], [-0.5, 0.5]], A=A, B1=B, B2=B,
        C1=np.broadcast_to([[1.0, 0], [0, 0]], s + (2, 2)), D11=np.zeros(s + (2, 1)),
        D12=np.broadcast_to([[0.0], [0.3]], s + (2, 1)))
    gp.state_names = ["x", "v"]
    return gp


def sampled_radius(ctrl, gp, dt):
    """Largest spectral radius of A_d + B_d K(rho) over the grid (python-control sample_system)."""
    import control
    out = 0.0
    for idx in np.ndindex(*gp.grid_shape):
        rho = [ax[i] for ax, i in zip(gp.axes, idx)]
        sd = control.sample_system(control.ss(gp.A[idx], gp.B2[idx], np.eye(2), 0), dt, method="zoh")
        out = max(out, np.abs(np.linalg.eigvals(sd.A + sd.B @ ctrl.gain(rho))).max())
    return out


def test_collapsed_grid_is_the_middle_line():
    gp = two_parameter_oscillator(3, 3)
    sub = collapsed(gp, 1)
    assert sub.grid_shape == (3, 1) and sub.axes[1].tolist() == [0.5]
    np.testing.assert_array_equal(sub.A[:, 0], gp.A[:, 1])
    np.testing.assert_array_equal(sub.D12[:, 0], gp.D12[:, 1])
    np.testing.assert_array_equal(sub.rate_bounds, gp.rate_bounds)
    assert sub.state_names == gp.state_names


@pytest.mark.slow
def test_sampled_bisection_starts_from_the_collapsed_grid_design():
    # dt = 0.9 s on the oscillator's 3 x 3 grid: by default the bisection first runs on the
    # 3 x 1 grid (b = 0.5); the full grid's first level starts from that design extended with
    # zero b-coefficients, which is the sub-grid design on its line, and the result holds the
    # gridded LMIs and the sampled loops on a 4x finer grid (true plants: A affine)
    gp, dt = two_parameter_oscillator(), 0.9
    lb = pointwise_state_feedback_bound(gp).lower_bound
    ctrl, br = bisect_gamma(gp, lower=lb, upper=2 * lb, rtol=0.05, sample_time=dt)
    assert br.start_grid == [3, 1] and br.start_levels and br.start_levels[0]["start"] == "riccati"
    sub_gamma = min(lv["gamma"] for lv in br.start_levels if lv["result"] == "feasible")
    sub_nf = [lv["gamma"] for lv in br.start_levels if lv["result"] == "not found"]
    run = [lv for lv in br.levels if "carried" not in lv["result"]]
    assert run[0]["start"] == f"sub-grid design 3x1 (gamma {sub_gamma:.5g})"
    # the first full level: the lowest where the extended sub-grid design holds as it is, or
    # (here: it holds nowhere below the upper level) the upper level
    assert run[0]["result"] == "feasible" and (run[0]["gamma"] == 2 * lb or run[0]["evaluations"] == 0)
    assert lb <= ctrl.gamma <= 2 * lb
    # the highest sub-grid level not found is carried as the full grid's lo
    if sub_nf and max(sub_nf) > lb:
        assert br.levels[0]["result"] == "not found on the 3x1 sub-grid (carried)"
        assert br.levels[0]["gamma"] == max(sub_nf) <= br.not_found < ctrl.gamma
    assert br.to_dict()["gamma_start_grid"] == [3, 1]
    fine = two_parameter_oscillator(9, 9)
    v = verify(ctrl, fine, sample_time=dt)
    assert v.passed and v.max_sampled_radius == pytest.approx(sampled_radius(ctrl, fine, dt), rel=1e-9)
    assert sampled_radius(ctrl, fine, dt) < 1
    # the extension: the sub-grid design's coefficients in the full grid's coordinates have
    # P_b = Q_b = 0 and give its P(rho), Q(rho) on the line b = 0.5
    sub = collapsed(gp, 1)
    sub_ctrl, _ = bisect_gamma(sub, lower=lb, upper=2 * lb, rtol=0.05, sample_time=dt)
    co = Coordinates.of(gp)
    Ps, Qs = co.coefficients_of(sub_ctrl, gp)
    assert len(Ps) == 3 and not Ps[2].any() and not Qs[2].any()
    for a in gp.axes[0]:
        c = co.c_of([a, 0.5])
        np.testing.assert_allclose(co.T[:, None] * sum(ck * P for ck, P in zip(c, Ps)) * co.T[None, :],
                                   sub_ctrl.P_of([a, 0.5]), rtol=1e-12, atol=1e-12)


def test_grid_continuation_only_where_it_applies():
    gp = two_parameter_oscillator()
    lb = pointwise_state_feedback_bound(gp).lower_bound
    # without a sample time the Riccati start is used (no sub-grid stage)
    _, br = bisect_gamma(gp, lower=lb, upper=2 * lb, rtol=0.2)
    assert br.start_grid is None and br.start_levels == [] and br.levels[0]["start"] == "riccati"
    with pytest.raises(InputError, match="at least two parameters"):
        bisect_gamma(collapsed(gp, 1), lower=lb, upper=2 * lb, sample_time=0.5, grid_continuation=True)
    ctrl, _ = bisect_gamma(gp, lower=lb, upper=2 * lb, rtol=0.2)
    with pytest.raises(InputError, match="no given start"):
        bisect_gamma(gp, lower=lb, upper=2 * lb, sample_time=0.5, start=ctrl, grid_continuation=True)


def test_a_full_grid_design_restricted_to_the_line_is_a_sub_grid_design():
    # why a level not found on the collapsed grid is carried into the full grid's bracket: the
    # full grid's P(rho), Q(rho) on the line b = 0.5 (normalised b = 0) hold the sub-grid's LMIs
    # at the same gamma (its points are full-grid points; the rate vertices +-v_b average out)
    from tmfem.control.lpv.state_feedback import LPVStateFeedback
    gp = two_parameter_oscillator()
    lb = pointwise_state_feedback_bound(gp).lower_bound
    ctrl, _ = bisect_gamma(gp, lower=lb, upper=2 * lb, rtol=0.05)
    assert ctrl.varying == [0, 1]
    sub = collapsed(gp, 1)
    line = LPVStateFeedback(gamma=ctrl.gamma, P=ctrl.P[:2], Q=ctrl.Q[:2], center=ctrl.center,
                            half_width=ctrl.half_width, varying=[0], axes=sub.axes, parameter_names=["a", "b"],
                            rate_bounds=ctrl.rate_bounds, state_names=ctrl.state_names, solver="restricted",
                            status="", solve_time=0.0, build_time=0.0, sizes={}, max_lmi_eig=np.nan, min_P_eig=np.nan)
    for a in gp.axes[0]:
        np.testing.assert_allclose(line.gain([a, 0.5]), ctrl.gain([a, 0.5]), rtol=1e-12, atol=1e-12)
    assert verify(line, sub).passed


def test_first_level_of_a_given_start_is_its_lowest_free_level():
    # a design feasible at g1 given as the start with the upper level 4 x the bound: the first
    # level is the lowest gamma where it holds as it is (to rtol / 4), found without iterating;
    # 2 % below it the same P, Q fail the LMI (verify), so the level is the design's own
    import dataclasses
    gp = two_parameter_oscillator()
    lb = pointwise_state_feedback_bound(gp).lower_bound
    d1, _ = bisect_gamma(gp, lower=lb, upper=2 * lb, rtol=0.3)
    ctrl, br = bisect_gamma(gp, lower=lb, upper=4 * lb, rtol=0.05, start=d1)
    first = br.levels[0]
    assert first["start"] == "given design" and first["result"] == "feasible" and first["evaluations"] == 0
    assert first["gamma"] <= d1.gamma * (1 + 0.05 / 4) and first["gamma"] < 4 * lb
    assert verify(dataclasses.replace(d1, gamma=first["gamma"]), gp).passed
    assert not verify(dataclasses.replace(d1, gamma=0.98 * first["gamma"]), gp, allow_failure=True).passed
    # without it the first level is the upper one, as before
    _, br0 = bisect_gamma(gp, lower=lb, upper=4 * lb, rtol=0.05, start=d1, first_free=False)
    assert br0.levels[0]["gamma"] == 4 * lb
