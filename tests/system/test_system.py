"""System description (ch. 2, eqs. 3.1-3.3, 3.19-3.22): geometry, topology, files."""
import numpy as np
import pytest

from tmfem.errors import InputError
from tmfem.system import (SymmetricConfig, System, dump_system, load_preset, load_system,
                          tendon_topology)
from tmfem.system.geometry import beta, euler_angles_321, floating_frame, rotation_ef


def test_frame_origin_and_x_axis_follow_section_2_2():
    s = load_preset("1-4")
    A = s.nodes()[:, :4]
    np.testing.assert_allclose(A[:, 3], 0.0, atol=1e-15)            # A_1N at the origin
    assert A[1, 0] == pytest.approx(0.0, abs=1e-15) and A[0, 0] > 0  # A_11 on +x
    # regular base of circumradius r_1: edge 2 r_1 sin(pi/N)
    np.testing.assert_allclose(np.linalg.norm(A - np.roll(A, 1, axis=1), axis=0),
                               2 * 0.4286 * np.sin(np.pi / 4))


def test_tendon_counts_match_section_3_3_2():
    # (6M-5)N tendons; T_q has (6M-2)N-6 entries once the 3N-6 corner forces are added
    for M, N in [(1, 3), (1, 4), (2, 3), (3, 5)]:
        n = len(tendon_topology(M, N, False))
        assert n == (6 * M - 5) * N
        assert n + 3 * N - 6 == (6 * M - 2) * N - 6
    assert len(tendon_topology(1, 6, True)) == 12


def test_S_tendon_length_matches_eq_3_29():
    s = load_preset("1-4")
    th, ps, r, l, N = np.radians(60), np.radians(10), 0.4286, 2.015, 4
    S = np.sqrt(l**2 + 4 * r**2 * np.sin(np.pi / N)**2
                - 4 * r * l * np.sin(np.pi / N) * np.sin(th) * np.cos(ps))
    np.testing.assert_allclose(s.tendon_lengths(), S, rtol=1e-13)


@pytest.mark.parametrize("preset", ["1-4", "2-3"])
def test_delta_eq_3_22_matches_corner_geometry(preset):
    s = load_preset(preset)
    B = s.membrane_corners_inertial()
    centre = B.mean(axis=1)
    radius = np.linalg.norm(B - centre[:, None], axis=0)
    np.testing.assert_allclose(radius - s.r_mb, s.symmetric.membrane_delta(s.N, s.r_mb), rtol=1e-12)
    np.testing.assert_allclose(B[2], B[2, 0])  # the top of a symmetric system is horizontal


def test_membrane_corners_in_floating_frame():
    s = load_preset("1-4")
    # the square of side r_mb*sqrt(2) = 2 m with O_f at corner N and x_f through corner 1 (3.2)
    np.testing.assert_allclose(s.membrane_corners, [[2, 2, 0, 0], [0, 2, 2, 0]], atol=1e-4)
    b = beta(4)
    np.testing.assert_allclose(np.degrees(b), [-45, 45, 135, 225])  # eq. 3.21


def test_floating_frame_of_the_1_4_design():
    s = load_preset("1-4")
    B = s.membrane_corners_inertial()
    o, R = floating_frame(B)
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-14)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-14)          # right-handed (3.2)
    np.testing.assert_array_equal(o, B[:, 3])                         # O_f = B_14
    e14_11 = (B[:, 0] - B[:, 3]) / np.linalg.norm(B[:, 0] - B[:, 3])
    np.testing.assert_allclose(R[:, 0], e14_11, atol=1e-14)           # x_f along B_14 -> B_11
    # the design top is horizontal (symmetric, eq. 3.19), so z_f = +z and x_f, y_f horizontal
    np.testing.assert_allclose(R[2, :2], 0, atol=1e-14)
    np.testing.assert_allclose(R[:, 2], [0, 0, 1], atol=1e-14)
    # the corners in O_f are the undeformed square stretched by Delta (eq. 3.22) along the
    # radii: B_13 (corner N-1) lies on the +y_f side, all corners on z_f = 0
    local = R.T @ (B - o[:, None])
    np.testing.assert_allclose(local[2], 0, atol=1e-14)
    assert local[1, 2] > 0 and abs(local[1, 0]) < 1e-14
    d = s.symmetric.membrane_delta(s.N, s.r_mb)
    np.testing.assert_allclose(local[:2], s.membrane_corners * (s.r_mb + d) / s.r_mb, atol=1e-12)


@pytest.mark.parametrize("preset", ["1-4", "2-3"])
def test_floating_frame_z_axis_is_the_polygon_normal(preset):
    # y_f towards B_M,N-1 (eq. 3.5) and z_f along (B_M1 - B_MN) x (B_M2 - B_MN) agree for
    # convex corner polygons (the rule of the former io.vtk copy)
    s = load_preset(preset)
    rng = np.random.default_rng(7)
    for _ in range(5):
        B = s.membrane_corners_inertial(s.q + 0.02 * rng.standard_normal(s.q.size))
        o, R = floating_frame(B)
        assert np.dot(np.cross(B[:, 0] - o, B[:, 1] - o), R[:, 2]) > 0


def test_floating_frame_rejects_collinear_corners():
    B = np.array([[1.0, 3.0, 2.0, 0.0], [1.0, 3.0, 2.0, 0.0], [0.5, 1.5, 1.0, 0.0]])
    with pytest.raises(InputError, match="collinear"):       # B_M3 on the line B_M4 B_M1
        floating_frame(B)
    B[:, 0] = 0.0
    with pytest.raises(InputError, match="collinear"):       # B_M1 = B_M4
        floating_frame(B)
    with pytest.raises(InputError, match=r"shape \(3, N >= 3\)"):
        floating_frame(B[:, :2])


def test_rotation_ef_numeric_matches_casadi_and_inverts():
    import casadi as ca

    from tmfem.models.com.kinematics import rotation_ef_sx
    rng = np.random.default_rng(11)
    g = ca.SX.sym("g", 3)
    f = ca.Function("R", [g], [rotation_ef_sx(g)])
    for gamma in rng.uniform([-np.pi, -1.5, -np.pi], [np.pi, 1.5, np.pi], (20, 3)):
        R = rotation_ef(gamma)
        np.testing.assert_allclose(f(gamma).full(), R, atol=1e-15)      # symbolic = numeric
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-14)
        np.testing.assert_allclose(euler_angles_321(R), gamma, atol=1e-12)  # |gamma_2| < pi/2


def test_q_round_trip_and_symmetric_recovery():
    s = load_preset("2-3")
    cfg = s.symmetric_from_q()
    for k in ("theta", "psi", "sigma", "z", "r", "l"):
        np.testing.assert_allclose(getattr(cfg, k), getattr(s.symmetric, k), atol=1e-12)
    np.testing.assert_allclose(cfg.to_q(3), s.q, atol=1e-12)
    q = s.q.copy()
    q[s.q_names.index("theta_12")] += 0.01
    with pytest.raises(InputError, match="stage 1 is not symmetric"):
        s.symmetric_from_q(q)


@pytest.mark.parametrize("preset", ["1-4", "2-3"])
def test_toml_round_trip(preset, tmp_path):
    s = load_preset(preset, as_printed=True)
    dump_system(s, tmp_path / "s.toml")
    t = load_system(tmp_path / "s.toml")
    np.testing.assert_allclose(t.q, s.q, rtol=1e-15)
    np.testing.assert_allclose(t.rest_lengths, s.rest_lengths)
    np.testing.assert_allclose(t.nodes(), s.nodes(), atol=1e-14)
    assert t.tendon_names() == s.tendon_names()


def _general_2_3():
    """The 2-3 preset as a general (non-symmetric) system: base, l, q given explicitly."""
    s = load_preset("2-3")
    return s, System(name="g", M=s.M, N=s.N, deployable=False, base=s.base, l=s.l, q=s.q,
                     membrane=s.membrane, membrane_corners=s.membrane_corners, bar=s.bar,
                     tendon_sections=s.tendon_sections)


def test_general_system_file_round_trip(tmp_path):
    s, g = _general_2_3()
    dump_system(g, tmp_path / "g.toml")
    t = load_system(tmp_path / "g.toml")
    np.testing.assert_allclose(t.nodes(), s.nodes(), atol=1e-14)


@pytest.mark.parametrize("text, match", [
    ("N = 4\n[symmetric\n", "not valid TOML"),
    ('N = 2\n', "N >= 3"),
    ('N = 4\n[membrane]\n', "missing number 'E'"),
])
def test_malformed_files_give_clear_errors(tmp_path, text, match):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(InputError, match=match):
        load_system(p)


def test_negative_lengths_are_rejected():
    with pytest.raises(InputError, match="expected l > 0"):
        SymmetricConfig(theta=[1.0], psi=[0.1], sigma=[0], z=[0], r=[0.4], l=[-2.0])
    with pytest.raises(InputError, match="0 < theta < 90 deg"):
        SymmetricConfig(theta=[2.0], psi=[0.1], sigma=[0], z=[0], r=[0.4], l=[2.0])


@pytest.mark.parametrize("as_printed", [False, True])
def test_every_preset_file_round_trips(as_printed, tmp_path):
    # every shipped preset (and its [as_printed] variant) passes the key checks and
    # dump_system writes only keys that load_system accepts back
    from tmfem.system import list_presets
    for name in list_presets():
        s = load_preset(name, as_printed=as_printed)
        dump_system(s, tmp_path / f"{name}.toml")
        t = load_system(tmp_path / f"{name}.toml")
        np.testing.assert_allclose(t.nodes(), s.nodes(), atol=1e-14)
        assert t.tendon_sections == s.tendon_sections
        assert t.tendon_names() == s.tendon_names()


def _general_dict():
    from tmfem.system import system_to_dict
    return system_to_dict(_general_2_3()[1])


def _preset_1_4_dict():
    from tmfem.system import system_to_dict
    return system_to_dict(load_preset("1-4"))


@pytest.mark.parametrize("make, path, table, expected", [
    (_preset_1_4_dict, ("symmetric",), r"\[symmetric\]", "psi_deg"),
    (_preset_1_4_dict, ("membrane",), r"\[membrane\]", "r_mb"),
    (_preset_1_4_dict, ("bar",), r"\[bar\]", "rho"),
    (_preset_1_4_dict, ("tendons", "S"), r"\[tendons\.S\]", "yield_stress"),
    (_general_dict, ("general",), r"\[general\]", "base"),
    (_general_dict, ("tendon", 0), r"\[\[tendon\]\] entry 1", "family"),
])
def test_unknown_keys_in_sub_tables_are_rejected(make, path, table, expected, tmp_path):
    import tomli_w
    d = make()
    t = d
    for k in path:
        t = t[k]
    t["diameter"] = 1.0                       # misspelt key (e.g. for 'd')
    p = tmp_path / "bad.toml"
    p.write_bytes(tomli_w.dumps(d).encode())
    with pytest.raises(InputError, match=table + r": unknown keys \['diameter'\]; expected some of") as e:
        load_system(p)
    assert repr(expected) in str(e.value)
    del t["diameter"]                         # the same file without the typo loads
    p.write_bytes(tomli_w.dumps(d).encode())
    load_system(p)


def test_as_printed_overrides_are_checked_after_merging():
    from tmfem.system import system_from_dict
    from tmfem.system.presets import preset_dict
    d = preset_dict("2-3", as_printed=True)
    d["symmetric"]["theta"] = [63.0, 63.0]    # 'theta' instead of 'theta_deg'
    with pytest.raises(InputError, match=r"\[symmetric\]: unknown keys \['theta'\]"):
        system_from_dict(d, where="preset 2-3")
