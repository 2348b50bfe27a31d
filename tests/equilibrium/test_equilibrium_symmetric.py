"""Closed forms of 3.3.3-3.3.4 against explicit node geometry and the general method of 3.2."""
import numpy as np
import pytest

from tmfem.equilibrium.general import corner_state, positive_null_vector, symmetric_matrix
from tmfem.equilibrium.symmetric import (A_1N, check_1N, check_1ND, closed_form_1N,
                                         closed_form_1ND, delta_1N, r1_bounds_1ND, det_A_1N,
                                         force_density_ratio_1N, membrane_delta_system, r1_1N,
                                         s1_length, sl_su_lengths)
from tmfem.errors import InfeasibleDesign, SlackMembrane, SlackTendon
from tmfem.system import SymmetricConfig, System, TendonSection, load_preset
from tmfem.system.geometry import beta

BASE = load_preset("1-4")
rng = np.random.default_rng(7)


def one_stage(theta_deg, psi_deg, r1, *, l1=2.2, N=4, r_mb=1.0, k_H=None):
    cfg = SymmetricConfig(theta=[np.radians(theta_deg)], psi=[np.radians(psi_deg)], sigma=[0.0],
                          z=[0.0], r=[r1], l=[l1])
    return System.symmetric_system(name="t", N=N, config=cfg, r_mb=r_mb, membrane=BASE.membrane,
                                   bar=BASE.bar, tendon_sections={"*": TendonSection(E=2e9, d=1e-3)},
                                   deployable=k_H is not None, k_H=k_H)


def random_cases(n):
    for _ in range(n):
        yield (rng.uniform(20, 80), rng.uniform(-40, 60), rng.uniform(0.1, 1.2),
               rng.uniform(1.0, 3.0), int(rng.integers(3, 8)))


def test_eq_3_29_against_node_geometry():
    for th, ps, r, l, N in random_cases(20):
        s = one_stage(th, ps, r, l1=l, N=N)
        c = s.symmetric
        S1 = s1_length(l1=l, theta1=c.theta[0], psi1=c.psi[0], r1=r, N=N)
        np.testing.assert_allclose(s.tendon_lengths(), S1, rtol=1e-12)


def test_eq_3_31_equals_reduced_general_matrix():
    # the reduced matrix of 3.3.2 acts on (T, F_Delta); eq. 3.31 on (T/|S_1|, F_D/(D + r_mb))
    for th, ps, r, l, N in random_cases(20):
        s = one_stage(th, ps, r, l1=l, N=N)
        cf = closed_form_1N(s)
        ours = symmetric_matrix(s).A * np.array([cf["S1"], cf["delta"] + s.r_mb])
        np.testing.assert_allclose(ours, cf["A"], rtol=1e-8, atol=1e-10 * np.abs(cf["A"]).max())


def test_eq_3_32_determinant_and_3_33_root():
    for th, ps, r, l, N in random_cases(20):
        p = dict(l1=l, theta1=np.radians(th), psi1=np.radians(ps), N=N)
        np.testing.assert_allclose(det_A_1N(r1=r, **p), np.linalg.det(A_1N(r1=r, **p)),
                                   rtol=1e-9, atol=1e-12)
        assert det_A_1N(r1=r1_1N(**p), **p) == pytest.approx(0.0, abs=1e-12)


def test_eq_3_34_null_vector_matches_general_method():
    # equilibrium designs (r_1 of eq. 3.33) with positive ratio: the LP finds the same vector
    for N, th, ps in [(3, 60, 20), (4, 60, 10), (4, 45, 30), (6, 70, 15), (5, 30, 5)]:
        p = dict(l1=2.0, theta1=np.radians(th), psi1=np.radians(ps), N=N)
        s = one_stage(th, ps, float(r1_1N(**p)), l1=2.0, N=N, r_mb=0.5)
        cf = closed_form_1N(s)
        nv = positive_null_vector(symmetric_matrix(s).A, rtol=1e-8)
        assert nv.dim == 1 and nv.exists
        T, F = nv.x
        ratio = (T / cf["S1"]) / (F / (cf["delta"] + s.r_mb))
        assert ratio == pytest.approx(float(force_density_ratio_1N(psi1=np.radians(ps), N=N)),
                                      rel=1e-7)


def test_eq_3_36_and_3_22_against_corner_geometry():
    for N, th, ps in [(3, 60, 20), (4, 60, 10), (6, 70, 15)]:
        p = dict(l1=2.0, theta1=np.radians(th), psi1=np.radians(ps), N=N)
        s = one_stage(th, ps, float(r1_1N(**p)), l1=2.0, N=N, r_mb=0.5)
        d = membrane_delta_system(s)
        assert d == pytest.approx(float(delta_1N(r_mb=0.5, **p)), rel=1e-12)
        # corner displacements of eq. 3.21 from the explicit corner constraints (eq. 3.5)
        b = beta(N)
        st = corner_state(s)
        expect = d * np.vstack([np.cos(b) - np.cos(b[-1]), np.sin(b) - np.sin(b[-1])])
        np.testing.assert_allclose(st.delta[:2], expect, atol=1e-12)


def test_table_6_2_design_satisfies_eq_3_37_within_its_rounding():
    # Table 6.2: r_1 = 0.4286 m printed to 4 digits; eq. 3.33 gives 0.42854 m
    s = load_preset("1-4")
    cf = check_1N(s, rtol=2e-4)
    # 0.428540 m: the printed 0.4286 is 6e-5 m off its own rounding (l_1 = 2.015 m is rounded too)
    assert cf["r1_equilibrium"] == pytest.approx(0.4286, abs=1e-4)
    assert cf["delta"] > 0


def test_check_1N_names_each_condition():
    p = dict(l1=2.2, theta1=np.radians(60), N=4)
    with pytest.raises(InfeasibleDesign, match="eq. 3.33"):
        check_1N(one_stage(60, 10, 0.5, l1=2.2))
    with pytest.raises(SlackTendon, match="eq. 3.35"):    # psi_1 > pi/2 - pi/N
        check_1N(one_stage(60, 50, float(r1_1N(psi1=np.radians(50), **p)), l1=2.2))
    with pytest.raises(SlackMembrane, match="eq. 3.36"):  # r_mb too large
        check_1N(one_stage(60, 10, float(r1_1N(psi1=np.radians(10), **p)), l1=2.2, r_mb=2.0))


def test_eq_3_38_against_node_geometry():
    for th, ps, r, l, N in random_cases(20):
        k = rng.uniform(0.1, 0.9)
        s = one_stage(th, ps, r, l1=l, N=N, k_H=k)
        c = s.symmetric
        SL, SU = sl_su_lengths(l1=l, theta1=c.theta[0], psi1=c.psi[0], r1=r, k_H=k, N=N)
        L = s.tendon_lengths()
        np.testing.assert_allclose(L[:N], SL, rtol=1e-12)
        np.testing.assert_allclose(L[N:], SU, rtol=1e-12)


def test_eq_3_40_proportional_to_reduced_general_matrix():
    # our rows are sin(pi/N) times those of eq. 3.40 (a common factor: same null space)
    for th, ps, r, l, N in random_cases(20):
        k = rng.uniform(0.1, 0.9)
        s = one_stage(th, ps, r, l1=l, N=N, k_H=k)
        cf = closed_form_1ND(s)
        ours = symmetric_matrix(s).A * np.array([cf["SL"], cf["SU"], cf["delta"] + s.r_mb])
        np.testing.assert_allclose(ours, np.sin(np.pi / N) * cf["A"], rtol=1e-8,
                                   atol=1e-10 * np.abs(cf["A"]).max())


def test_eq_3_41_bounds_on_r1_match_positive_null_vector():
    # positivity of the null vector of the general reduced matrix vs the bounds on r_1:
    # k_H r* < r_1 < r* (eq. 3.41) and r_1 < L sin(psi_1 + 2pi/N)/cos(pi/N), which eq. 3.41
    # omits (derived in r1_bounds_1ND; docs/validation/errata.md "ch. 3 / eq. 3.41")
    n_in = n_341_wrong = 0
    for _ in range(80):
        N = int(rng.integers(3, 7))
        th, ps, k = rng.uniform(25, 80), rng.uniform(1, 75), rng.uniform(0.1, 0.8)
        lo, up, up_sl = r1_bounds_1ND(l1=2.0, theta1=np.radians(th), psi1=np.radians(ps),
                                      k_H=k, N=N)
        r = rng.uniform(0.02, 1.3 * up)
        if min(abs(r - up), abs(r - lo), abs(r - up_sl)) < 1e-3 * up:
            continue
        s = one_stage(th, ps, r, l1=2.0, N=N, k_H=k)
        nv = positive_null_vector(symmetric_matrix(s).A)
        inside = lo < r < min(up, up_sl)
        n_in += inside
        n_341_wrong += (lo < r < up) != inside
        assert nv.exists == inside, (N, th, ps, k, r, lo, up, up_sl)
        assert np.all(closed_form_1ND(s)["null"] > 0) == inside
    assert n_in > 10 and n_341_wrong > 3


def test_eq_3_41_misses_bound_example():
    # N = 3, psi_1 = 40 deg > 90 - 60: eq. 3.41 admits r_1 = 1.0 (0.57 < 1.0 < 1.57) but
    # T_SL/|SL| < 0 there: SL would have to push
    s = one_stage(38.5, 40.0, 1.0, l1=2.0, N=3, k_H=0.3636)
    cf = closed_form_1ND(s)
    assert cf["r1_lower"] < 1.0 < cf["r1_upper"] and cf["r1_upper_SL"] < 1.0
    assert cf["null"][0] < 0
    with pytest.raises(SlackTendon, match="omits"):
        check_1ND(s)


def test_eq_3_41_membrane_condition_is_eq_3_36_not_eq_3_22():
    # eq. 3.41 states Delta > 0 with the 1-N expression of eq. 3.36 (r_1 of eq. 3.33); a
    # 1-N(D) design has r_1 < r* and Delta of eq. 3.22 differs (docs/validation/errata.md, "ch. 3").
    s = one_stage(50, 15, 0.5, l1=2.2, N=4, k_H=0.3)
    cf = check_1ND(s)
    st = corner_state(s)
    b = beta(4)
    # Delta from the explicit corner geometry (eq. 3.5 with eq. 3.21)
    d_geom = st.delta[0, 0] / (np.cos(b[0]) - np.cos(b[-1]))
    assert d_geom == pytest.approx(cf["delta"], rel=1e-12)
    assert abs(cf["delta_3_41"] - d_geom) > 0.05       # 0.192 m vs 0.277 m
    # a design taut by eq. 3.22 (and the explicit corners) that eq. 3.41 would call slack:
    s2 = one_stage(50, 15, 0.5, l1=2.2, N=4, k_H=0.3, r_mb=1.25)
    cf2 = check_1ND(s2)
    assert cf2["delta_3_41"] < 0 < cf2["delta"]
    with pytest.raises(SlackMembrane, match="Delta"):
        check_1ND(one_stage(50, 15, 0.5, l1=2.2, N=4, k_H=0.3, r_mb=1.3))


def test_check_1ND_slack_tendon_named():
    with pytest.raises(SlackTendon, match="eq. 3.41"):
        check_1ND(one_stage(50, 15, 0.05, l1=2.2, N=4, k_H=0.3))
