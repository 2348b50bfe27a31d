"""The equilibria of a gridded LPV plant give every bar azimuth on (-pi, pi]; an azimuth that
passes +-pi between grid points is interpolated on one turn (GriddedLPV.on_turn), and the
LPV deployment takes the grid's equilibria on the turn of its reference (the three-stage
tower of tests/data/systems/tower-3-3-lpv.toml, whose psi_32 goes from 3.118 rad at
theta_13 = 60 deg to -3.024 at 55 deg)."""
from pathlib import Path

import numpy as np
import pytest

from tmfem.control.lpv.plant import GriddedLPV
from tmfem.system import load_system

TOWER = Path(__file__).resolve().parents[2] / "data" / "systems" / "tower-3-3-lpv.toml"


def plant(psi_values):
    """A 3 x 1 grid with the states [psi_1, x_1] and the output [psi_1] (A, B, C, D of no
    interest), x_e = [psi, 0.5], y_e = [psi]."""
    n = len(psi_values)
    x_e = np.zeros((n, 1, 2))
    x_e[:, 0, 0], x_e[:, 0, 1] = psi_values, 0.5
    return GriddedLPV(axes=[np.arange(float(n)), [0.0]], parameter_names=["theta_13", "psi_13"],
                      A=np.zeros((n, 1, 2, 2)), B=np.zeros((n, 1, 2, 1)), C=np.zeros((n, 1, 1, 2)),
                      D=np.zeros((n, 1, 1, 1)), rate_bounds=[[-1, 1], [-1, 1]],
                      state_names=["psi_1", "x_1"], input_names=["r_1"], output_names=["psi_1"],
                      x_e=x_e, y_e=x_e[..., :1].copy())


def test_an_azimuth_passing_pi_between_grid_points_is_interpolated_on_one_turn():
    # 3.0 -> -3.1 -> -2.9 rad is 3.0 -> 3.1832 -> 3.3832 on one turn (whole turns of 2 pi
    # added); half-way between the first two points the angle is their mean on that turn,
    # 3.0916, where the grid as given interpolates through 0 (-0.05)
    p = plant([3.0, -3.1, -2.9])
    assert p.interpolate("x_e", [0.5, 0.0])[0] == pytest.approx(-0.05, abs=1e-12)
    t = p.on_turn([0.0, 0.0], {"psi_1": 3.0})
    want = np.array([3.0, -3.1 + 2 * np.pi, -2.9 + 2 * np.pi])
    np.testing.assert_allclose(t.x_e[:, 0, 0], want, rtol=0, atol=1e-15)
    np.testing.assert_allclose(t.y_e[:, 0, 0], want, rtol=0, atol=1e-15)
    assert t.interpolate("x_e", [0.5, 0.0])[0] == pytest.approx((3.0 + want[1]) / 2, abs=1e-12)
    np.testing.assert_array_equal(t.x_e[:, 0, 1], 0.5)                       # not an angle: untouched
    # on the turn of the reference: a start at 3.0 - 2 pi moves the whole grid by -2 pi
    t2 = p.on_turn([0.0, 0.0], {"psi_1": 3.0 - 2 * np.pi})
    np.testing.assert_allclose(t2.x_e[:, 0, 0], want - 2 * np.pi, rtol=0, atol=1e-15)


def test_a_plant_on_its_turn_is_returned_unchanged():
    p = plant([2.0, 2.5, 3.0])
    assert p.on_turn([1.0, 0.0], {"psi_1": 2.4}) is p


@pytest.mark.slow
def test_the_towers_lpv_deployment_takes_the_grids_equilibria_on_the_reference():
    # the 3 x 1 grid of the file (theta 55, 57.5, 60 deg at psi 10 deg): along the reference
    # of eq. 5.100 the interpolated x_e(rho_r(t)) follows q_d(t) to the grid's interpolation
    # error (3.8e-3 rad or m at most), where the grid as given is off by 1.53 rad at t = 2 s
    # and by 2 pi from theta_13 = 57.5 deg on (psi_32 on the other turn)
    from tmfem.control.lpv.plant import com_lpv_plant
    from tmfem.reference.deployments import lpv_bases, lpv_setup
    s = load_system(TOWER)
    pl = com_lpv_plant(s, theta=np.radians([55.0, 57.5, 60.0]), psi=np.radians([10.0]), bases=lpv_bases(s))
    dep = lpv_setup(s, pl)
    nq = dep.model.nq
    k = list(s.q_names).index("psi_32")
    assert pl.x_e[2, 0, k] == pytest.approx(3.1181, abs=1e-4) and pl.x_e[1, 0, k] < -3.0
    err = max(np.abs(np.asarray(dep.reference(t)[0]) - dep.plant.interpolate("x_e", dep.reference_rho(t))[:nq]).max()
              for t in np.arange(0.0, 20.01, 0.5))
    assert err < 0.01
    raw = np.abs(np.asarray(dep.reference(2.0)[0]) - pl.interpolate("x_e", dep.reference_rho(2.0))[:nq]).max()
    assert raw > 1.0
    np.testing.assert_array_equal(dep.plant.u_e, pl.u_e)
