"""Tension-field membrane in boundary-value problems and in the models.

Sources: the twisted prestressed annulus against the tension-field solution derived in
tmfem.reference.wrinkling (docs/guides/wrinkling.md; the problem of Mansfield 1970 and Miller &
Hedgepeth 1982) and, below the onset torque, the closed-form taut (Lame + shear) solution;
plane-stress design: positive homogeneity of the small-strain tension-field law (corner
forces linear in Delta) and the energy bound W_TF <= W_SVK (Pipkin 1986: the relaxed energy is
the lower envelope, so the stored energy F_Delta Delta / 2 at prescribed corners is lower);
MTC prestress: the stress of the law is tension-only.
"""
import json

import numpy as np
import pytest

from tmfem.cli import main
from tmfem.errors import InputError
from tmfem.fem.membrane_problem import quad_mesh, solve_membrane
from tmfem.fem.plane_stress import PlaneStressMembrane
from tmfem.reference.wrinkling import twisted_annulus
from tmfem.system import load_preset
from tmfem.system.materials import MembraneMaterial

MAT = MembraneMaterial(E=1.0e9, nu=0.3, rho=1.0, h=1.0e-4)
A, B, DELTA = 0.1, 0.3, 3.0e-6


def annulus_mesh(nr=20, nt=96):
    r = np.linspace(A, B, nr + 1)
    th = np.linspace(0, 2 * np.pi, nt, endpoint=False)
    R, T = np.meshgrid(r, th, indexing="ij")
    p = np.stack([(R * np.cos(T)).ravel(), (R * np.sin(T)).ravel()])
    i = np.arange((nr + 1) * nt).reshape(nr + 1, nt)
    t = np.stack([i[:-1], i[1:], np.roll(i[1:], -1, 1), np.roll(i[:-1], -1, 1)]).reshape(4, -1)
    return quad_mesh(p, t)


def twist(mesh, phi, law="tension-field"):
    """Hub rotated rigidly by phi, rim pulled out radially by DELTA; in-plane (z fixed)."""
    p = mesh.p
    nn = p.shape[1]
    r = np.hypot(*p)
    hub, rim = np.isclose(r, A), np.isclose(r, B)
    fixed = np.zeros((3, nn), bool)
    fixed[2] = True
    fixed[:2, hub | rim] = True
    disp = np.zeros((3, nn))
    c, s = np.cos(phi), np.sin(phi)
    disp[0, hub] = (c - 1) * p[0, hub] - s * p[1, hub]
    disp[1, hub] = s * p[0, hub] + (c - 1) * p[1, hub]
    disp[:2, rim] = DELTA * p[:, rim] / B
    sol = solve_membrane(mesh=mesh, material=MAT, law=law, fixed=fixed, displacement=disp, tol=1e-7)
    f, x = sol.reactions, sol.x
    torque = float(np.sum(x[0, hub] * f[1, hub] - x[1, hub] * f[0, hub]))
    st = sol.membrane.law.state(sol.membrane.strain(x)[1])
    dx = np.asarray(sol.membrane.basis.dx)
    R_w = float(np.sqrt(A**2 + dx[st == 1].sum() / np.pi))     # area-equivalent wrinkled radius
    return torque, R_w, st


@pytest.mark.parametrize("torque", [0.15, 0.5, 2.0])
def test_twisted_annulus_wrinkled_and_taut_zones(torque):
    ref = twisted_annulus(a=A, b=B, material=MAT, delta=DELTA, torque=torque)
    assert A < ref.R < B
    T_fe, R_fe, st = twist(annulus_mesh(), ref.phi)
    assert (st == 1).any() and (st == 0).any()
    assert T_fe == pytest.approx(torque, rel=0.015)
    assert R_fe == pytest.approx(ref.R, rel=0.02)


def test_twisted_annulus_below_onset_is_taut_and_linear():
    ref = twisted_annulus(a=A, b=B, material=MAT, delta=DELTA, torque=0.05)
    assert ref.R == A
    # closed form: phi = T / (4 pi h G) (1 / a^2 - 1 / b^2)
    G = MAT.E / (2 * (1 + MAT.nu))
    assert ref.phi == pytest.approx(0.05 / (4 * np.pi * MAT.h * G) * (1 / A**2 - 1 / B**2), rel=1e-12)
    T_fe, _, st = twist(annulus_mesh(), ref.phi)
    assert np.all(st == 0)
    assert T_fe == pytest.approx(0.05, rel=0.01)
    # the SVK membrane gives the same torque while taut
    assert twist(annulus_mesh(), ref.phi, law="svk")[0] == pytest.approx(T_fe, rel=1e-9)


def test_twisted_annulus_bad_input():
    with pytest.raises(InputError, match="expected 0 < a < b"):
        twisted_annulus(a=B, b=A, material=MAT, delta=DELTA, torque=1.0)


def test_plane_stress_tension_field_design():
    s = load_preset("1-4")
    for att, n in (("point", 10), ("distributed", 20)):
        svk = PlaneStressMembrane(corners=s.membrane_corners, material=s.membrane, n=n,
                                  attachment=att)
        tf = PlaneStressMembrane(corners=s.membrane_corners, material=s.membrane, n=n,
                                 attachment=att, law="tension-field")
        r1, r2 = tf.symmetric_response(1e-3), tf.symmetric_response(2e-3)
        assert r2.F_Delta == pytest.approx(2 * r1.F_Delta, rel=1e-8)    # positively homogeneous
        assert r1.F_Delta < svk.symmetric_response(1e-3).F_Delta        # W_TF <= W_SVK
        sig = r1.solution.sigma
        minor = 0.5 * (sig[0] + sig[1]) - np.hypot(0.5 * (sig[0] - sig[1]), sig[2])
        assert minor.min() >= -1e-5 * np.abs(sig).max()                 # tension only (eta)
        with pytest.raises(InputError, match="linear law"):
            tf.corner_stiffness()


def test_mtc_tension_field_prestress_and_cli(capsys):
    rc = main(["static", "--preset", "1-4", "--membrane-law", "tension-field", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert rc == 0 and doc["membrane_law"] == "tension-field"
    fr = doc["membrane_state_fractions"]
    assert fr["wrinkled"] > 0.05 and fr["taut"] > 0.5
    # tension only: the minor principal Cauchy stress is at most eta of the major in magnitude
    assert doc["membrane_min_minor_principal"] >= -1e-5 * doc["membrane_max_sigma_p1"]
    rc = main(["static", "--preset", "1-4", "--json"])
    svk = json.loads(capsys.readouterr().out)
    assert svk["membrane_law"] == "svk" and svk["membrane_min_minor_principal"] < 0
    with pytest.raises(SystemExit):
        main(["modal", "--preset", "1-4", "--membrane-law", "wrinkly"])


def test_com_basis_about_the_tension_field_prestress():
    from tmfem.models.com.membrane_modes import build_membrane_basis
    from tmfem.models.com.model import ControlOrientedModel
    s = load_preset("1-4")
    com = ControlOrientedModel(s, membrane_modes=5, membrane_law="tension-field")
    mb = com.membrane
    d0 = mb.delta0
    comps = mb.layout.corner_components
    inplane = [k for k, (i, c) in enumerate(comps) if c < 2]
    dvec = np.array([d0[c, i] for (i, c) in comps])
    # Euler's theorem for the positively homogeneous law: K_t(Delta_0) Delta_0 = f(Delta_0),
    # so the condensed tangent S reproduces the tension-field corner forces at the design
    F = mb.plane.solve(d0[:2]).corner_forces
    f_expected = np.array([F[c, i] for k, (i, c) in enumerate(comps) if k in inplane])
    f_S = (mb.S @ dvec)[inplane]
    assert np.allclose(f_S, f_expected, rtol=1e-6, atol=1e-6 * np.abs(f_expected).max())
    # the prestress of the basis is tension-only (eta of SVK at most) ...
    tau = mb.tau
    minor = 0.5 * (tau[0] + tau[1]) - np.hypot(0.5 * (tau[0] - tau[1]), tau[2])
    assert minor.min() >= -1e-5 * np.abs(tau).max()
    # ... and the SVK basis (the dissertation's) keeps compression at the free edges
    svk = build_membrane_basis(s, delta0=d0, n_modes=5)
    t2 = svk.tau
    assert (0.5 * (t2[0] + t2[1]) - np.hypot(0.5 * (t2[0] - t2[1]), t2[2])).min() < 0


def test_design_field_carries_membrane_states():
    from tmfem.equilibrium.design import design_equilibrium
    from tmfem.post.fields import placed_membrane_field
    s = load_preset("1-4")
    d = design_equilibrium(s, membrane_law="tension-field")
    mf = placed_membrane_field(s, d.membrane_model, d.membrane)
    st, dr = mf.cell_data["membrane_state"], mf.cell_data["wrinkle_direction"]
    w = st == 1
    assert w.any() and (st == 0).any()
    nrm = np.linalg.norm(dr, axis=1)
    # unit where any Gauss point is wrinkled (always in a wrinkled element), zero elsewhere
    assert np.allclose(nrm[w], 1.0) and np.all((nrm == 0.0) | np.isclose(nrm, 1.0))
    # the direction lies in the membrane plane (normal to the inertial z of a level membrane)
    assert np.abs(dr[w, 2]).max() < 1e-9


def test_com_cli_takes_the_membrane_law(capsys):
    rc = main(["modal", "--model", "com", "--preset", "1-4", "--membrane-law", "tension-field",
               "--modes", "3", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert rc == 0 and doc["membrane_law"] == "tension-field" and len(doc["freq_hz"]) == 3
