"""Control-oriented model (dissertation ch. 5): constraints, membrane basis, energies,
coordinate partitioning, derivatives, frequencies (Table 6.6) and energy conservation."""
import numpy as np
import pytest

from tmfem.errors import InputError
from tmfem.models.com.constraints import ZetaLayout, zeta_closed_form
from tmfem.models.com.dae import dae_terms, matrices_newton
from tmfem.models.com.linearize import linearize, output_jacobian
from tmfem.models.com.model import ControlOrientedModel
from tmfem.solvers.park import park_integrate
from tmfem.system import load_preset
from tmfem.system.geometry import rotation_ef


@pytest.fixture(scope="module")
def sys14():
    return load_preset("1-4")


@pytest.fixture(scope="module")
def m14(sys14):
    return ControlOrientedModel(sys14, membrane_modes=3)


def _random_state(m, seed=0, dz=0.01, dv=0.1):
    rng = np.random.default_rng(seed)
    return m.z0 + dz * rng.standard_normal(m.nz), dv * rng.standard_normal(m.nz)


# ---------------------------------------------------------------- constraints (3.3-3.5)
def test_zeta_layout_counts():
    # eq. 5.14: 3N - 6 corner displacements + 3 Euler angles = 3N - 3 constraints (3.5)
    for N in (3, 4, 6):
        L = ZetaLayout.for_polygon(N)
        assert L.n == 3 * N - 3
    assert ZetaLayout.for_polygon(4).names == ["Delta_u1", "Delta_u2", "Delta_v2", "Delta_w2",
                                               "Delta_u3", "Delta_v3", "gamma_1", "gamma_2", "gamma_3"]


def test_rotation_is_3_2_1_sequence():
    # eq. 3.3 equals Rz(g1) Ry(g2) Rx(g3); independent construction, checked on the casadi
    # R^ef of the model (the numeric one: tests/equilibrium/test_equilibrium_general.py, system/test_system.py)
    import casadi as ca

    from tmfem.models.com.kinematics import rotation_ef_sx
    g = np.array([0.3, -0.2, 0.7])
    c, s = np.cos, np.sin
    Rz = np.array([[c(g[0]), -s(g[0]), 0], [s(g[0]), c(g[0]), 0], [0, 0, 1]])
    Ry = np.array([[c(g[1]), 0, s(g[1])], [0, 1, 0], [-s(g[1]), 0, c(g[1])]])
    Rx = np.array([[1, 0, 0], [0, c(g[2]), -s(g[2])], [0, s(g[2]), c(g[2])]])
    assert np.allclose(ca.evalf(rotation_ef_sx(ca.SX(g))).full(), Rz @ Ry @ Rx, atol=1e-15)


def test_constraints_newton_and_jacobian(m14, sys14):
    cs, L = m14.constraints, m14.layout
    rng = np.random.default_rng(1)
    q = sys14.q + 0.02 * rng.standard_normal(sys14.q.size)
    zc = zeta_closed_form(sys14, L, q)
    assert np.max(np.abs(cs.phi(q, zc)[0])) < 1e-12
    # Newton from the design's zeta converges to the geometric definition of O_f (3.2)
    zn = cs.solve(q, zeta0=m14.zeta0)
    assert np.allclose(zn, zc, atol=1e-11)
    # symmetric design: radial corner displacement of eq. 3.21-3.22 (A1's closed form)
    from tmfem.equilibrium.symmetric import membrane_delta_system
    D = membrane_delta_system(sys14)
    b = np.pi * (-(4 + 2) / 8 + 2 * np.arange(1, 5) / 4)     # beta_j, eq. 3.21
    d = L.delta_array(m14.zeta0)
    assert np.allclose(d[:2], D * (np.array([np.cos(b), np.sin(b)]) - np.array([[np.cos(b[-1])], [np.sin(b[-1])]])),
                       atol=1e-12)
    # eq. 5.23 against central finite differences of zeta(q)
    J = cs.dzeta_dq(q, zn)
    h = 1e-6
    Jfd = np.column_stack([(zeta_closed_form(sys14, L, q + h * e) - zeta_closed_form(sys14, L, q - h * e)) / (2 * h)
                           for e in np.eye(q.size)])
    assert np.allclose(J, Jfd, atol=1e-7)


# ---------------------------------------------------------------- membrane basis (5.1-5.8)
def test_membrane_basis_properties(m14, sys14):
    mb = m14.membrane
    ps = mb.plane
    corners = ps.mesh.corners
    nd = mb.n_delta
    # mass = rho h A (square of circumradius r_mb: A = 2 r_mb^2)
    mat = sys14.membrane
    assert mb.mass == pytest.approx(mat.rho * mat.h * 2 * sys14.r_mb**2, rel=1e-12)
    # static shapes: unit displacement of their own corner component, zero elsewhere
    for k, (i, c) in enumerate(mb.layout.corner_components):
        P = mb.shapes[1 + k][:, corners]
        target = np.zeros((3, sys14.N))
        target[c, i] = 1.0
        assert np.allclose(P, target, atol=1e-12)
    # relative modes vanish at the corners (corner-held, no double counting) and are
    # mass-normalised (eq. 5.79): int rho phi_i . phi_j = delta_ij
    modes = mb.shapes[1 + nd:]
    assert np.allclose(modes[:, :, corners], 0.0)
    Mxi = np.trace(mb.Jt, axis1=2, axis2=3)[1 + nd:, 1 + nd:]
    assert np.allclose(Mxi, np.eye(mb.K), atol=1e-10)
    # S symmetric positive semidefinite; in-plane block = A2's condensed corner stiffness
    assert np.allclose(mb.S, mb.S.T)
    Sc = ps.corner_stiffness()
    ip = mb.layout.in_plane()
    idx = [2 * i + c for (i, c) in np.array(mb.layout.corner_components)[ip]]
    assert np.allclose(mb.S[np.ix_(ip, ip)], Sc[np.ix_(idx, idx)], rtol=1e-8, atol=1e-6 * np.abs(Sc).max())
    # corner forces of the design are radial and equal (eq. 3.21, A2's F_Delta)
    from tmfem.fem.plane_stress import symmetric_corner_force
    F = mb.S[np.ix_(ip, ip)] @ m14.zeta0[ip]
    F_D = symmetric_corner_force(sys14, n=10)
    b = np.pi * (-(4 + 2) / 8 + 2 * np.arange(1, 5) / 4)
    assert F[0] == pytest.approx(F_D * np.cos(b[0]), rel=1e-6)


def test_membrane_kinetic_energy_against_nodal_sum(m14, sys14):
    """T_m of eqs. 5.2-5.3 from the mass invariants equals 1/2 sum v^T M v over the FE
    nodes with nodal velocities by finite differences of the nodal positions (independent)."""
    mb, L = m14.membrane, m14.layout
    z, zd = _random_state(m14, seed=3, dz=0.005, dv=0.2)
    nq = m14.nq

    def nodes(zz):
        q, eta = zz[:nq], zz[nq:]
        zeta = m14.constraints.solve(q, zeta0=m14.zeta0)
        xb = np.concatenate([[1.0], zeta[:L.n_delta], eta])
        rf = np.einsum("a,aij->ij", xb, mb.shapes)
        O = sys14.membrane_corners_inertial(q)[:, -1]
        return O[:, None] + rotation_ef(zeta[L.n_delta:]) @ rf

    h = 1e-6
    V = (nodes(z + h * zd) - nodes(z - h * zd)) / (2 * h)
    from tmfem.models.com.membrane_modes import _mass_matrix
    Ms = _mass_matrix(mb.scalar_basis, sys14.membrane.rho * sys14.membrane.h)
    T_nodal = 0.5 * np.einsum("in,nm,im->", V, Ms.toarray(), V)
    # bar kinetic energy, eq. 5.9 (M = 1)
    th, ps_d = zd[0:nq:2], zd[1:nq:2]
    theta = z[0:nq:2]
    m_bar = sys14.bar.mass(sys14.l[0, 0])
    T_bar = np.sum(m_bar * sys14.l[0, 0] ** 2 / 6 * (th**2 + ps_d**2 * np.sin(theta) ** 2))
    assert m14.kinetic_energy(z, zd) == pytest.approx(T_bar + T_nodal, rel=1e-7)


# ---------------------------------------------------------------- partitioning (5.20-5.28)
def test_partitioned_equals_substituted(sys14, m14):
    """Eqs. 5.20-5.28 (Newton zeta, T_z, G) against an independent formulation: zeta(q) in
    closed form substituted into the Lagrangian before differentiation."""
    ms = ControlOrientedModel(sys14, membrane_modes=3, formulation="substituted")
    for seed in range(2):
        z, zd = _random_state(m14, seed)
        A, B = m14.matrices(z, zd), ms.matrices(z, zd)
        for a, b in zip(A, B):
            assert np.allclose(a, b, rtol=1e-10, atol=1e-10 * np.abs(a).max())


def test_derivatives_against_finite_differences(m14):
    z, zd = _random_state(m14, seed=5)
    zdd = 0.3 * np.random.default_rng(6).standard_normal(m14.nz)
    K, C, M = m14.jacobians(z, zd, zdd)
    h = 1e-6
    Kfd = np.column_stack([(m14.residual(z + h * e, zd, zdd) - m14.residual(z - h * e, zd, zdd)) / (2 * h)
                           for e in np.eye(m14.nz)])
    Cfd = np.column_stack([(m14.residual(z, zd + h * e, zdd) - m14.residual(z, zd - h * e, zdd)) / (2 * h)
                           for e in np.eye(m14.nz)])
    assert np.allclose(K, Kfd, rtol=1e-5, atol=1e-5 * np.abs(K).max())
    assert np.allclose(C, Cfd, rtol=1e-5, atol=1e-6 * max(np.abs(C).max(), 1.0))
    # M_hat is the Hessian of the kinetic energy: T = 1/2 z'^T M_hat z'
    assert m14.kinetic_energy(z, zd) == pytest.approx(0.5 * zd @ M @ zd, rel=1e-12)
    # B_hat = d r / d u against finite differences in the rest lengths
    Bh = m14.input_matrix(z)
    u = m14.u0
    Bfd = np.column_stack([(m14.static_residual(z, u + h * e) - m14.static_residual(z, u - h * e)) / (2 * h)
                           for e in np.eye(m14.n_t)])
    assert np.allclose(Bh, Bfd, atol=1e-5 * np.abs(Bh).max())
    # output Jacobian vs finite differences of w at the monitored points (eq. 5.36)
    Jy = output_jacobian(m14, z)
    Jfd = np.column_stack([(m14.outputs(z + h * e) - m14.outputs(z - h * e)) / (2 * h) for e in np.eye(m14.nz)])
    assert np.allclose(Jy, Jfd, atol=1e-7)


def test_design_is_equilibrium_and_rest_lengths(m14, sys14):
    # the design tendon forces balance the membrane corner forces (eq. 3.16); the
    # equilibrium of the model with those rest lengths is the design up to the rounding
    # of r_1 = 0.4286 m in Table 6.2 (eq. 3.33 gives 0.428565 m)
    assert m14.design.residual < 1e-3
    z_e = m14.equilibrium().state
    assert np.max(np.abs(z_e - m14.z0)) < 1e-3
    assert np.max(np.abs(m14.static_residual(z_e))) < 1e-8
    # A1's 1-N closed form (eq. 3.34) gives the same tendon force for the same F_Delta
    from tmfem.equilibrium.symmetric import tendon_force_1N
    from tmfem.fem.plane_stress import symmetric_corner_force
    T = tendon_force_1N(sys14, symmetric_corner_force(sys14, n=10))
    assert np.allclose(m14.design.tendon_forces, T, rtol=2e-4)


# ---------------------------------------------------------------- frequencies (Table 6.6)
def test_frequencies_1_4_against_table_6_6(sys14):
    """Table 6.6, COM column, K = 5. The printed numbers are reproduced when the prestress
    is the one implied by the printed tendon stress of Table 6.3 (37.98 MPa, i.e. x1.290 our
    designed prestress, see docs/validation/errata.md); with the designed prestress the prestress-
    dominated modes are lower by up to 12 %."""
    from tmfem.reference.com_modal import modal_summary
    r1 = modal_summary(sys14, modes=12, membrane_modes=5)
    s = r1["printed_stress_prestress_scale"]
    assert s == pytest.approx(37.98e6 * np.pi * 0.3e-3**2 / r1["design_tendon_forces"]["S_11"], rel=1e-9)
    r = modal_summary(sys14, modes=12, membrane_modes=5, prestress_scale=s)
    assert max(abs(d) for d in r["relative_difference"]) < 1.5e-3
    assert r["highest_hz"] == pytest.approx(2.4322, rel=1e-3)       # 6.5.1
    assert len(r1["freq_hz"]) == 12 and r1["sizes"]["n_z"] == 13
    # designed prestress: first mode lower (prestress-stiffened mechanism)
    assert r1["freq_hz"][0] < 0.95 * 0.1367


def test_point_coordinates_same_dynamics(sys14, m14):
    # eqs. 5.17-5.18: K membrane deflections as coordinates give the same frequencies
    pts = [("w", 0.6, 1.6), ("w", 0.5, 0.4), ("w", 1.5, 0.3)]
    mp = ControlOrientedModel(sys14, membrane_modes=3, membrane_points=pts)
    f1, f2 = linearize(m14).frequencies_hz(), linearize(mp).frequencies_hz()
    assert np.allclose(f1, f2, rtol=1e-8)
    assert mp.z_names[-3:] == ["wr_1", "wr_2", "wr_3"]
    with pytest.raises(InputError, match="condition number"):
        ControlOrientedModel(sys14, membrane_modes=3,
                             membrane_points=[("w", 0.6, 1.6), ("w", 0.6, 1.6), ("w", 1.5, 0.3)])


def test_linear_state_space_names(m14, sys14):
    ss = linearize(m14).to_ss()
    assert ss.nstates == 2 * m14.nz
    assert ss.input_labels == [f"r_{t.name}" for t in sys14.tendons]
    assert ss.state_labels[:2] == ["theta_11", "psi_11"] and ss.state_labels[-1] == "eta_3_dot"
    assert ss.output_labels[-3:] == ["w_1", "w_2", "w_3"]


# ---------------------------------------------------------------- energy (5.12-5.13)
def test_energy_conserved_without_damping(sys14, m14):
    m = m14
    z0 = m.equilibrium().state
    zd0 = np.zeros(m.nz)
    zd0[2] = 0.01          # theta_12_dot = 0.01 rad/s (6.5.1)
    E = []
    park_integrate(m, x0=z0, v0=zd0, dt=0.005, n_steps=300, scheme="trapezoidal",
                         jacobian="reuse",
                         callback=lambda t, x, v, a: E.append(m.kinetic_energy(x, v) + m.potential_energy(x)))
    E = np.array(E)
    T0 = m.kinetic_energy(z0, zd0)
    assert np.max(np.abs(E - E[0])) < 1e-4 * T0
    # with modal damping (eq. 5.13) the energy decays
    md = ControlOrientedModel(sys14, membrane_modes=3, damping=0.5)
    Ed = []
    park_integrate(md, x0=z0, v0=zd0, dt=0.005, n_steps=300, scheme="trapezoidal",
                   jacobian="reuse",
                   callback=lambda t, x, v, a: Ed.append(md.kinetic_energy(x, v) + md.potential_energy(x)))
    assert Ed[-1] < Ed[0] - 1e-3 * T0


def test_fast_path_equals_newton_partitioning(m14):
    # the integrator's single-call graph (closed-form zeta inside) against zeta from
    # Newton on Phi and eqs. 5.23-5.28 evaluated numerically from the DAE matrices
    for seed in (7, 8):
        z, zd = _random_state(m14, seed)
        for a, b in zip(m14.matrices(z, zd), matrices_newton(m14, z, zd)):
            assert np.allclose(a, b, rtol=1e-10, atol=1e-10 * np.abs(a).max())
    w, X = m14.fast_outputs(z)
    assert np.allclose(w, m14.membrane_w(z), atol=1e-14)
    assert np.allclose(X, m14.system.nodes(z[:m14.nq]), atol=1e-14)


def test_nlsys_and_linearization_consistent(m14):
    # python-control's finite-difference linearisation of our nlsys (independent of the AD
    # derivatives) against linearize (eq. 5.33)
    import control
    lin = linearize(m14)
    nl = m14.to_nlsys()
    x_e = np.concatenate([lin.z_e, np.zeros(m14.nz)])
    assert np.max(np.abs(nl.dynamics(0.0, x_e, lin.u_e))) < 1e-8        # an equilibrium
    fd = control.linearize(nl, x_e, lin.u_e, eps=1e-7, copy_names=True)
    assert fd.state_labels == lin.to_ss().state_labels
    assert np.allclose(fd.A, lin.A, atol=1e-5 * np.abs(lin.A).max())
    assert np.allclose(fd.B, lin.B, atol=1e-5 * np.abs(lin.B).max())
    assert np.allclose(fd.C, lin.Cy, atol=1e-6)
    assert np.allclose(nl.output(0.0, x_e, lin.u_e), lin.y_e)


def test_slack_membrane_is_refused(sys14):
    from tmfem.errors import SlackMembrane
    from tmfem.system.geometry import membrane_corners_regular
    # a membrane larger than the bar tops (Delta < 0, eq. 3.36): r_mb = 1.5 m > 1.4155 m
    big = sys14.replace(membrane_corners=membrane_corners_regular(4, 1.5), r_mb=1.5)
    with pytest.raises(SlackMembrane, match="Delta > 0"):
        ControlOrientedModel(big, membrane_modes=2)


def test_membrane_follows_bar_tops(m14, sys14):
    # eq. 3.5: the membrane corners (static shapes, modes vanish there) sit on the bar tops
    z, _ = _random_state(m14, seed=11, dz=0.02)
    x, defl = m14.membrane_positions(z)
    corners = m14.membrane.mesh.corners
    assert np.allclose(x[:, corners], sys14.membrane_corners_inertial(z[:m14.nq]), atol=1e-12)
    # tendon forces T = k (|d| - r) are the design forces at the design
    assert np.allclose(m14.tendon_forces(m14.z0), m14.design.tendon_forces, rtol=1e-9)


def test_dae_with_multipliers_equals_partitioned_ode(m14):
    """Eq. 5.19 solved as an index-1 DAE with Lagrange multipliers,
    [M Phi_x^T; Phi_x 0] [x''; lambda] = [-F - B u; -gamma], gives the same z'' as the ODE
    5.27 of the coordinate partitioning; and T_z^T Phi_x^T = 0 (eq. 5.26)."""
    z, zd = _random_state(m14, seed=21)
    d = dae_terms(m14, z, zd)
    assert np.allclose(d["T_z"].T @ d["Phi_x"].T, 0.0, atol=1e-12)
    nx, nc = d["M"].shape[0], d["Phi_x"].shape[0]
    A = np.block([[d["M"], d["Phi_x"].T], [d["Phi_x"], np.zeros((nc, nc))]])
    rhs = np.concatenate([-d["F"] - d["B"] @ m14.u0, -d["gamma"]])
    xdd = np.linalg.solve(A, rhs)[:nx]
    assert np.allclose(xdd[:m14.nz], m14.acceleration(z, zd), rtol=1e-8, atol=1e-10)


def test_model_interface_modes_and_plant(m14):
    """The Model protocol (tmfem.models.base): modes solve K v = omega^2 M v of the
    linearisation (eq. 5.33) with M-normalised shapes, at the frequencies of
    Linearization.frequencies_hz (checked against Table 6.6 above); the plant starts at
    the equilibrium (residual of eq. 5.27 zero there) with the perturbation by name."""
    lin = linearize(m14)
    md = m14.modes(k=6)
    assert np.allclose(lin.K @ md.shapes, lin.M @ md.shapes * md.omega2, atol=1e-9 * np.abs(lin.K).max())
    assert np.allclose(md.shapes.T @ lin.M @ md.shapes, np.eye(6), atol=1e-8)
    assert np.allclose(md.freq_hz, lin.frequencies_hz()[:6], rtol=1e-12)
    plant = m14.plant(perturb={"theta_12_dot": 0.01})
    zero = np.zeros(m14.nz)
    r = plant.residual(plant.x0, zero, zero, 0.0, plant.u0)
    assert np.linalg.norm(r) < 1e-9 * np.linalg.norm(m14.input_matrix(plant.x0) @ plant.u0)
    assert plant.v0[m14.z_names.index("theta_12")] == 0.01 and np.count_nonzero(plant.v0) == 1


def test_frequencies_interlace_with_K(sys14, m14):
    # nested modal bases (K = 1 within K = 3) at the same equilibrium: Rayleigh-Ritz /
    # Cauchy interlacing, each frequency can only decrease when modes are added
    f3 = linearize(m14).frequencies_hz()
    m1 = ControlOrientedModel(sys14, membrane_modes=1)
    f1 = linearize(m1).frequencies_hz()
    assert np.all(f3[: len(f1)] <= f1 * (1 + 1e-9))
    assert len(f3) == len(f1) + 2


def test_free_vibration_matches_linear_response(m14):
    """6.5.1 perturbation (theta_12' = 0.01 rad/s): the nonlinear COM integrated by Park
    against the exact (matrix exponential) response of its linearisation (eq. 5.33) over
    3 s; the motion is small, so they agree to ~1 % of the amplitude."""
    from scipy.linalg import expm
    from tmfem.simulation.vibration import free_vibration
    res = free_vibration(m14, t_end=3.0, dt=0.005, perturb={"theta_12_dot": 0.01}, jacobian="reuse")
    lin = linearize(m14)
    x0 = np.zeros(2 * m14.nz)
    x0[m14.nz + 2] = 0.01
    Phi = expm(lin.A * 0.005)
    X = [x0]
    for _ in range(len(res.t) - 1):
        X.append(Phi @ X[-1])
    X = np.array(X)
    dz = res.z - lin.z_e
    amp = np.max(np.abs(X[:, :m14.nz]), axis=0)
    err = np.max(np.abs(dz - X[:, :m14.nz]), axis=0)
    assert np.all(err[:m14.nq] < 0.02 * amp[:m14.nq].max())
    yl = (lin.Cy @ X.T).T[:, m14.nq:]             # w_1..w_3 of eq. 5.36
    assert np.max(np.abs(res.w - yl)) < 0.03 * np.max(np.abs(yl))


def test_rest_length_step_matches_linear_input_response(m14):
    """A 1 mm step of the rest length of S_12 at t = 0 (input u, eq. 5.27): the nonlinear
    response against the exact zero-order-hold response of the linearisation (A, B of 5.33)."""
    from scipy.linalg import expm
    from tmfem.simulation.vibration import free_vibration
    du = np.zeros(m14.n_t)
    du[1] = -1e-3
    dt = 0.005
    res = free_vibration(m14, t_end=2.0, dt=dt, u=m14.u0 + du, jacobian="reuse")
    lin = linearize(m14)
    n = lin.A.shape[0]
    E = expm(np.block([[lin.A, lin.B], [np.zeros((m14.n_t, n + m14.n_t))]]) * dt)
    Ad, Bd = E[:n, :n], E[:n, n:]
    X = [np.zeros(n)]
    for _ in range(len(res.t) - 1):
        X.append(Ad @ X[-1] + Bd @ du)
    X = np.array(X)
    dz = res.z - lin.z_e
    amp = np.max(np.abs(X[:, :m14.nq]))
    assert amp > 1e-4                                  # the step does move the bars
    assert np.max(np.abs(dz[:, :m14.nq] - X[:, :m14.nq])) < 0.01 * amp


def test_driven_run_frames_carry_the_driven_rest_lengths_and_forces(m14, tmp_path):
    # the ParaView frames of a run with prescribed rest lengths u show T = k (|d| - u)
    # (eq. 3.8) for that u, computed here independently by ControlOrientedModel.tendon_forces
    import meshio
    from tmfem.io.series import read_pvd
    from tmfem.simulation.vibration import free_vibration
    du = np.zeros(m14.n_t)
    du[1] = -1e-3
    res = free_vibration(m14, t_end=0.02, dt=0.01, u=m14.u0 + du, vtk_dir=tmp_path, vtk_every=1)
    frames = read_pvd(res.stats["pvd"])
    assert len(frames) == 3
    nb = m14.system.M * m14.system.N
    last = meshio.read(frames[-1][1])
    cd = {k: np.concatenate(v) for k, v in last.cell_data.items()}
    T = m14.tendon_forces(res.z[-1], m14.u0 + du)
    assert cd["axial_force"][nb:nb + m14.n_t] == pytest.approx(T, rel=1e-9)
    assert cd["rest_length"][nb:nb + m14.n_t] == pytest.approx(m14.u0 + du, rel=1e-12)
    # the driven tendon S_12 differs from the nominal-u force by k du
    assert abs(T[1] - m14.tendon_forces(res.z[-1])[1]) == pytest.approx(
        m14.k[1] * 1e-3, rel=1e-9)


def test_buffered_function_equals_the_casadi_call(m14):
    # in-place evaluation (casadi function buffer) against casadi's own call, twice in a row
    # (the output is a copy, not the buffer), and refused for a two-input function
    import casadi as ca
    from tmfem.errors import InputError
    from tmfem.models.com.graphs import BufferedFunction
    f = m14.graphs.fast
    bf = BufferedFunction(f)
    rng = np.random.default_rng(4)
    x1, x2 = (np.concatenate([m14.z0, np.zeros(m14.nz)]) + 1e-3 * rng.standard_normal(2 * m14.nz)
              for _ in range(2))
    y1 = bf(x1)
    y2 = bf(x2)
    assert np.array_equal(y1, f(x1).full().ravel()) and np.array_equal(y2, f(x2).full().ravel())
    a, b = ca.SX.sym("a"), ca.SX.sym("b")
    with pytest.raises(InputError, match="one dense input"):
        BufferedFunction(ca.Function("g", [a, b], [a + b]))
