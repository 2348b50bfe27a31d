"""The exact rate of the ch. 3 design along a configuration angle
(:mod:`tmfem.design.design_derivative`) against the independent check: the fourth-order
central difference (8 (f(h) - f(-h)) - (f(2h) - f(-2h))) / 12h of the design re-run at the
moved angles (:func:`tmfem.design.configuration.with_angles`), h = 1e-3 deg: truncation
O(h^4) below 1e-12 relative, rounding of the design (its residual about 1e-15) / h about
1e-10. On the 1-4, 2-3 and 1-4D presets and the user 1-N system tests/data/systems/triangle-1-3.toml,
mesh_n=4 with the point attachment, and on 1-4 also mesh_n=12 with the distributed one (its
patch needs nodes)."""
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from tmfem.design.configuration import angle_direction, design_of, with_angles
from tmfem.design.design_derivative import design_rate, euler_R_second_derivatives, node_rates
from tmfem.equilibrium.general import euler_R_derivatives, node_jacobian
from tmfem.errors import InputError
from tmfem.system import load_preset, load_system

TRIANGLE = Path(__file__).parents[1] / "data" / "systems" / "triangle-1-3.toml"
STEP = 1e-3                                                  # [deg]


def central(f, p0, h=STEP):
    """Fourth-order central difference of f at p0."""
    return (8 * (f(p0 + h) - f(p0 - h)) - (f(p0 + 2 * h) - f(p0 - 2 * h))) / (12 * h)


def redesigned(system, angle, stage, *, attachment, mesh_n):
    """p -> the design's fields at the angle p [deg] (all others at the system's)."""
    def fields(p):
        d = design_of(with_angles(system, {(angle, stage): p}), mesh_n=mesh_n, attachment=attachment)
        return np.concatenate([d.rest_lengths, d.tendon_forces, d.nodes.ravel(), d.corner_forces.ravel()])
    return fields


CASES = [(load_preset("1-4"), a, 0, "point", 4) for a in ("theta", "psi")] + \
        [(load_preset("1-4"), a, 0, "distributed", 12) for a in ("theta", "psi")] + \
        [(load_preset("2-3"), a, i, "point", 4) for a in ("theta", "psi") for i in (0, 1)] + \
        [(load_system(TRIANGLE), a, 0, "point", 4) for a in ("theta", "psi")] + \
        [(load_preset("1-4D"), a, 0, "point", 4) for a in ("theta", "psi")]


@pytest.mark.parametrize("system, angle, stage, attachment, mesh_n", CASES,
                         ids=[f"{s.name}-{a}_{i + 1}-{at}" for s, a, i, at, _ in CASES])
def test_the_design_rate_matches_the_central_difference_of_the_redesigned_system(system, angle, stage,
                                                                                  attachment, mesh_n):
    d = design_of(system, mesh_n=mesh_n, attachment=attachment)
    dq, dbase = angle_direction(system, angle, stage)
    rate = design_rate(d, dq=dq, dbase=dbase)
    exact = np.concatenate([rate.rest_lengths, rate.tendon_forces, rate.nodes.ravel(),
                            rate.corner_forces.ravel()])
    p0 = float(np.degrees(getattr(system.symmetric, angle)[stage]))
    fd = central(redesigned(system, angle, stage, attachment=attachment, mesh_n=mesh_n), p0)
    nt, nn = len(system.tendons), d.nodes.size
    parts = (("rest lengths", slice(0, nt), d.rest_lengths),
             ("tendon forces", slice(nt, 2 * nt), d.tendon_forces),
             ("nodes", slice(2 * nt, 2 * nt + nn), d.nodes),
             ("corner forces", slice(2 * nt + nn, None), d.corner_forces))
    assert np.abs(fd[:2 * nt]).min() > 0                       # the angle moves every tendon
    for part, sl, value in parts:
        # relative to the rate, or to the value per degree where the angle does not move the
        # part (a stage-1 angle of a 2-3 system leaves the membrane's corners)
        scale = max(np.abs(fd[sl]).max(), 1e-3 * np.abs(value).max())
        assert np.abs(exact[sl] - fd[sl]).max() < 1e-8 * scale, part


def test_the_node_and_rotation_second_derivatives_match_their_first_derivatives_differenced():
    # J' of eqs. 3.19-3.20 against a central difference of J, d^2 R^ef of eq. 3.3 against complex steps of
    # dR^ef (exact to rounding): J' along a random q', d^2 R along each gamma_l
    system = load_preset("2-3")
    rng = np.random.default_rng(1)
    dq = rng.standard_normal(system.q.size)
    J, _, dJ = node_rates(system, dq=dq, dbase=np.zeros_like(system.base))
    h = 1e-30
    # J depends on q only through the bar angles; the central difference of J along dq with
    # t = 1e-7 has truncation O(t^2), 1e-14, and rounding eps / t, 1e-9
    t = 1e-7
    fd = (node_jacobian(system, system.q + t * dq) - node_jacobian(system, system.q - t * dq)) / (2 * t)
    assert np.abs(dJ - fd).max() < 1e-7 * np.abs(J).max()
    gamma = np.array([0.3, -0.4, 0.7])
    dd = euler_R_second_derivatives(gamma)
    for m in range(3):
        g = gamma.astype(complex)
        g[m] += 1j * h
        assert np.allclose(dd[:, :, :, m], euler_R_derivatives(g).imag / h, rtol=0, atol=1e-14)


@pytest.mark.parametrize("attachment, mesh_n", [("point", 4), ("distributed", 12)])
def test_the_tension_field_design_rate_matches_the_central_difference(attachment, mesh_n):
    # the membrane's corner forces move by the law's consistent tangent
    system = load_preset("1-4")
    d = design_of(system, mesh_n=mesh_n, attachment=attachment, membrane_law="tension-field")
    assert np.any(d.membrane_model.wrinkling(_dofs(d))["state"] != 0)      # some elements wrinkle
    for angle in ("theta", "psi"):
        dq, dbase = angle_direction(system, angle, 0)
        exact = design_rate(d, dq=dq, dbase=dbase).rest_lengths
        p0 = float(np.degrees(getattr(system.symmetric, angle)[0]))
        fd = central(lambda p: design_of(with_angles(system, {(angle, 0): p}), mesh_n=mesh_n, attachment=attachment,
                                         membrane_law="tension-field").rest_lengths, p0)
        assert np.abs(exact - fd).max() < 1e-8 * np.abs(fd).max()


def test_a_design_with_a_tendon_self_stress_of_its_own_has_no_rate():
    # such a design picks its forces among the self-stress states by a linear programme
    d = design_of(load_preset("2-3"), mesh_n=2)
    dq, dbase = angle_direction(d.system, "theta", 0)
    with pytest.raises(InputError, match="2 self-stress states"):
        design_rate(dataclasses.replace(d, self_stress_dim=2), dq=dq, dbase=dbase)


def _dofs(design):
    """The membrane's DOF vector of a design's plane-stress solution."""
    basis = design.membrane_model.basis
    x = np.zeros(basis.N)
    x[basis.nodal_dofs] = design.membrane.u
    return x
