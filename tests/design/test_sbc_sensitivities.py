"""Design sensitivities of the SBC model (shells, beams, cables) against central finite
differences of its re-solved equilibrium: tendon-group rest lengths of 1-4 and of the
deployable 1-4D (Richardson-extrapolated differences at 5e-4 and 1e-3 m, equilibria on the
round-off floor: tol = TOL; a derivative is compared relative to its own size or, where smaller, to
a tenth of |f| / |p| as in test_responses.py). The eigenvalue derivatives need the modes'
refinement of :func:`tmfem.design.sensitivities._refined_modes`: with ARPACK's modes as they
come (residual 3e-4) the lowest pair of 1-4D was 7e-4 off."""
import numpy as np
import pytest

from tmfem.design import design_sensitivities
from tmfem.design.configuration import with_angles
from tmfem.design.sensitivities import _rest_length_map
from tmfem.design.variables import apply_design, parse_variables, variable_values
from tmfem.models.sbc.model import SBCModel
from tmfem.system import load_preset, load_system
from tests.design.test_angles import PENTAGON_D, fd_check as angle_fd_check
from tests.design.test_responses import rel_err, richardson

#: the equilibria's tolerance, relative to the member forces: the SBC model's round-off floor
#: (its stiff beams and shells) lies near 1e-9 of the forces, 1.4e-7 N of 103 N on 1-4, above
#: the 1e3 x tol a solve with tol = 1e-12 accepts as the floor on some CPUs; with 1e-11 every
#: solve ends on the floor itself (its residual is the same)
TOL = 1e-11
FORCES = ["mass", "tendon_force", "tendon_stress", "bar_force", "bar_buckling", "corner_delta",
          "membrane_von_mises", "membrane_min_principal"]


def stacked(s, names):
    return (np.concatenate([np.atleast_1d(s.value(n)) for n in names]),
            np.concatenate([np.reshape(s.gradient(n), (-1, len(s.names))) for n in names]))


def fd_check(preset):
    system = load_preset(preset)
    m = SBCModel(system, mesh_n=4)
    r0 = m.rest_lengths.copy()
    eq = m.equilibrium(tol=TOL)
    names = FORCES + ["omega2"]
    f0, exact = stacked(design_sensitivities(m, equilibrium=eq, variables="groups", k=4), names)
    G = _rest_length_map(m, parse_variables(system, "groups"))
    fd = np.zeros_like(exact)
    for j in range(G.shape[1]):
        central = []
        for h in (5e-4, 1e-3):
            vals = []
            for sgn in (1, -1):
                mj = SBCModel(system, mesh_n=4, rest_lengths=r0 + sgn * h * G[:, j])
                ej = mj.equilibrium(start=eq.state, tol=TOL)
                vals.append(stacked(design_sensitivities(mj, equilibrium=ej, variables="groups", k=4), names)[0])
            central.append((vals[0] - vals[1]) / (2 * h))
        fd[:, j] = (4 * central[0] - central[1]) / 3
    floor = 0.1 * np.abs(f0)[:, None] / r0.mean()
    err = np.abs(exact - fd) / np.maximum(np.abs(fd), floor)
    return err[:-4], err[-4:]


@pytest.mark.parametrize("preset", ["1-4", "1-4D"])
def test_sbc_rest_length_gradients_match_finite_differences(preset):
    err_forces, err_eig = fd_check(preset)
    assert np.all(err_forces < 1e-5), err_forces.max(axis=0)
    assert np.all(err_eig < 2e-5), err_eig          # worst 1.02e-5: omega_3^2 of 1-4D, along SL


def design_fd_check(preset, variables, rel_step, names, **options):
    """Relative errors (n_responses, n_var) of the exact derivatives of ``names`` against
    Richardson-extrapolated differences of the re-solved equilibrium with steps rel_step p0
    and 2 rel_step p0, and the exact derivatives."""
    system = load_preset(preset)
    m = SBCModel(system, mesh_n=4)
    r0 = m.rest_lengths.copy()
    eq = m.equilibrium(tol=TOL)
    vs = parse_variables(system, variables)
    p0 = variable_values(system, r0, vs)
    f0, exact = stacked(design_sensitivities(m, equilibrium=eq, variables=variables, k=4, **options), names)

    def values(p):
        sj, rj = apply_design(system, r0, vs, p)
        mj = SBCModel(sj, mesh_n=4, rest_lengths=rj)
        ej = mj.equilibrium(start=eq.state, tol=TOL)
        return stacked(design_sensitivities(mj, equilibrium=ej, variables=variables, k=4, **options), names)[0]

    return rel_err(exact, richardson(values, p0, rel_step * p0), f0, p0), exact


@pytest.mark.parametrize("preset", ["1-4", "1-4D"])
@pytest.mark.slow
def test_sbc_thickness_and_diameter_gradients_match_finite_differences(preset):
    # Richardson-extrapolated differences with 1 % and 2 % of each variable; the partial
    # derivatives of the shells and beams are the five-point difference of the rebuilt model
    # (exact for their polynomial dependence on h and d)
    variables = ["h_membrane", "d_bar", "d_" + load_preset(preset).tendons[0].family]
    err, exact = design_fd_check(preset, variables, 1e-2, FORCES + ["omega2"])
    assert np.abs(exact).max(axis=0).min() > 0
    assert np.all(err < 1e-5), err.max(axis=0)


@pytest.mark.parametrize("preset", ["1-4", "1-4D"])
def test_sbc_membrane_radius_gradients_match_finite_differences(preset):
    # differences with 0.1 % and 0.2 % of r_mb: the shells' reference mesh scales (measured
    # worst 9e-7, 1-4D's omega_2^2); the wrinkled area at a width of 10 kPa (test_wrinkled_area.py)
    err, exact = design_fd_check(preset, ["r_mb"], 1e-3, FORCES + ["wrinkled_area", "omega2"], wrinkle_width=1e4)
    assert np.all(np.abs(exact[[0, -4]]) > 0)                    # the mass and omega_1^2 move
    assert np.all(err < 1e-5), err.max(axis=0)


@pytest.mark.parametrize("system, variables", [
    (load_preset("1-4"), ["theta_1", "psi_1", "S1"]),
    (load_preset("1-4D"), ["theta_1", "psi_1"]),
    (load_system(PENTAGON_D), ["psi_1"]),
    (load_preset("2-3"), ["theta_2", "psi_1"]),
], ids=["1-4", "1-4D", "pentagon-1-5D", "2-3"])
def test_sbc_angle_gradients_match_finite_differences_of_the_redesigned_system(system, variables):
    # the SBC model takes from the ch. 3 design what the MTC model takes, the rest lengths and
    # (1-N) the pinned bases; the shells' and beams' reference placement follows the design
    # configuration rigidly, which moves no equilibrium. Differences as on the MTC model
    # (test_angles.py), each moved design re-solved from the neighbouring equilibrium
    # (measured worst 7e-6: omega_4^2 of 2-3 along psi_1)
    exact, fd, f0, p0 = angle_fd_check(system, variables, SBCModel, tol=TOL)
    assert np.abs(exact).max(axis=0).min() > 0            # every angle moves the responses
    err = rel_err(exact, fd, f0, p0)
    assert np.all(err < 1e-5), err.max(axis=0)


def test_the_sbc_equilibrium_depends_on_the_angles_only_through_the_rest_lengths():
    # the premise of the SBC angle sensitivities: with the same rest lengths, the SBC model of
    # the 2-3 preset moved to theta_1 = 50 deg, psi_2 = -20 deg (its beams' and shells'
    # reference placed there) reaches the same equilibrium (measured: positions within 4e-16 m,
    # tendon forces within 2e-13 N, bar forces within 2e-8 N of 18 N, the stiff beams' round-off,
    # the lowest eigenvalues within 4e-7, the modes' accuracy)
    system = load_preset("2-3")
    m = SBCModel(system, mesh_n=4)
    moved = SBCModel(with_angles(system, {("theta", 0): 50.0, ("psi", 1): -20.0}), mesh_n=4,
                     rest_lengths=m.rest_lengths.copy())
    assert not np.allclose(moved.X, m.X, rtol=0, atol=1e-3)             # the reference moved
    e0, e1 = m.equilibrium(tol=1e-12), moved.equilibrium(tol=1e-12)
    n = m.numbering.n_mtc_nodes
    assert np.abs(e1.state.x[:, :n] - e0.state.x[:, :n]).max() < 1e-12
    f0, f1 = m.member_forces(e0.state), moved.member_forces(e1.state)
    for k in ("tendon", "bar"):
        assert np.abs(f1[k] - f0[k]).max() < 1e-8 * np.abs(f0[k]).max()
    w0, w1 = m.modes(k=4, at=e0).omega2, moved.modes(k=4, at=e1).omega2
    assert np.allclose(w1, w0, rtol=2e-6, atol=0)
