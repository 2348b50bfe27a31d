"""The LPV logs and messages name grid points in degrees with units (the scheduling angles
theta_13, psi_13 of 8.3 are stored in radians). Reference: numpy's radians/degrees
conversion of the grid point the bound itself returns (``PointwiseBound.at``, radians)."""
import logging

import numpy as np

from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.plant import grid_point_text


def test_grid_point_text_gives_angles_in_degrees_and_other_parameters_as_given():
    assert grid_point_text(["theta_13", "psi_13"], np.radians([64.0, 25.0])) == \
        "theta_13 = 64 deg, psi_13 = 25 deg"
    assert grid_point_text(["rho0"], [0.5]) == "rho0 = 0.5"
    assert grid_point_text(["theta_13"], None) == "none"


def unstable_first_order():
    """x' = theta x + w + b u, p = [x; u] with b = 1 / (1 + theta) on a 3 x 2 grid of
    (theta_13, psi_13) [rad]."""
    th, ps = np.radians([10.0, 20.0, 30.0]), np.radians([5.0, 15.0])
    shp = (th.size, ps.size)
    A = np.broadcast_to(th[:, None, None, None], shp + (1, 1)).copy()
    one = np.ones(shp + (1, 1))
    gp = GeneralizedLPV.from_matrices(axes=[th, ps], parameter_names=["theta_13", "psi_13"],
                                      rate_bounds=[[-0.1, 0.1], [-0.1, 0.1]], A=A, B1=one, B2=one / (1 + A),
                                      C1=np.concatenate([one, 0 * one], axis=-2),
                                      D11=np.zeros(shp + (2, 1)), D12=np.concatenate([0 * one, one], axis=-2))
    return gp, th


def test_the_worst_grid_point_of_the_pointwise_bound_is_logged_in_degrees(caplog):
    # |T_pw| >= sqrt(1 + k^2) / (b k - theta) > 1 / b for every stabilising u = -k x, so
    # gamma_SF >= 1 + theta grows with theta: the worst point is at the grid's largest theta
    gp, th = unstable_first_order()
    with caplog.at_level(logging.INFO, logger="tmfem.control.lpv.bounds"):
        b = pointwise_state_feedback_bound(gp)
    assert b.at[0] == th[-1] and b.lower_bound >= (1 + th[-1]) * (1 - 1e-4)
    text = f"theta_13 = 30 deg, psi_13 = {np.degrees(b.at[1]):.4g} deg"
    assert any(text in r.getMessage() for r in caplog.records), [r.getMessage() for r in caplog.records]


def test_lpvsyn_verification_names_its_worst_point_and_rate_vertex_in_degrees():
    from tmfem.control.lpv import lpvsyn
    gp, _ = unstable_first_order()
    r = lpvsyn(gp, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine", method="sdp")
    v = r.verification
    rho, rate = (np.degrees(x) for x in v["max_lmi_eig_at"])                # stored in rad, rad/s
    assert f"at theta_13 = {rho[0]:.4g} deg, psi_13 = {rho[1]:.4g} deg, theta_13' = {rate[0]:.4g} deg/s, " \
           f"psi_13' = {rate[1]:.4g} deg/s" in v["summary"]
    assert "rho = [" not in v["summary"] and abs(abs(rate[0]) - np.degrees(0.1)) < 1e-9
