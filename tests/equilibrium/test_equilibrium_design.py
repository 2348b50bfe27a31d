"""Design pipeline: F from the plane-stress FE, tendon forces, rest lengths, checks (3.2, 5.29-5.31)."""
import numpy as np
import pytest

from tmfem.equilibrium.design import design_equilibrium, forces_from_rest_lengths
from tmfem.equilibrium.general import corner_state, positive_null_vector, symmetric_matrix
from tmfem.equilibrium.symmetric import r1_1N, tendon_force_1N
from tmfem.errors import InfeasibleDesign, SlackMembrane, SlackTendon
from tmfem.fem.plane_stress import symmetric_corner_force
from tmfem.system import SymmetricConfig, load_preset

MESH = 4   # coarse membrane mesh: the tests compare formulations on the same mesh


def one_stage(theta_deg=60.0, psi_deg=10.0, *, r1=None, r_mb=1.4142, l1=2.015):
    s = load_preset("1-4")
    th, ps = np.radians(theta_deg), np.radians(psi_deg)
    if r1 is None:
        r1 = float(r1_1N(l1=l1, theta1=th, psi1=ps, N=4))       # eq. 3.33
    cfg = SymmetricConfig(theta=[th], psi=[ps], sigma=[0], z=[0], r=[r1], l=[l1])
    return s.replace(q=cfg.to_q(4), symmetric=cfg, base=cfg.base_nodes(4)[:, 0, :],
                     r_mb=r_mb, membrane_corners=_corners(r_mb), rest_lengths=None)


def _corners(r_mb):
    from tmfem.system.geometry import membrane_corners_regular
    return membrane_corners_regular(4, r_mb)


def one_stage_D(*, theta, psi, r1, l1=2.2):
    """A symmetric 1-4(D) system (k_H = 0.3, r_mb = 1 m) with the 1-4 materials; angles [rad]."""
    from tmfem.system import System, TendonSection
    base = load_preset("1-4")
    cfg = SymmetricConfig(theta=[theta], psi=[psi], sigma=[0], z=[0], r=[r1], l=[l1])
    return System.symmetric_system(name="d", N=4, config=cfg, r_mb=1.0, membrane=base.membrane,
                                   bar=base.bar,
                                   tendon_sections={"*": TendonSection(E=2e9, d=1e-3)},
                                   deployable=True, k_H=0.3)


def two_stage(psi2_deg, sigma2_deg):
    """2-3 with the Table 6.4 dimensions (theta 63 deg, l 2.5 m, r_mb 1.87 m), psi_1 = 20 deg,
    z_2 = 0.6001 m, r_2 = 0.2798 m and the given psi_2, sigma_2."""
    s = load_preset("2-3", as_printed=True)
    c = s.symmetric
    cfg = SymmetricConfig(theta=c.theta, psi=[np.radians(20), np.radians(psi2_deg)],
                          sigma=[0, np.radians(sigma2_deg)], z=[0, 0.6001], r=[0.7, 0.2798], l=c.l)
    return s.replace(q=cfg.to_q(3), symmetric=cfg, rest_lengths=None)


def test_1N_design_matches_closed_form_null_vector():
    s = one_stage()
    d = design_equilibrium(s, mesh_n=MESH)
    assert d.residual < 1e-9
    # F_Delta of the FE (A2's symmetric_corner_force, same mesh) and T_S of eq. 3.34
    F = symmetric_corner_force(s, n=MESH)
    assert d.F_Delta == pytest.approx(F, rel=1e-9)
    np.testing.assert_allclose(d.tendon_forces, tendon_force_1N(s, F), rtol=1e-8)
    # rest lengths of eqs. 3.8-3.9 give back the same forces (reverse direction)
    back = forces_from_rest_lengths(s, d.rest_lengths, mesh_n=MESH)
    np.testing.assert_allclose(back["forces"], d.tendon_forces, rtol=1e-10)
    assert back["residual"] < 1e-9 and not back["slack"].any()
    # force density T/|S| (eq. 3.30)
    np.testing.assert_allclose(d.force_densities, d.tendon_forces / d.tendon_lengths)


def test_bar_load_is_axial_and_balances_the_bar_top():
    # stage-1 bar pinned at A: moment equilibrium needs the resultant at B along the bar
    s = one_stage()
    d = design_equilibrium(s, mesh_n=MESH)
    X = d.nodes
    A, B = s.bar_ends()
    u = (B - A)[:, 0, 0] / s.l[0, 0]
    # resultant on B_11 from S_12 (A_12 - B_11) and the membrane corner 1
    k = s.tendon_names().index("S_12")
    c = s.tendon_connectivity[:, k]
    t = X[:, c[0]] - X[:, c[1]]
    f = d.tendon_forces[k] * t / np.linalg.norm(t)
    st = corner_state(s)
    f = f - st.R @ np.append(d.corner_forces[:, 0], 0.0)
    assert np.linalg.norm(np.cross(f, u)) < 1e-6 * np.linalg.norm(f)
    assert d.bar_loads[0, 0] == pytest.approx(-f @ u, rel=1e-9)
    crit = np.pi**2 * s.bar.E * np.pi * s.bar.d**4 / 64 / s.l[0, 0]**2     # eq. 5.31, K = 1
    assert d.bar_critical[0, 0] == pytest.approx(crit)


def test_2_3_design_agrees_with_reduced_null_vector_scaled_to_F_delta():
    # a 2-3 configuration with a positive null vector and Delta > 0 (found with the map of
    # tmfem.equilibrium.symmetric_map); tendon forces = null vector scaled to F_Delta (3.2)
    s = two_stage(157.84, 145.67)
    nv = positive_null_vector(symmetric_matrix(s).A)
    assert nv.exists
    d = design_equilibrium(s, mesh_n=MESH)
    assert d.ok or all(ch.name in ("bar buckling", "tendon yield", "membrane von Mises stress",
                                    "membrane max principal stress") for ch in d.failed)
    x = nv.x * d.F_Delta / nv.x[-1]
    got = d.group_values(d.tendon_forces)
    for g, v in zip(symmetric_matrix(s).cols[:-1], x[:-1]):
        assert got[g] == pytest.approx(v, rel=1e-6), g
    sn = d.symmetric_null
    assert sn["positive"] and sn["dim"] == 1
    np.testing.assert_allclose(np.array(sn["per_F_Delta"]) * d.F_Delta, x, rtol=1e-6)


def test_named_errors():
    with pytest.raises(SlackMembrane, match=r"membrane stretched \(eq. 3.22/3.36\).*Delta = -"):
        design_equilibrium(one_stage(r_mb=2.0), mesh_n=MESH)
    # a 1-N system with cot psi_1 < tan(pi/N) also has Delta < 0 (eq. 3.36), so take a 2-3
    # configuration with Delta > 0 whose unique null vector (3.3.2) has negative entries
    s = two_stage(120, 100)      # Table 6.4 dimensions
    with pytest.raises(SlackTendon, match=r"tendons taut.*= -\d.*slack\)"):
        design_equilibrium(s, mesh_n=MESH)
    with pytest.raises(InfeasibleDesign, match=r"eq. 3.33 requires r_1 = 0.42854"):
        design_equilibrium(one_stage(r1=0.40), mesh_n=MESH)


def test_non_strict_reports_every_failed_check():
    d = design_equilibrium(one_stage(r_mb=2.0), mesh_n=MESH, strict=False)
    names = {c.name for c in d.failed}
    assert {"membrane stretched", "tendons taut"} <= names
    for c in d.failed:
        assert any(ch.isdigit() for ch in c.message)


def test_printed_rest_length_of_table_6_2_is_slack_or_taut_by_strain():
    # Table 6.2: r_1^S = 1.529 m against |S_1| = 1.5311 m (eq. 3.29): strain +0.14 %, taut
    s = load_preset("1-4", as_printed=True)
    out = forces_from_rest_lengths(s, mesh_n=MESH)
    np.testing.assert_allclose(out["strain"], 1.531113642924252 / 1.529 - 1, rtol=1e-9)
    assert not out["slack"].any()


def test_equilibrium_map_agrees_with_pointwise_design():
    # the map of eq. 5.97 near the configuration of the test above (sigma_2 = 145.67 deg):
    # feasibility must agree with the LP at the same point, and the null-vector ratios with
    # the design's tendon forces / F_Delta (unique: A_T is square and regular for 2-3)
    from tmfem.equilibrium.symmetric_map import (configuration_5_97, equilibrium_map,
                                                 with_configuration)
    s = load_preset("2-3", as_printed=True)      # Table 6.4 dimensions
    c = s.symmetric
    sg = np.radians(145.67)
    cfg = SymmetricConfig(theta=c.theta, psi=[np.radians(12.17), np.radians(12.17) + sg],
                          sigma=[0, sg], z=[0, 0.6001], r=[0.7, 0.2798], l=c.l)
    s = with_configuration(s, cfg)
    th, ps = np.radians([60.0, 63.0]), np.radians([12.17, 40.0])
    m = equilibrium_map(s, theta=th, psi=ps)
    assert m.ratios.shape == (2, 2, 8) and m.columns[-1] == "F_Delta"
    for a in range(2):
        for b in range(2):
            sp = with_configuration(s, configuration_5_97(s, th[a], ps[b]))
            assert m.positive[a, b] == positive_null_vector(symmetric_matrix(sp).A).exists
            assert m.Delta[a, b] == pytest.approx(sp.symmetric.membrane_delta(3, sp.r_mb))
    np.testing.assert_array_equal(m.feasible, m.positive & (m.Delta > 0))
    d = design_equilibrium(with_configuration(s, configuration_5_97(s, th[1], ps[0])),
                           mesh_n=MESH, strict=False)
    got = d.group_values(d.tendon_forces)
    for g, v in zip(m.columns[:-1], m.ratios[1, 0, :-1]):
        assert got[g] / d.F_Delta == pytest.approx(v, rel=1e-6), g


def test_1ND_design_matches_null_vector_of_eq_3_40():
    # 1-4(D) inside the bounds of eq. 3.41: forces = averaged null vector of 3.40 times
    # |SL|, |SU| and F_Delta / (Delta + r_mb) (eq. 3.39)
    from tmfem.equilibrium.symmetric import closed_form_1ND
    s = one_stage_D(theta=np.radians(50), psi=np.radians(15), r1=0.5)
    d = design_equilibrium(s, mesh_n=MESH)
    cf = closed_form_1ND(s)
    scale = d.F_Delta / (cf["delta"] + s.r_mb) / cf["null"][2]
    np.testing.assert_allclose(d.tendon_forces[:4], cf["null"][0] * cf["SL"] * scale, rtol=1e-8)
    np.testing.assert_allclose(d.tendon_forces[4:], cf["null"][1] * cf["SU"] * scale, rtol=1e-8)
    assert d.residual < 1e-9 and d.Delta == pytest.approx(cf["delta"], rel=1e-12)
    # bar b_11 pinned at A_11: forces at H_11 (SL_2, SU_2) and B_11 (SU_1, membrane) must
    # have zero moment about A_11; the compression of segment A-H is -(f_B + f_H).u
    X = d.nodes
    lab = s.node_labels
    f = {n: np.zeros(3) for n in ("B_11", "H_11")}
    for k, t in enumerate(s.tendons):
        for a, b in (t.ends, t.ends[::-1]):
            if a in f:
                v = X[:, lab.index(b)] - X[:, lab.index(a)]
                f[a] += d.tendon_forces[k] * v / np.linalg.norm(v)
    f["B_11"] -= corner_state(s).R @ np.append(d.corner_forces[:, 0], 0.0)
    A = X[:, lab.index("A_11")]
    mom = sum(np.cross(X[:, lab.index(n)] - A, f[n]) for n in f)
    assert np.linalg.norm(mom) < 1e-8 * s.l[0, 0] * np.linalg.norm(f["B_11"])
    u = (X[:, lab.index("B_11")] - A) / s.l[0, 0]
    seg = max(-(f["B_11"] + f["H_11"]) @ u, -f["B_11"] @ u)
    assert d.bar_loads[0, 0] == pytest.approx(seg, rel=1e-9)


def test_equilibrium_map_with_a_base_rule():
    # a rule bases(theta, psi) that returns the system's own values reproduces the default
    from tmfem.equilibrium.symmetric_map import equilibrium_map
    s = load_preset("2-3")
    c = s.symmetric
    th, ps = np.radians([50.0, 70.0]), np.radians([0.0, 20.0])
    a = equilibrium_map(s, theta=th, psi=ps)
    b = equilibrium_map(s, theta=th, psi=ps, bases=lambda t, p: {"r": c.r, "z": c.z,
                                                                 "sigma": c.sigma})
    np.testing.assert_array_equal(a.positive, b.positive)
    np.testing.assert_allclose(a.Delta, b.Delta)
    # a different stage-2 radius changes Delta as eq. 3.22 says
    cc = equilibrium_map(s, theta=th, psi=ps, bases=lambda t, p: {"r": [c.r[0], 0.3]})
    from tmfem.equilibrium.symmetric import membrane_delta
    assert cc.Delta[0, 0] == pytest.approx(membrane_delta(l_M=c.l[1], theta_M=th[0],
                                                          psi_M=ps[0] + c.sigma[1],
                                                          sigma_M=c.sigma[1], r_M=0.3,
                                                          r_mb=s.r_mb, N=3))


def test_force_ratios_agree_with_mtc_nodal_balance():
    # independent formulation (the MTC model): nonlinear membrane with the corners at
    # the design bar tops, then force balance at every free node along the member
    # directions. The membrane forces differ (nonlinear vs linear), so compare the tendon
    # forces relative to one of them: they must agree for a 2-3 design (3.3.2)
    from tmfem.models.mtc.model import MTCModel
    s = two_stage(157.84, 145.67)
    d = design_equilibrium(s, mesh_n=MESH)
    m = MTCModel(s, mesh_n=MESH, rest_lengths=d.rest_lengths)
    T = m.consistent_rest_lengths()["tendon_force"]
    np.testing.assert_allclose(T / T[0], d.tendon_forces / d.tendon_forces[0], rtol=1e-6)


def test_best_bases_reports_what_it_found():
    # the search result, re-evaluated independently (LP on the reduced matrix, eq. 3.22)
    from tmfem.equilibrium.symmetric import membrane_delta
    from tmfem.equilibrium.symmetric_map import best_bases, configuration_5_97, with_configuration
    s = load_preset("2-3")
    th, ps = np.radians(79.63), np.radians(10.0)
    b = best_bases(s, th, ps, starts=1, maxiter=60)
    cfg = configuration_5_97(s, th, ps, r=b["r"], z=b["z"], sigma=b["sigma"])
    nv = positive_null_vector(symmetric_matrix(with_configuration(s, cfg)).A)
    assert nv.margin == pytest.approx(b["margin"], abs=1e-9)
    assert b["Delta"] == pytest.approx(membrane_delta(l_M=cfg.l[-1], theta_M=th, psi_M=cfg.psi[-1],
                                                      sigma_M=cfg.sigma[-1], r_M=cfg.r[-1],
                                                      r_mb=s.r_mb, N=3), abs=1e-12)
    assert b["feasible"] == (nv.exists and b["Delta"] > 0)
    assert -np.pi < b["sigma"][1] <= np.pi


def test_1ND_slack_tendon_names_the_r1_bounds():
    # r_1 below k_H r* = 0.185 m. eq. 3.41: r* = l_1 sin(theta_1) sin(psi_1) / cos(pi/N)
    # = 2.2 sin 50 sin 15 / cos 45 = 0.616862 m, k_H r* = 0.3 r* = 0.185059 m
    s = one_stage_D(theta=np.radians(50), psi=np.radians(15), r1=0.1)
    with pytest.raises(SlackTendon, match=r"0.185059 < r_1 < min\(0.616862"):
        design_equilibrium(s, mesh_n=MESH)


def test_duplicated_tendon_has_self_stress_and_shares_the_force():
    # S_11 doubled: A_T gets two equal columns, a 1-D tendon self-stress (T_a - T_b); the
    # minimum-norm forces split the single-tendon force of eq. 3.34 equally
    from tmfem.system.topology import Tendon
    s = one_stage()
    t0 = s.tendons[0]
    twin = Tendon("S_11b", t0.family, t0.stage, t0.j, t0.ends)
    s2 = s.replace(tendons=s.tendons + (twin,))
    d1 = design_equilibrium(s, mesh_n=MESH)
    d2 = design_equilibrium(s2, mesh_n=MESH)
    assert d1.self_stress_dim == 0 and d2.self_stress_dim == 1
    assert d2.tendon_forces[0] == pytest.approx(d2.tendon_forces[-1], rel=1e-9)
    assert d2.tendon_forces[0] + d2.tendon_forces[-1] == pytest.approx(d1.tendon_forces[0],
                                                                        rel=1e-9)


def test_equilibrium_map_of_a_1ND_system_matches_closed_form_bounds():
    # 1-N(D): positivity over (theta, psi) must follow r1_bounds_1ND (eq. 3.41 + SL bound)
    # and Delta of eq. 3.22
    from tmfem.equilibrium.symmetric import r1_bounds_1ND
    from tmfem.equilibrium.symmetric_map import equilibrium_map
    s = one_stage_D(theta=1.0, psi=0.3, r1=0.5)
    th = np.radians(np.linspace(20, 85, 9))
    ps = np.radians(np.linspace(2, 70, 9))
    m = equilibrium_map(s, theta=th, psi=ps)
    T, P = np.meshgrid(th, ps, indexing="ij")
    lo, up, up_sl = r1_bounds_1ND(l1=2.2, theta1=T, psi1=P, k_H=0.3, N=4)
    expect = (lo < 0.5) & (0.5 < np.minimum(up, up_sl))
    np.testing.assert_array_equal(m.positive, expect)
    assert 5 < m.feasible.sum() < m.feasible.size


def test_equilibrium_map_marks_points_without_a_stage_base_infeasible():
    # preset 2-3 with the Table 7.7 base rule (tmfem.reference.tables.deployment_bases): at
    # psi = -10 deg, theta = 60-80 deg no r_2 satisfies eq. 3.22 (the rule itself raises
    # there, checked directly below); the map must mark those points infeasible, keep
    # the reason, and give every other point exactly as a map over feasible points only.
    from tmfem.equilibrium.symmetric_map import equilibrium_map
    from tmfem.errors import InputError
    from tmfem.reference.tables import deployment_bases
    s = load_preset("2-3")
    rule = deployment_bases(s)
    th, ps = np.radians([55.0, 60.0, 70.0, 80.0]), np.radians([-10.0, 0.0, 10.0])
    bad = [(a, 0) for a in (1, 2, 3)]
    for a, b in bad:
        with pytest.raises(InputError, match="eq. 3.22"):
            rule(th[a], ps[b])
    m = equilibrium_map(s, theta=th, psi=ps, bases=rule)
    for a in range(th.size):
        for b in range(ps.size):
            if (a, b) in bad:
                assert not m.feasible[a, b] and not m.positive[a, b]
                assert "eq. 3.22" in m.reason[a, b] and np.isnan(m.Delta[a, b])
                assert np.isnan(m.ratios[a, b]).all()
            else:
                assert m.reason[a, b] == ""
    assert m.feasible[:, 2].all()       # psi = 10 deg: feasible (Delta = 1 mm by the rule)
    # feasible points unchanged: theta = 55 deg over all psi, the rest over psi = 0, 10 deg
    ref55 = equilibrium_map(s, theta=th[:1], psi=ps, bases=rule)
    ref = equilibrium_map(s, theta=th[1:], psi=ps[1:], bases=rule)
    for k in ("feasible", "positive", "margin", "Delta", "ratios"):
        np.testing.assert_array_equal(getattr(m, k)[:1], getattr(ref55, k))
        np.testing.assert_array_equal(getattr(m, k)[1:, 1:], getattr(ref, k))
    d = m.to_dict()
    assert d["Delta"][1][0] is None and d["reason"][1][0].startswith("bases rule: eq. 3.22")
