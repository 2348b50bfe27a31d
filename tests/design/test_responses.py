"""Every response of the design sensitivities against central finite differences of the
re-solved equilibrium, for rest lengths, the membrane thickness and the bar and tendon
diameters (mesh_n=4, equilibrium to a residual of 1e-12 of the member forces).

The differences are Richardson-extrapolated central differences (4 D(h) - D(2h)) / 3, error
O(h^4), with h = 5e-4 m on rest lengths, 1 % of a thickness or diameter and 0.1 % of the
membrane radius: the membrane
strains are 1e-6 to 1e-4, so its stresses carry the equilibrium's round-off at smaller steps.
A derivative is compared relative to its own size, or to a tenth of the response's logarithmic
scale |f| / |p| where it is smaller than that: the bar forces depend on the bar diameter by
2e-5 of that scale, a change of 3e-6 N in a difference, at the equilibrium's round-off of
the stiff bars' forces (1e-5 N)."""
import numpy as np
import pytest

from tmfem.design import design_sensitivities
from tmfem.design.sensitivities import RESPONSES
from tmfem.design.variables import apply_design, parse_variables, variable_values
from tmfem.errors import InputError
from tmfem.models.mtc.model import MTCModel
from tmfem.models.sbc.model import SBCModel
from tmfem.system import load_preset

SCALARS = ["mass", "tendon_force_min", "tendon_stress_max", "bar_buckling_max", "corner_delta_max",
           "membrane_von_mises", "membrane_min_principal", "surface_rms"]
VECTORS = ["omega2", "freq", "tendon_force", "tendon_stress", "bar_force", "bar_buckling", "corner_delta"]
OPTIONS = {"k": 4, "aperture": 0.8}


def stacked(s, names):
    vals = np.concatenate([np.atleast_1d(s.value(n)) for n in names])
    grads = np.concatenate([np.reshape(s.gradient(n), (-1, len(s.names))) for n in names])
    return vals, grads


def fd_check(system, variables, names, rest_lengths=None):
    """Exact and finite-difference derivatives (n_responses, n_var), the values and the
    design; ``rest_lengths``: start there instead of the model's default."""
    m = MTCModel(system, mesh_n=4, rest_lengths=rest_lengths)
    r0 = m.rest_lengths.copy()
    eq = m.equilibrium(tol=1e-12)
    vs = parse_variables(system, variables)
    p0 = variable_values(system, r0, vs)
    f0, exact = stacked(design_sensitivities(m, equilibrium=eq, variables=variables, **OPTIONS), names)

    def values(p):
        sj, rj = apply_design(system, r0, vs, p)
        mj = MTCModel(sj, mesh_n=4, rest_lengths=rj)
        ej = mj.equilibrium(x0=eq.state, tol=1e-12)
        return stacked(design_sensitivities(mj, equilibrium=ej, variables=variables, **OPTIONS), names)[0]

    steps = [{"rest_length": 5e-4, "membrane_radius": 1e-3 * x}.get(v.kind, 0.01 * x) for v, x in zip(vs, p0)]
    return exact, richardson(values, p0, steps), f0, p0


def richardson(values, p0, steps):
    """Richardson-extrapolated central differences (4 D(h) - D(2h)) / 3 (n_responses, n_var) of
    ``values(p)`` about p0, with h = steps[j] on variable j."""
    cols = []
    for j, h in enumerate(steps):
        central = []
        for step in (h, 2 * h):
            p_plus, p_minus = p0.copy(), p0.copy()
            p_plus[j] += step
            p_minus[j] -= step
            central.append((values(p_plus) - values(p_minus)) / (2 * step))
        cols.append((4 * central[0] - central[1]) / 3)
    return np.column_stack(cols)


def rel_err(exact, fd, f0, p0):
    floor = 0.1 * np.abs(f0)[:, None] / np.abs(p0)[None, :]
    return np.abs(exact - fd) / np.maximum(np.abs(fd), floor)


def test_responses_of_1_4_for_every_kind_of_variable_match_finite_differences():
    # the 1-4 membrane stays flat (its corners coplanar by symmetry): surface_rms is checked
    # on an asymmetric design below
    names = [n for n in SCALARS if n != "surface_rms"] + VECTORS
    exact, fd, f0, p0 = fd_check(load_preset("1-4"), ["S1", "h_membrane", "d_bar", "d_S", "r_mb"], names)
    err = rel_err(exact, fd, f0, p0)
    assert np.all(err < 1e-5), err.max(axis=0)


def test_responses_of_two_stage_2_3_match_finite_differences():
    names = [n for n in SCALARS if n != "surface_rms"] + VECTORS      # flat by symmetry too
    exact, fd, f0, p0 = fd_check(load_preset("2-3"), ["S1", "V2", "d_V", "d_bar", "r_mb"], names)
    err = rel_err(exact, fd, f0, p0)
    assert np.all(err < 1e-5), err.max(axis=0)


def test_surface_deviation_of_a_warped_membrane_matches_finite_differences():
    # one tendon of 1-4 shortened by 2 cm warps the membrane out of its plane
    system = load_preset("1-4")
    r = MTCModel(system, mesh_n=4).rest_lengths.copy()
    r[0] -= 0.02
    exact, fd, f0, p0 = fd_check(system, "tendons", ["surface_rms", "corner_delta"], rest_lengths=r)
    assert f0[0] > 1e-4                         # a warp of more than 0.1 mm RMS
    err = rel_err(exact, fd, f0, p0)
    assert np.all(err < 1e-5), err


def test_mass_is_the_sum_of_the_members_and_the_membrane():
    # closed form: bars rho pi d^2 / 4 l, tendons rho A r, membrane rho h area (r_mb^2 N
    # sin(2 pi / N) / 2 of the regular polygon)
    system = load_preset("1-4")
    m = MTCModel(system, mesh_n=4)
    s = design_sensitivities(m, variables=["S1", "h_membrane", "d_bar", "d_S", "r_mb"])
    bar, sec, mem = system.bar, system.tendon_sections["S"], system.membrane
    area = system.r_mb**2 * system.N * np.sin(2 * np.pi / system.N) / 2
    tendon = sec.rho * sec.area * m.rest_lengths.sum()
    expected = bar.mass(1.0) * system.l.sum() + tendon + mem.rho * mem.h * area
    assert s.value("mass") == pytest.approx(expected, rel=1e-4)
    grad = [sec.rho * sec.area * 4, mem.rho * area, bar.rho * np.pi * bar.d / 2 * system.l.sum(),
            2 * tendon / sec.d, 2 * mem.rho * mem.h * area / system.r_mb]
    assert s.gradient("mass") == pytest.approx(grad, rel=1e-4)


def test_every_response_is_read_by_name():
    m = MTCModel(load_preset("1-4"), mesh_n=2)
    s = design_sensitivities(m, node="B_11", k=3)
    assert set(s.values) == set(RESPONSES)
    assert s.value("freq_2") == s.freq_hz[1] and np.array_equal(s.gradient("omega2_3"), s.d_omega2[2])
    assert s.value("tendon_force_max") == pytest.approx(s.max_tendon_force, rel=1e-12)
    assert s.value("tendon_force_min") <= s.value("tendon_force_max")
    assert s.value("membrane_min_principal") <= s.values["membrane_von_mises"]
    for bad, text in (("freq_9", "index 1..3"), ("lift", "expected one of"), (3, "a name")):
        with pytest.raises(InputError, match=text):
            s.value(bad)
    with pytest.raises(InputError, match="expected a node"):
        design_sensitivities(m, k=1).value("position")
    for kwargs, text in (({"aperture": 1e-3}, "found none on this mesh"), ({"aperture": -1.0}, "aperture"),
                         ({"ks_width": 0.0}, "ks_width")):
        with pytest.raises(InputError, match=text):
            design_sensitivities(m, k=1, **kwargs)


def test_variables_that_change_the_geometry_or_do_not_exist_are_refused():
    m = MTCModel(load_preset("1-4"), mesh_n=2)
    for variables, text in ((["psi_11"], "a stage 1..1"), (["theta_11"], "a stage 1..1"),
                            (["r_1"], "only the angles"),
                            (["d_Q"], "expected a tendon group"), (["S1", "S1"], "distinct"),
                            (["S1", "S_11"], "two variables"), ([], "at least one")):
        with pytest.raises(InputError, match=text):
            design_sensitivities(m, variables=variables)


@pytest.mark.parametrize("Model, variables", [(MTCModel, ["S1", "h_membrane", "d_bar", "d_S"]),
                                               (MTCModel, ["S1", "theta_1", "psi_1"]),
                                               (SBCModel, "groups"),
                                               (SBCModel, ["S1", "h_membrane", "d_bar", "d_S"]),
                                               (SBCModel, ["S1", "theta_1", "psi_1"])])
def test_petsc_backend_gives_the_gradients_of_scipy(Model, variables):
    # the same responses and gradients with PETSc's factorisation and SLEPc's modes on the
    # PETSc backend's equilibrium (measured: within 2e-8 of each column's largest)
    pytest.importorskip("petsc4py")
    out = []
    for backend in ("scipy", "petsc"):
        m = Model(load_preset("1-4"), mesh_n=4, backend=backend)
        s = design_sensitivities(m, equilibrium=m.equilibrium(tol=1e-12), variables=variables, k=4)
        out.append(stacked(s, SCALARS[:-1] + VECTORS))
    (f_s, g_s), (f_p, g_p) = out
    assert f_p == pytest.approx(f_s, rel=1e-7, abs=1e-9)
    assert np.all(np.abs(g_p - g_s) <= 1e-7 * np.abs(g_s).max(axis=0)), np.abs(g_p - g_s).max(axis=0)
