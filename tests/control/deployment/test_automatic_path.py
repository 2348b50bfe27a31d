"""The automatic deployment path of an M >= 2 system (tmfem.equilibrium.deployment_path):
it ends on both designs, keeps Delta linear between its end values (eq. 3.22), every point it
was checked at is a symmetric equilibrium by an independent test (the LP of 3.2 on the
reduced matrix of 3.3.2, and the rest lengths of the equilibrium design of ch. 3), and a
path that cannot be found is a named error saying where and why."""
import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog

from tmfem.equilibrium.deployment_path import (SymmetricPath, automatic_path, membrane_stiffness,
                                               path_feasibility, top_radius_for_delta)
from tmfem.equilibrium.design import design_equilibrium
from tmfem.equilibrium.general import null_space, symmetric_matrix
from tmfem.equilibrium.symmetric_map import configuration_5_97, with_configuration
from tmfem.errors import InfeasibleDesign
from tmfem.system import load_preset, load_system

SYSTEMS = Path(__file__).resolve().parents[2] / "data" / "systems"


@pytest.fixture(scope="module")
def tower():
    """The user 2-5 of tests/data/systems: (system, packaged configuration, kappa)."""
    f = load_system(SYSTEMS / "pentagon-2-5.toml")
    kappa = membrane_stiffness(design_equilibrium(f, strict=False))
    return f, f.problem.packaged.symmetric, kappa


def lp_margin(system, cfg) -> float:
    """The null-vector margin of 3.2 by the LP over the null-space coordinates written out
    here (scipy HiGHS), independent of positive_null_vector's one-vector shortcut."""
    A = symmetric_matrix(with_configuration(system, cfg)).A
    Z, _ = null_space(A, 1e-9)
    k = Z.shape[1]
    res = linprog(np.r_[np.zeros(k), -1.0], A_ub=np.hstack([-Z, np.ones((Z.shape[0], 1))]),
                  b_ub=np.zeros(Z.shape[0]), A_eq=[np.r_[Z.sum(axis=0), 0.0]], b_eq=[1.0],
                  bounds=[(None, None)] * k + [(None, 1.0)], method="highs")
    return float(res.x[-1])


def test_top_radius_solves_eq_3_22():
    # both roots of eq. 3.22 give the Delta asked for (SymmetricConfig.membrane_delta, the
    # closed form of eq. 3.22); `near` picks the root closest to it
    f = load_system(SYSTEMS / "pentagon-2-5.toml")
    c = f.symmetric
    kw = dict(l_M=1.8, theta_M=np.radians(60.0), psi_rel=np.radians(15.0), r_mb=f.r_mb, Delta=2e-3, N=5)
    lo, hi = top_radius_for_delta(**kw), top_radius_for_delta(**kw, near=10.0)
    assert lo < hi
    for r2 in (lo, hi):
        cfg = dataclasses.replace(c, theta=np.radians([60.0, 60.0]), psi=c.sigma + np.radians(15.0),
                                  r=np.array([c.r[0], r2]))
        assert cfg.membrane_delta(5, f.r_mb) == pytest.approx(2e-3, abs=1e-12)


def test_linear_bases_slacken_a_tendon_the_automatic_path_does_not(tower):
    f, packaged, kappa = tower
    straight = SymmetricPath(system=f, initial=packaged, final=f.symmetric)
    bad = straight.point(0.3, kappa=kappa)
    assert bad.margin < 0 and "P2" in bad.reason
    assert lp_margin(f, straight.config(0.3)) == pytest.approx(bad.margin, abs=1e-10)
    rep = automatic_path(f, packaged, kappa=kappa, r_min=1e-3)
    assert rep.evaluations > 0 and rep.checked.size == 101 and rep.min_margin > 0
    p = rep.path
    D0, De = (c.membrane_delta(5, f.r_mb) for c in (packaged, f.symmetric))
    for s in np.linspace(0.0, 1.0, 11):
        cfg = p.config(s)
        # Delta linear in s between the designs' values (eq. 3.22)
        assert cfg.membrane_delta(5, f.r_mb) == pytest.approx(D0 + s * (De - D0), abs=1e-12)
        # eq. 5.97 kept: one theta, one psi relative to the stage base
        assert np.ptp(cfg.theta) < 1e-12 and np.ptp(cfg.psi - cfg.sigma) < 1e-12
        # a symmetric equilibrium by the independent LP, taut tendons in the ch. 3 design
        assert lp_margin(f, cfg) > 0
        d = design_equilibrium(with_configuration(f, cfg), strict=False)
        assert d.tendon_forces.min() > 0 and np.all(d.rest_lengths < d.tendon_lengths)
    for s, end in ((0.0, packaged), (1.0, f.symmetric)):
        for k in ("theta", "psi", "sigma", "z", "r"):
            assert np.allclose(getattr(p.config(s), k), getattr(end, k), atol=1e-9), (s, k)


def test_the_2_3_linear_bases_are_already_feasible():
    # the 2-3 of 7.4.3: the automatic path needs no correction (0 evaluations) and every
    # checked point is an equilibrium; its rule differs from Table 7.7's (Delta 1 mm fixed)
    f = load_preset("2-3-deploy")
    kappa = membrane_stiffness(design_equilibrium(f.replace(rest_lengths=None), strict=False))
    rep = automatic_path(f, f.problem.packaged.symmetric, kappa=kappa, r_min=1e-3)
    assert rep.evaluations == 0 and rep.min_margin > 0.01
    assert lp_margin(f, rep.path.config(rep.at)) == pytest.approx(rep.min_margin, abs=1e-10)


def test_no_path_is_a_named_error_with_the_obstacle(tower):
    # a packaged design of the same 2-5 (theta 78 deg, psi 28 deg, sigma_2 = -60 deg, a
    # feasible equilibrium) from which neither the straight bases nor the optimiser's
    # corrections stay taut: the error gives s, theta, psi and the slack group, and the
    # independent LP confirms that group's sign there
    f, _, kappa = tower
    packaged = configuration_5_97(f, np.radians(78.0), np.radians(28.0), r=[0.9, 0.9573],
                                  z=[0.0, 0.257], sigma=[0.0, np.radians(-60.0)])
    assert path_feasibility(f, packaged, kappa=kappa).margin > 0
    with pytest.raises(InfeasibleDesign, match=r"fails at s = [0-9.]+ \(theta = \[.*\] deg, psi = "
                                               r"\[.*\] deg\): no positive null vector of 3.3.2: "
                                               r"force sign of .*P2") as e:
        automatic_path(f, packaged, kappa=kappa, maxiter=60)
    s = float(str(e.value).split("fails at s = ")[1].split(" ")[0])
    straight = SymmetricPath(system=f, initial=packaged, final=f.symmetric)
    assert lp_margin(f, straight.config(s)) < 0


def test_rest_lengths_below_the_limit_are_named(tower):
    # eq. 3.9 with the tendon forces scaled to kappa Delta: a limit above the shortest rest
    # length of the deployed design is refused, naming that tendon and its rest length
    f, _, kappa = tower
    d = design_equilibrium(f, strict=False)
    k = int(np.argmin(d.rest_lengths))
    p = path_feasibility(f, f.symmetric, kappa=kappa, r_min=d.rest_lengths[k] + 1e-3)
    # the group's members are equal by symmetry; the value is the design's (eq. 3.9)
    assert p.margin < 0 and f"rest length of {d.tendon_names[k][:-1]}" in p.reason
    assert f" {d.rest_lengths[k]:.4g} m below" in p.reason
    assert path_feasibility(f, f.symmetric, kappa=kappa, r_min=d.rest_lengths[k] - 1e-3).reason == ""


def test_a_three_stage_path_ends_on_both_designs_through_equilibria():
    # any M: a 3-3 of our own (tests/data/systems/tower-3-3.toml); the corrected parameters
    # are r_2, z_2, z_3, sigma_2, sigma_3 (r_3 follows Delta by eq. 3.22); the straight line
    # is feasible here, every checked point has a positive null vector by the LP of 3.2 over
    # the two-dimensional null space of the 12 x 14 matrix, Delta linear in s; a correction of
    # r_2 moves r_2 by its sine terms and leaves Delta on its line
    from tmfem.reference.deployments import automatic_path_of, checked_configurations
    f = checked_configurations(load_system(SYSTEMS / "tower-3-3.toml"))
    rep = automatic_path_of(f, r_min=1e-3)
    p = rep.path
    assert p.names == ["r_2", "z_2", "z_3", "sigma_2", "sigma_3"] and rep.min_margin > 0
    assert null_space(symmetric_matrix(f).A, 1e-9)[0].shape[1] == 2
    a, b = f.problem.packaged.symmetric, f.symmetric
    D0, De = a.membrane_delta(3, f.r_mb), b.membrane_delta(3, f.r_mb)
    for s in (0.0, 0.25, 0.5, 0.75, 1.0):
        cfg = p.config(s)
        assert lp_margin(f, cfg) > 0
        assert cfg.membrane_delta(3, f.r_mb) == pytest.approx(D0 + s * (De - D0), abs=1e-12)
    assert np.allclose(p.config(1.0).r, b.r, atol=1e-9) and np.allclose(p.config(0.0).sigma, a.sigma)
    coefficients = np.zeros((5, 3))
    coefficients[0, 0] = 0.05                     # r_2 += 0.05 sin(pi s)
    bent = SymmetricPath(system=f, initial=a, final=b, coefficients=coefficients)
    c = bent.config(0.5)
    assert c.r[1] == pytest.approx(p.config(0.5).r[1] + 0.05, abs=1e-12)
    assert c.membrane_delta(3, f.r_mb) == pytest.approx(0.5 * (D0 + De), abs=1e-12)
