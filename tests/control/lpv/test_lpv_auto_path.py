"""The LPV grid on the automatic deployment path (`[lpv] path = "auto"`, the default for
M >= 3): the stage bases at a grid point (theta, psi) are the path's at the progress whose
theta is the grid's. The three-stage 3-3 of tests/data/systems/tower-3-3-lpv.toml (39
tendons, 36 bar coordinates) against the path of the 7.4 deployment
(tmfem.equilibrium.deployment_path.automatic_path, checked there at 101 points), eq. 3.22
(Delta), eqs. 3.8-3.9 (rest lengths below the tendon lengths)."""
from pathlib import Path

import numpy as np
import pytest

from tmfem.errors import InfeasibleDesign, InputError
from tmfem.system import load_system
from tmfem.system.problem import lpv_path

SYSTEMS = Path(__file__).resolve().parents[2] / "data" / "systems"
TOWER = SYSTEMS / "tower-3-3-lpv.toml"


@pytest.fixture(scope="module")
def tower():
    from tmfem.reference.deployments import automatic_path_of, checked_configurations, lpv_bases
    s = load_system(TOWER)
    path = automatic_path_of(checked_configurations(s), r_min=1e-3).path
    return s, lpv_bases(s), path


def test_the_default_rule_is_the_automatic_path_beyond_two_stages():
    assert lpv_path(load_system(TOWER)) == "auto"
    assert lpv_path(load_system(SYSTEMS / "pentagon-2-5-lpv.toml")) == "table-7-7-bases"
    assert lpv_path(load_system(SYSTEMS / "pentagon-2-5.toml")) == "table-7-7-bases"


@pytest.mark.parametrize("theta", [55.0, 57.5, 60.0])
def test_grid_points_on_the_paths_azimuth_are_the_paths_configurations(tower, theta):
    # psi = 10 deg is the path's own azimuth (both ends psi_i - sigma_i = 10 deg): the grid's
    # configuration of eq. 5.97 is the path's at s = (theta - 60) / (55 - 60)
    from tmfem.equilibrium.symmetric_map import configuration_5_97
    s, bases, path = tower
    th, ps = np.radians(theta), np.radians(10.0)
    cfg = configuration_5_97(s, th, ps, **bases(th, ps))
    ref = path.config((theta - 60.0) / (55.0 - 60.0))
    for k in ("theta", "psi", "sigma", "z", "r"):
        np.testing.assert_allclose(getattr(cfg, k), getattr(ref, k), rtol=0, atol=1e-9, err_msg=k)


def test_off_the_paths_azimuth_the_membrane_keeps_the_paths_stretch(tower):
    # psi = 12 deg: r_3 from eq. 3.22 for the path's Delta(s); the other bases are the path's
    from tmfem.equilibrium.symmetric_map import configuration_5_97
    s, bases, path = tower
    th, ps = np.radians(57.5), np.radians(12.0)
    b = bases(th, ps)
    cfg = configuration_5_97(s, th, ps, **b)
    ref = path.config(0.5)
    assert cfg.membrane_delta(s.N, s.r_mb) == pytest.approx(path.delta(0.5), rel=1e-10)
    np.testing.assert_allclose(b["z"], ref.z, atol=1e-12)
    np.testing.assert_allclose(b["sigma"], ref.sigma, atol=1e-12)
    np.testing.assert_allclose(b["r"][:-1], ref.r[:-1], atol=1e-12)
    assert b["r"][-1] != pytest.approx(ref.r[-1], abs=1e-4)


def test_outside_the_paths_angles_the_nearer_ends_bases_are_taken(tower):
    s, bases, path = tower
    for theta, end in ((54.0, path.final), (61.0, path.initial)):
        b = bases(np.radians(theta), np.radians(10.0))
        np.testing.assert_allclose(b["z"], end.z, atol=1e-12)
        np.testing.assert_allclose(b["sigma"], end.sigma, atol=1e-12)


def test_an_infeasible_grid_point_names_theta_psi_and_the_condition(tower):
    s, bases, _ = tower
    with pytest.raises(InfeasibleDesign, match=r"theta = 57\.5 deg, psi = 30 deg .*positive null vector"):
        bases(np.radians(57.5), np.radians(30.0))


def test_a_one_stage_system_has_no_lpv_grid():
    from tmfem.reference.deployments import lpv_bases
    # a 1-N(D) deploys with psi moving (eq. 3.22): packaged (87.6, 30.4), deployed (75, 24) deg
    with pytest.raises(InputError, match=r"M = 1: a 1-N\(D\) system deploys along the Delta rule of eq. 3.22.*"
                                         r"packaged \(87.6, 30.4\) deg and deployed \(75, 24\) deg"):
        lpv_bases(load_system(SYSTEMS / "pentagon-1-5D.toml"))
    with pytest.raises(InputError, match="M = 1: a 1-N system's reduced equilibrium matrix of 3.3.2 is square"):
        lpv_bases(load_system(SYSTEMS / "pentagon-1-5.toml"))


def test_the_auto_path_needs_a_packaged_configuration(tmp_path):
    from tmfem.reference.deployments import lpv_bases
    text = TOWER.read_text()
    start = text.index("[packaged]")
    f = tmp_path / "t.toml"
    f.write_text(text[:start] + text[text.index("[deployment]"):])
    with pytest.raises(InputError, match=r"expected a symmetric \[packaged\] configuration"):
        lpv_bases(load_system(f))


@pytest.mark.slow
def test_the_grids_equilibria_are_the_paths_designs(tower):
    # a 3 x 2 grid (theta 55, 57.5, 60 deg; psi 10, 12 deg) of COM linearisations: at psi =
    # 10 deg the equilibrium q_e of every point is the path's configuration (eqs. 3.19-3.20),
    # at psi = 12 deg it has the path's Delta; every rest length u_e lies in (r_min, |tendon|)
    # (every tendon in tension, eqs. 3.8-3.9) and the 39 inputs stay in the plant
    from tmfem.control.deployment.limits import tendon_lengths
    from tmfem.control.lpv.plant import com_lpv_plant
    from tmfem.equilibrium.symmetric_map import configuration_5_97, with_configuration
    s, bases, path = tower
    th, ps = np.radians([55.0, 57.5, 60.0]), np.radians([10.0, 12.0])
    pl = com_lpv_plant(s, theta=th, psi=ps, bases=bases)
    assert pl.grid_shape == (3, 2) and pl.nu == 39 and pl.nx == 2 * (36 + 3)
    nq = 36
    for a, theta in enumerate([55.0, 57.5, 60.0]):
        q = pl.x_e[a, 0, :nq]
        np.testing.assert_allclose(q, path.config((theta - 60.0) / -5.0).to_q(s.N), rtol=0, atol=1e-6)
        for b in range(2):
            cfg = configuration_5_97(s, th[a], ps[b], **bases(th[a], ps[b]))
            sb = with_configuration(s, cfg)
            L = tendon_lengths(sb, pl.x_e[a, b, :nq])
            assert np.all(pl.u_e[a, b] > 1e-3) and np.all(pl.u_e[a, b] < L)
        d12 = configuration_5_97(s, th[a], ps[1], **bases(th[a], ps[1])).membrane_delta(s.N, s.r_mb)
        assert d12 == pytest.approx(path.delta((theta - 60.0) / -5.0), rel=1e-10)


class Command:
    """A controller that commands fixed rest lengths (the protocol of tmfem.simulation.controllers)."""

    name = "fixed"

    def __init__(self, u):
        self.u = u

    def reset(self, t0, y0, dt):
        return np.zeros(0)

    def output(self, t, y, xc):
        return self.u

    def update(self, t, y, xc):
        return xc


def test_an_over_actuated_command_outside_the_limits_is_allocated_as_the_pfl_inverts(tower):
    # the 3-3's COM at its deployed design (39 rest lengths, 36 bar coordinates, a wide B_q of
    # eq. 5.41): a command whose first tendon is 5 mm longer than its tendon is replaced by the
    # admissible rest lengths whose bar acceleration is closest to the command's in the metric
    # M_q (compared with SLSQP on the same problem without the regularisation, an independent
    # solver), inside [r_min, |tendon| - f (L_d - u_d)]; a command inside passes unchanged
    from scipy.optimize import minimize
    from tmfem.control.deployment.limits import tendon_lengths
    from tmfem.control.deployment.pfl import partition
    from tmfem.control.lpv.deployment import MinimumChangeAllocation
    from tmfem.models.com.model import ControlOrientedModel
    from tmfem.reference.deployments import checked_configurations
    s = checked_configurations(tower[0])
    m = ControlOrientedModel(s, membrane_modes=3, rest_lengths="system")
    z = m.equilibrium(m.u0).state
    y = np.concatenate([z, np.zeros(m.nz)])
    L = tendon_lengths(s, z[:m.nq]).copy()
    ref = lambda t: (z[:m.nq], None, None)                                   # noqa: E731
    inside = MinimumChangeAllocation(Command(m.u0), model=m, reference=ref, u_d=lambda t: m.u0)
    assert np.array_equal(inside.output(0.0, y, None), m.u0) and inside.allocation_active == []
    u_c = m.u0.copy()
    u_c[0] = L[0] + 5e-3
    a = MinimumChangeAllocation(Command(u_c), model=m, reference=ref, u_d=lambda t: m.u0, floor=0.5)
    u = a.output(0.0, y, None)
    upper = L - 0.5 * (L - m.u0)
    assert a.allocation_active == [0.0]
    assert np.all(u >= 1e-3) and np.all(u <= upper + 1e-12)
    terms = partition(*m.matrices(z, np.zeros(m.nz)), nq=m.nq)
    R = np.linalg.cholesky(0.5 * (terms.M_q + terms.M_q.T)).T
    A = R @ terms.B_q
    cost = lambda v: float(np.sum((A @ (v - u_c))**2))                      # noqa: E731
    ref_sol = minimize(cost, np.clip(u_c, 1e-3, upper), jac=lambda v: 2 * A.T @ (A @ (v - u_c)),
                       bounds=list(zip(np.full(u.size, 1e-3), upper)), method="SLSQP",
                       options={"ftol": 1e-16, "maxiter": 500})
    assert cost(u) <= ref_sol.fun * (1 + 1e-6) + 1e-14
    # clipping the first tendon alone misses the commanded acceleration by more
    assert cost(np.clip(u_c, 1e-3, upper)) > 10 * cost(u)
