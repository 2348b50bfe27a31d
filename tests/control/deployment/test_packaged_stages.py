"""The packaged configuration of a symmetric M >= 2 system
(tmfem.control.deployment.packaged.packaged_stages): a feasible equilibrium by independent
tests (the LP of 3.2 over the null space of the reduced matrix of 3.3.2, the ch. 3 equilibrium
design of a system at that configuration with its strict checks), the deployed Delta kept
(eq. 3.22, here from the design's corner displacements, eq. 3.5), eq. 5.97 kept (one theta,
one psi relative to the stage bases), the automatic path from it feasible, and a theta without
any feasible packaged equilibrium a named error."""
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

from tests.control.deployment.test_automatic_path import lp_margin
from tmfem.control.deployment.packaged import packaged_stages
from tmfem.equilibrium.deployment_path import automatic_path, membrane_stiffness, path_feasibility
from tmfem.equilibrium.design import design_equilibrium
from tmfem.equilibrium.symmetric_map import with_configuration
from tmfem.errors import InfeasibleDesign, InputError
from tmfem.system import load_system

SYSTEMS = Path(__file__).resolve().parents[2] / "data" / "systems"


@lru_cache
def packaged(file, theta_deg):
    """(system, packaged_stages result) of the user system ``file`` at ``theta_deg``."""
    f = load_system(SYSTEMS / file)
    return f, packaged_stages(f, theta_deg=theta_deg)


def check_packaged(f, r, theta_deg):
    """Every property the packaged configuration ``r`` of ``f`` must have (module docstring)."""
    cfg = r["config"]
    kappa = membrane_stiffness(design_equilibrium(f.replace(rest_lengths=None), strict=False))
    assert np.allclose(np.degrees(cfg.theta), theta_deg, atol=1e-12)
    assert np.ptp(cfg.psi - cfg.sigma) < 1e-12                          # eq. 5.97
    assert np.allclose(cfg.l, f.symmetric.l) and cfg.r[0] == f.symmetric.r[0]
    # a positive null vector by the LP written out in the tests, the rest lengths above r_min
    assert lp_margin(f, cfg) == pytest.approx(r["margin"], abs=1e-9) and r["margin"] > 0
    assert path_feasibility(f, cfg, kappa=kappa, r_min=1e-3).reason == ""
    # the ch. 3 design at the packaged configuration passes its strict checks; its Delta (from
    # the corner displacements of eq. 3.5) is the deployed design's
    d0 = design_equilibrium(f.replace(rest_lengths=None), strict=True)
    d = design_equilibrium(with_configuration(f, cfg), strict=True)
    assert d.ok and d.tendon_forces.min() > 0 and np.all(d.rest_lengths >= 1e-3)
    assert d.Delta == pytest.approx(d0.Delta, abs=1e-9)
    assert r["Delta"] == pytest.approx(r["Delta_deployed"], abs=1e-12)
    # the printed entries are the configuration (angles to 1e-4 deg, lengths to 1e-6 m)
    s = r["symmetric"]
    assert np.allclose(s["psi_deg"], np.degrees(cfg.psi), atol=1e-9)
    assert np.allclose(s["sigma_deg"], np.degrees(cfg.sigma), atol=1e-9)
    assert np.allclose(s["z"], cfg.z, atol=1e-12) and np.allclose(s["r"], cfg.r, atol=1e-9)
    # the automatic path from it, checked again here
    rep = automatic_path(f, cfg, kappa=kappa, r_min=1e-3)
    assert rep.min_margin > 0 and rep.checked.size == r["path"]["points_checked"] == 101
    assert rep.min_margin == pytest.approx(r["path"]["min_margin"], rel=1e-9)


@pytest.mark.slow
def test_packaged_stages_are_a_feasible_start_of_the_automatic_path():
    f, r = packaged("pentagon-2-5.toml", 78.0)
    check_packaged(f, r, 78.0)
    assert r["candidates"] >= 1 and r["psi_step_deg"] == 10.0


@pytest.mark.slow
def test_the_2_5_gets_the_bases_found_by_hand():
    # the file's [packaged] was made by hand with r_2 from eq. 3.22 for the deployed Delta at
    # theta 78 deg, psi 20 deg, z_2 = 0.153 m and sigma_2 = 0 near the largest null vector; the
    # search arrives at the same psi, the same root of 3.22 and bases near the hand-made ones
    f, r = packaged("pentagon-2-5.toml", 78.0)
    hand = f.problem.packaged.symmetric
    assert r["symmetric"]["psi_deg"][0] == pytest.approx(np.degrees(hand.psi[0]))
    assert r["symmetric"]["r"][1] == pytest.approx(hand.r[1], abs=1e-4)
    assert r["symmetric"]["z"][1] == pytest.approx(hand.z[1], abs=0.03)
    assert r["symmetric"]["sigma_deg"][1] == pytest.approx(np.degrees(hand.sigma[1]), abs=5.0)


@pytest.mark.slow
def test_the_bases_keep_half_the_largest_margin_nearer_the_deployed_ones():
    # the largest-margin bases at the chosen psi and r_2 (best_bases, the same search): the
    # packaged bases keep at least half its margin (up to the rounding of the printed values)
    # and lie nearer to the deployed bases
    from tmfem.equilibrium.symmetric_map import best_bases
    f, r = packaged("pentagon-2-5.toml", 78.0)
    cfg, c, l = r["config"], f.symmetric, 1.8
    b = best_bases(f, cfg.theta[0], cfg.psi[0], starts=2, maxiter=100, r_top=cfg.r[1],
                   r_bounds=(0.025 * l, 1.1 * l), z_bounds=(0.025 * l, 1.4 * l))
    assert r["margin"] >= 0.5 * b["margin"] - 1e-4

    def distance(z, sigma):
        return np.hypot((z - c.z[1]) / l, np.angle(np.exp(1j * (sigma - c.sigma[1]))))
    assert distance(cfg.z[1], cfg.sigma[1]) < distance(b["z"][1], b["sigma"][1])


@pytest.mark.slow
def test_packaged_stages_of_a_three_stage_system():
    # the 3-3: r_2, z_2, z_3, sigma_2, sigma_3 searched with r_3 from eq. 3.22
    check_packaged(*packaged("tower-3-3.toml", 60.0), 60.0)


@pytest.mark.slow
def test_a_finer_psi_grid_where_the_coarse_candidates_have_no_path():
    # the 2-6 at theta = 70 deg: the feasible candidates of the 10 deg grid have no automatic
    # path (a named error without refinement, with the obstacle); the 5 deg grid has one
    f, r = packaged("hexagon-2-6.toml", 70.0)
    with pytest.raises(InfeasibleDesign, match=r"none of the \d+ feasible packaged equilibria at theta = 70 "
                                               r"deg .* has a path to the deployed configuration; the last: "
                                               r"deployment path: .*fails at s = "):
        packaged_stages(f, theta_deg=70.0, refinements=0)
    assert r["psi_step_deg"] == 5.0 and r["symmetric"]["psi_deg"][0] % 10 == 5
    check_packaged(f, r, 70.0)


def test_no_packaged_equilibrium_is_a_named_error():
    # at theta = 30 deg no stage base of the 2-5 has a positive null vector with the deployed
    # Delta; the error names the condition and eq. 3.22's psi range; a coarse psi grid here
    f = load_system(SYSTEMS / "pentagon-2-5.toml")
    with pytest.raises(InfeasibleDesign, match=r"no feasible equilibrium at theta = 30 deg \(psi in \[-80, 80\] "
                                               r"deg in steps down to 20 deg.*\): no positive null "
                                               r"vector of 3.3.2 \(\d+ candidates\)"):
        packaged_stages(f, theta_deg=30.0, psi_step_deg=20.0, refinements=0)


def test_packaged_stages_refuse_other_systems():
    with pytest.raises(InputError, match="expected a symmetric system with M >= 2 stages, found 1-5"):
        packaged_stages(load_system(SYSTEMS / "pentagon-1-5D.toml"), theta_deg=80.0)
    with pytest.raises(InputError, match="expected 0 < theta < 90 deg"):
        packaged_stages(load_system(SYSTEMS / "pentagon-2-5.toml"), theta_deg=95.0)
