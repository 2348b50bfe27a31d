"""The configuration angles theta_i, psi_i of symmetric M-N systems as design variables:
every response's derivative against central finite differences of the re-designed (ch. 3
design at the moved angles) and re-solved MTC equilibrium, Richardson-extrapolated
(4 D(h) - D(2h)) / 3 with a step h that moves the rest lengths by at most 5e-4 m (as on the
rest-length variables) and the bases by at most 1e-4 m (0.001 to 0.02 deg), on the 2-3,
1-4 and 1-4D presets (1-4D on the MTC model with H_1j held rigidly on the bars, as the ch. 3
design holds it) and the user systems tests/data/systems/square-2-4.toml and triangle-1-3.toml
(1-N systems: their bases move with r_1 of eq. 3.33; a 1-N(D) system's r_1 stays), mesh_n=4,
equilibrium to a residual of 1e-12 of the member forces. The same check on the SBC model is in
test_sbc_sensitivities.py."""
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from tmfem.design import design_sensitivities
from tmfem.design.configuration import design_rates, redesign_of, warm_start, with_angles
from tmfem.design.optimizer import optimize
from tmfem.design.variables import apply_design, parse_variables, variable_values
from tmfem.equilibrium.design import design_equilibrium
from tmfem.equilibrium.symmetric import delta_1N, force_density_ratio_1N, r1_1N, s1_length
from tmfem.errors import InfeasibleDesign, InputError
from tmfem.models.mtc.model import MTCModel
from tmfem.system import dump_system, load_preset, load_system
from tests.design.test_responses import OPTIONS, SCALARS, VECTORS, rel_err, richardson, stacked

DATA = Path(__file__).parents[1] / "data" / "systems"
SQUARE, TRIANGLE, PENTAGON_D = DATA / "square-2-4.toml", DATA / "triangle-1-3.toml", DATA / "pentagon-1-5D.toml"
NAMES = [n for n in SCALARS if n != "surface_rms"] + VECTORS        # flat membranes by symmetry


def fd_check(system, variables, Model=MTCModel, names=NAMES, tol=1e-12, **options):
    """Exact and Richardson-extrapolated derivatives of ``names`` on ``Model`` (MTCModel or
    SBCModel) at mesh_n=4 with the model's ``options``, equilibria to ``tol`` of the member
    forces, with the values and the design."""
    m = Model(system, mesh_n=4, **options)
    r0 = m.rest_lengths.copy()
    eq = m.equilibrium(tol=tol)
    vs = parse_variables(system, variables)
    p0 = variable_values(system, r0, vs)
    f0, exact = stacked(design_sensitivities(m, equilibrium=eq, variables=variables, **OPTIONS), names)
    redesign = redesign_of(m)

    def values(p):
        sj, rj = apply_design(system, r0, vs, p, redesign=redesign)
        mj = Model(sj, mesh_n=4, rest_lengths=rj, **options)
        ej = mj.equilibrium(tol=tol, **warm_start(mj, eq.state))
        return stacked(design_sensitivities(mj, equilibrium=ej, variables=variables, **OPTIONS), names)[0]

    steps = []
    for v in vs:
        h = 5e-4
        if v.kind == "angle":
            # a step that moves a rest length by 5e-4 m (as on the rest-length variables) and a
            # base by 1e-4 m at most: the triangle's pair omega_2^2 = omega_3^2 curves with psi_1
            # so that Richardson's O(h^4) with 2.4e-3 deg leaves 1e-6, with 0.01 deg 1e-2
            dr, da = design_rates(m, v.angle, v.stage)
            h = min(5e-4 / np.abs(dr).max(), 1e-4 / max(np.abs(da).max(), 1e-30))
        steps.append(h)
    return exact, richardson(values, p0, steps), f0, p0


@pytest.mark.parametrize("system, variables, options", [
    (load_preset("2-3"), ["theta_1", "psi_1", "theta_2", "psi_2", "S1"], {}),
    (load_system(SQUARE), ["theta_2", "psi_1", "V2"], {}),
    (load_preset("1-4"), ["theta_1", "psi_1", "S1"], {}),
    (load_system(TRIANGLE), ["theta_1", "psi_1"], {}),
    (load_preset("1-4D"), ["theta_1", "psi_1"], {"rigid_bar_points": True}),
], ids=["2-3", "square-2-4", "1-4", "triangle-1-3", "1-4D"])
def test_responses_of_the_angles_match_finite_differences_of_the_redesigned_system(system, variables, options):
    exact, fd, f0, p0 = fd_check(system, variables, **options)
    assert np.abs(exact[:, :-1]).max() > 0                # the angles do move the responses
    err = rel_err(exact, fd, f0, p0)
    assert np.all(err < 1e-5), err.max(axis=0)


def test_the_design_rates_of_a_1_n_system_match_its_closed_form():
    # eqs. 3.30, 3.33, 3.34, 3.36: with r_1 of eq. 3.33 every tendon S carries T = |S_1| ratio(psi)
    # F_Delta / (Delta + r_mb) with F_Delta = k Delta (the linear membrane; k from the design at
    # the start), and r = EA |S_1| / (T + EA); its derivatives by complex step (exact to rounding)
    base = load_system(TRIANGLE)
    c, N, r_mb = base.symmetric, base.N, base.r_mb
    cfg = dataclasses.replace(c, r=[r1_1N(l1=c.l[0], theta1=c.theta[0], psi1=c.psi[0], N=N)])
    system = base.replace(symmetric=cfg, **cfg.system_arrays(N))
    m = MTCModel(system, mesh_n=4)
    start = design_equilibrium(system, mesh_n=4)
    k, EA, l1 = start.F_Delta / start.Delta, system.tendon_EA[0], c.l[0]

    def closed(theta, psi):
        r1 = r1_1N(l1=l1, theta1=theta, psi1=psi, N=N)
        L = s1_length(l1=l1, theta1=theta, psi1=psi, r1=r1, N=N)
        delta = delta_1N(l1=l1, theta1=theta, psi1=psi, r_mb=r_mb, N=N)
        T = L * force_density_ratio_1N(psi1=psi, N=N) * k * delta / (delta + r_mb)
        return EA * L / (T + EA), r1

    assert np.allclose(start.rest_lengths, closed(c.theta[0], c.psi[0])[0], rtol=1e-10, atol=0)
    for angle, unit in (("theta", (1, 0)), ("psi", (0, 1))):
        h = 1e-30
        r, r1 = closed(c.theta[0] + 1j * h * unit[0], c.psi[0] + 1j * h * unit[1])
        dr, da = design_rates(m, angle, 0)
        # the design's exact rates: measured within 2.5e-13 (rest lengths) and 2e-16 (bases)
        assert np.allclose(dr, np.radians(r.imag / h), rtol=1e-11, atol=0)
        assert np.allclose(da, system.base / cfg.r[0] * np.radians(r1.imag / h), rtol=1e-13, atol=1e-15)


def test_a_1_n_base_follows_eq_3_33_and_keeps_an_equilibrium_design():
    # theta_1 = 62 deg, psi_1 = 9 deg on 1-4: the ch. 3 design's residual of eq. 3.16 stays at
    # the level of the start's (r_1 printed to 4 digits there), far below the 1e-3 it accepts;
    # without r_1 following eq. 3.33 it is 7e-3 at theta_1 = 62 deg alone
    system = load_preset("1-4")
    moved = with_angles(system, {("theta", 0): 62.0, ("psi", 0): 9.0})
    ratio = moved.symmetric.r[0] / system.symmetric.r[0]
    assert ratio == pytest.approx(np.sin(np.radians(62)) * np.sin(np.radians(9))
                                  / (np.sin(np.radians(60)) * np.sin(np.radians(10))), rel=1e-12)
    assert np.allclose(moved.base, ratio * system.base, rtol=0, atol=1e-15)
    start, d = design_equilibrium(system, mesh_n=4), design_equilibrium(moved, mesh_n=4)
    assert d.residual < 2 * start.residual < 2e-4


def test_the_fe_residual_of_an_m_n_system_depends_on_the_angles_only_through_the_rest_lengths():
    # the premise of the angle sensitivities: at the same reduced state and rest lengths the
    # MTC residual of the moved configuration is the same (bars' l, membrane mesh and, for
    # M >= 2, the pinned bases A_1j do not move with the angles)
    system = load_preset("2-3")
    m = MTCModel(system, mesh_n=3)
    eq = m.equilibrium()
    moved = MTCModel(with_angles(system, {("theta", 0): 50.0, ("psi", 1): -20.0}), mesh_n=3,
                     rest_lengths=m.rest_lengths.copy())
    xr = m.reduce(eq.state)
    R0, R1 = m.residual(xr, tangent=False)[0], moved.residual(xr, tangent=False)[0]
    assert np.array_equal(R0, R1)
    assert np.array_equal(m.full(xr), moved.full(xr))


def test_an_angle_optimum_is_written_back_with_its_angles_and_rest_lengths(tmp_path):
    system = load_preset("2-3")
    res = optimize(system, objective="max:freq_1", mesh_n=4, k=2, max_iter=2,
                   variables={"theta_1": (54.0, 56.0)})
    opt = res.system
    assert res.optimum[0] < 55.0               # d freq_1 / d theta_1 < 0 at the start (checked above)
    assert np.degrees(opt.symmetric.theta[0]) == pytest.approx(res.optimum[0], rel=1e-12)
    dump_system(opt, tmp_path / "optimal.toml")
    back = load_system(tmp_path / "optimal.toml")
    assert np.degrees(back.symmetric.theta[0]) == pytest.approx(res.optimum[0], rel=1e-12)
    assert np.allclose(back.q, opt.q, rtol=0, atol=1e-12)
    assert np.allclose(back.rest_lengths, opt.rest_lengths, rtol=1e-12)


@pytest.mark.parametrize("system, variables, text", [
    (load_preset("2-3"), ["psi_3"], "stage 1..2"),
    (load_preset("2-3"), ["theta_1", "d_bar"], "rest lengths only"),
    (load_preset("2-3"), ["sigma_2"], "only the angles"),
])
def test_angle_variables_that_have_no_design_are_refused(system, variables, text):
    with pytest.raises(InputError, match=text):
        parse_variables(system, variables)


def test_an_angle_without_a_design_names_the_angle():
    # the 2-3 preset's membrane is stretched by Delta = 1 mm; theta_2 0.1 deg lower slackens it
    system = load_preset("2-3")
    m = MTCModel(system, mesh_n=2)
    vs = parse_variables(system, ["theta_2"])
    with pytest.raises(InfeasibleDesign, match="theta_2 = 53 deg"):
        apply_design(system, m.rest_lengths, vs, [53.0], redesign=redesign_of(m))


def test_an_angle_optimum_on_the_sbc_model_moves_the_bases_and_the_rest_lengths():
    # 1-4: d freq_1 / d theta_1 > 0 at the start (0.80 Hz/deg on both models), so the
    # optimum is the upper bound; the written design has r_1 of eq. 3.33 at 61 deg
    system = load_preset("1-4")
    res = optimize(system, objective="max:freq_1", model="sbc", mesh_n=4, k=2, max_iter=2,
                   variables={"theta_1": (59.0, 61.0)})
    assert res.optimum[0] == pytest.approx(61.0, abs=1e-9)
    assert res.optimum_responses["freq_1"] > res.start_responses["freq_1"]
    ratio = res.system.symmetric.r[0] / system.symmetric.r[0]
    assert ratio == pytest.approx(np.sin(np.radians(61)) / np.sin(np.radians(60)), rel=1e-12)
