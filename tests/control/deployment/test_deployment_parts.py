"""Parts of the deployment controller: reference (eq. 5.68), PFL partition
(eqs. 5.39-5.41), B_q check, RBF and projection (eqs. 5.44, 5.51-5.52), gains (eq. 5.69),
rest-length saturation and switching (eq. 5.70)."""
import numpy as np
import pytest

from tmfem.control.deployment.adaptive import Gains
from tmfem.control.deployment.pfl import check_input_matrix, partition
from tmfem.control.deployment.rbf import GaussianRBF, euler_step, projection
from tmfem.control.deployment.reference_trajectory import DeploymentReference, theta_reference
from tmfem.control.deployment.switching import SwitchingController, relative_error
from tmfem.errors import InputError, SingularInputMatrix
from tmfem.simulation.controllers import LinearController
from tmfem.system.presets import load_preset


def test_theta_reference_solves_eq_5_68():
    # closed form against the ODE of eq. 5.68 by central differences, and its start
    kw = dict(theta_0=1.5, theta_e=1.3, omega_r=0.7)
    t = np.linspace(0.1, 10, 50)
    h = 1e-4
    th, thd, thdd = theta_reference(t, **kw)
    fd1 = (theta_reference(t + h, **kw)[0] - theta_reference(t - h, **kw)[0]) / (2 * h)
    assert np.allclose(thd, fd1, atol=1e-8)
    assert np.allclose(thdd + 2 * 0.7 * thd + 0.7**2 * th, 0.7**2 * 1.3, atol=1e-10)
    th0, thd0, _ = theta_reference(0.0, **kw)
    assert th0 == pytest.approx(1.5) and thd0 == 0.0
    with pytest.raises(InputError):
        theta_reference(t, xi_r=0.5, **kw)


@pytest.fixture(scope="module")
def ref14():
    f, i = load_preset("1-4D"), load_preset("1-4D-initial")
    return DeploymentReference(initial=i.symmetric, final=f.symmetric, N=4,
                               q_names=list(f.q_names), omega_r=0.7), f, i


def test_reference_ends_and_derivatives(ref14):
    ref, f, i = ref14
    # starts at the packaged configuration (preset 1-4D-initial), ends at the deployed one
    assert np.allclose(ref(0.0)[0], i.q, atol=1e-12)
    d = ref(60.0)[0] - f.q
    assert np.allclose(np.angle(np.exp(1j * d)), 0, atol=1e-9)
    # q_d' and q_d'' against central differences of q_d
    t, h = 2.3, 1e-4
    q, qd, qdd = ref(t)
    qp, qm = ref(t + h)[0], ref(t - h)[0]
    assert np.allclose(qd, (qp - qm) / (2 * h), atol=1e-6)
    assert np.allclose(qdd, (qp - 2 * q + qm) / h**2, atol=1e-4)
    # the spline of s -> q against the exact map between its knots
    for t in (0.37, 1.91, 5.55):
        assert np.allclose(ref(t)[0], ref.q_of_s(float(ref.progress(t)[0])), atol=1e-10)


@pytest.fixture(scope="module")
def model14():
    from tmfem.models.com.model import ControlOrientedModel
    return ControlOrientedModel(load_preset("1-4D"), membrane_modes=3, rest_lengths="system")


def test_partition_gives_the_models_acceleration(model14):
    # q'' = -F_q* - B_q* u (eq. 5.40) against z'' = -M_hat^-1 (F_hat + B_hat u) (eq. 5.27)
    m = model14
    rng = np.random.default_rng(1)
    z = m.z0 + 1e-2 * rng.standard_normal(m.nz)
    zd = 1e-2 * rng.standard_normal(m.nz)
    u = m.u0 * 0.99
    M, F, B = m.matrices(z, zd)
    p = partition(M, F, B, nq=m.nq)
    acc = m.acceleration(z, zd, u)
    assert np.allclose(-p.F_q - p.B_q @ u, acc[:m.nq], rtol=1e-9, atol=1e-9)
    # second row of eq. 5.40
    assert np.allclose(p.M22 @ acc[m.nq:] + p.F2 + p.M12.T @ acc[:m.nq], 0, atol=1e-8)
    c = check_input_matrix(p.B_q)
    s = np.linalg.svd(p.B_q, compute_uv=False)
    assert c == pytest.approx(s[0] / s[-1])


def test_input_matrix_check_refuses_singular_and_too_few_tendons():
    with pytest.raises(SingularInputMatrix, match="at least as many actuated tendons"):
        check_input_matrix(np.ones((4, 3)))
    with pytest.raises(SingularInputMatrix, match="condition number"):
        check_input_matrix(np.diag([1.0, 1e-14]))
    # a wide B_q of rank 1 < 3 rows (all columns equal): no full row rank, its condition named
    with pytest.raises(SingularInputMatrix, match="full-row-rank B_q .*found"):
        check_input_matrix(np.ones((3, 4)))


def test_rbf_values():
    r = GaussianRBF(centers=[[0.0, 0.0], [1.0, 0.0]], sigma=0.5)
    phi = r(np.array([0.0, 0.5]))
    # eq. 5.44: |v - c|^2 = 0.25 and 1.25
    assert np.allclose(phi, np.exp(-np.array([0.25, 1.25]) / (2 * 0.25)))


def test_projection_property_and_bound():
    rng = np.random.default_rng(0)
    bound, eps = 2.0, 0.1
    for _ in range(200):
        W = rng.standard_normal((5, 3)) * 1.2
        Y = rng.standard_normal((5, 3)) * 3
        Ws = rng.standard_normal((5, 3))
        Ws *= (bound / np.sqrt(1 + eps)) * rng.uniform(0, 1, 3) / np.linalg.norm(Ws, axis=0)
        P = projection(W, Y, bound=bound, eps=eps)
        # Tr(dW^T (Y - Proj(W, Y))) <= 0 with dW = W* - W (eqs. 5.51-5.53)
        assert np.trace((Ws - W).T @ (Y - P)) <= 1e-12
    # inside the ball the operator is the identity
    W = np.full((4, 2), 0.1)
    Y = rng.standard_normal((4, 2))
    assert np.array_equal(projection(W, Y, bound=bound), Y)
    # a law that pushes outward for ever keeps every column within the bound
    W = np.zeros((4, 2))
    for _ in range(5000):
        W = euler_step(W, W + 1.0, dt=0.01, bound=bound, eps=eps)
    assert np.all(np.linalg.norm(W, axis=0) <= bound + 1e-12)
    assert np.all(np.linalg.norm(W, axis=0) > 0.9 * bound)


def test_gains_eq_5_69():
    g = Gains(omega_0=15, omega_e=150, tau=20, d_c=1.5)
    d0, k0 = g(0.0)
    assert (d0, k0) == (2 * 1.5 * 15, 15**2)
    w = 15 + 150 * (1 - np.exp(-1.0))
    assert np.allclose(g(20.0), (3 * w, w * w))


def test_rest_length_saturation(model14):
    from tmfem.control.deployment.run import RestLengthLimits

    class Push:
        name = "push"

        def reset(self, t0, y0, dt):
            return np.zeros(0)

        def output(self, t, y, xc):
            u = np.full(8, 5.0)
            u[0] = -1.0
            return u

        def update(self, t, y, xc):
            return xc
    lim = RestLengthLimits(Push(), model=model14, r_min=1e-3)
    y = np.concatenate([model14.z0, np.zeros(model14.nz)])
    lim.reset(0.0, y, 0.01)
    u = lim.output(0.0, y, np.zeros(0))
    L = model14.system.tendon_lengths(model14.q0)
    assert u[0] == 1e-3 and np.allclose(u[1:], L[1:])
    assert lim.active == [(0.0, 8)] and lim.margins[0] == pytest.approx(0.0)


class _Const:
    """A deployment controller with the constant input 0.3 (no state)."""

    name = "first"

    def reset(self, t0, y0, dt):
        return np.zeros(0)

    def output(self, t, y, xc):
        return np.array([0.3])

    def update(self, t, y, xc):
        return xc


def test_switching_bumpless():
    # eq. 5.70 with q_e = (1, 2): switch at the first sample within R_c; a dynamic linear
    # controller then starts from a state giving the deployment controller's last input
    import control

    q_e = np.array([1.0, 2.0])
    assert relative_error([1.01, 2.0], q_e) == pytest.approx(0.01)
    lin = LinearController(control.ss([[-1.0]], [[1.0, 0.0]], [[2.0]], [[0.0, 0.0]]),
                           u_e=[0.1], y_e=q_e, name="lin")
    sw = SwitchingController(first=_Const(), second=lin, q_of_y=lambda y: y, q_e=q_e,
                             measure=lambda y: y, R_c=0.01)
    xc = sw.reset(0.0, np.array([1.5, 2.0]), 0.01)
    u = sw.output(0.0, np.array([1.5, 2.0]), xc)
    xc = sw.update(0.0, np.array([1.5, 2.0]), xc)
    assert sw.name == "first" and u[0] == 0.3
    y = np.array([1.005, 2.0])
    u = sw.output(0.01, y, xc)
    assert sw.switch_time == 0.01 and sw.name == "lin"
    assert u[0] == pytest.approx(0.3) and sw.switch_jump == pytest.approx(0.0, abs=1e-12)


def test_switching_estimate_start():
    # start="estimate": an observer's state starts at the measured perturbation y - y_e
    # (the central H-infinity controller, tmfem.control.linear.hinf_central); the input then jumps
    # to the controller's own, and the jump is reported
    import control

    q_e = np.array([1.0, 2.0])
    lin = LinearController(control.ss(-np.eye(2), np.eye(2), [[1.0, 0.5]], [[0.0, 0.0]]),
                           u_e=[0.1], y_e=q_e, name="lin")
    sw = SwitchingController(first=_Const(), second=lin, q_of_y=lambda y: y, q_e=q_e,
                             measure=lambda y: y, R_c=0.01, start="estimate")
    xc = sw.reset(0.0, np.array([1.5, 2.0]), 0.01)
    assert sw.output(0.0, np.array([1.5, 2.0]), xc)[0] == 0.3
    xc = sw.update(0.0, np.array([1.5, 2.0]), xc)
    y = np.array([1.005, 2.004])
    u = sw.output(0.01, y, xc)
    assert sw.switch_time == 0.01
    assert u[0] == pytest.approx(0.1 + 0.005 + 0.5 * 0.004)           # u_e + C_k (y - y_e)
    assert sw.switch_jump == pytest.approx(0.3 - u[0])
    with pytest.raises(InputError, match="start"):
        SwitchingController(first=_Const(), second=lin, q_of_y=lambda y: y, q_e=q_e,
                            measure=lambda y: y, start="zero")
    small = LinearController(control.ss([[-1.0]], [[1.0, 0.0]], [[2.0]], [[0.0, 0.0]]),
                             u_e=[0.1], y_e=q_e, name="lin")
    sw = SwitchingController(first=_Const(), second=small, q_of_y=lambda y: y, q_e=q_e,
                             measure=lambda y: y, start="estimate")
    xc = sw.reset(0.0, y, 0.01)
    with pytest.raises(InputError, match="order 2"):
        sw.output(0.0, y, xc)


def test_bounded_inversion_kkt_and_exact_inside():
    # eq. 5.46 with rest-length limits: inside the limits the exact B_q^-1 v; outside, the
    # minimiser of (B_q u - v)^T M_q (B_q u - v) over the box, checked by its KKT
    # conditions (gradient zero on free entries, of the right sign on active bounds)
    from tmfem.control.deployment.pfl import PFLTerms, bounded_inversion
    rng = np.random.default_rng(3)
    n = 6
    A = rng.standard_normal((n, n))
    Mq = A @ A.T + n * np.eye(n)
    Bq = rng.standard_normal((n, n)) + 3 * np.eye(n)
    t = PFLTerms(M_q=Mq, F_q=np.zeros(n), B_q=Bq, M12=None, M22=None, F2=None)
    u_in = rng.uniform(0.4, 0.6, n)
    u, active = bounded_inversion(t, Bq @ u_in, lower=0.1, upper=np.ones(n))
    assert not active and np.allclose(u, u_in, atol=1e-12)
    u_out = u_in.copy()
    u_out[[1, 4]] = [1.3, -0.2]
    v = Bq @ u_out
    lo, hi = np.full(n, 0.1), np.ones(n)
    u, active = bounded_inversion(t, v, lower=lo, upper=hi)
    assert active and np.all(u >= lo) and np.all(u <= hi)
    g = Bq.T @ Mq @ (Bq @ u - v)
    free = (u > lo + 1e-9) & (u < hi - 1e-9)
    scale = np.abs(Bq.T @ Mq @ v).max()
    assert np.all(np.abs(g[free]) < 1e-8 * scale)
    assert np.all(g[u >= hi - 1e-9] <= 1e-8 * scale) and np.all(g[u <= lo + 1e-9] >= -1e-8 * scale)
    # closer in acceleration than clipping each rest length
    err = lambda w: (Bq @ w - v) @ Mq @ (Bq @ w - v)                 # noqa: E731
    assert err(u) < err(np.clip(np.linalg.solve(Bq, v), lo, hi))


def test_2_3_path_on_the_table_7_7_rule():
    # the 2-3 reference with the stage-2 base rule of Table 7.7 (deployment_bases): it ends
    # on the presets, keeps Delta = 1 mm (eq. 3.22, the rule's definition) along the path and
    # every point is a symmetric equilibrium (positive null vector of 3.3.2)
    from tmfem.reference.deployments import setup
    from tmfem.control.deployment.run import equilibrium_checker
    from tmfem.equilibrium.symmetric import membrane_delta_system
    from tmfem.equilibrium.symmetric_map import with_configuration
    from tmfem.reference.tables import deployment_bases
    f, i = load_preset("2-3-deploy"), load_preset("2-3-deploy-initial")
    ref = DeploymentReference(initial=i.symmetric, final=f.symmetric, N=3, q_names=list(f.q_names),
                              omega_r=0.5, bases=deployment_bases(f))
    assert np.allclose(ref(0.0)[0], i.q, atol=1e-6)
    d = ref(80.0)[0] - f.q
    assert np.allclose(np.angle(np.exp(1j * d)), 0, atol=1e-6)
    ss = ref.check_equilibria(checker=equilibrium_checker(f), n=6)
    for s in ss:
        assert membrane_delta_system(with_configuration(f, ref.config(s))) == pytest.approx(1e-3, rel=1e-6)
    # a rule that misses an end is refused
    with pytest.raises(InputError, match="stage bases of the initial"):
        DeploymentReference(initial=i.symmetric, final=f.symmetric, N=3, q_names=list(f.q_names),
                            omega_r=0.5, bases=deployment_bases(f, Delta=2e-3))
    assert setup("2-3-deploy", controller="adaptive").reference.bases is not None


def test_stress_recovery_superposition_against_direct_solves():
    # the recovery superposes unit corner-displacement solutions (linear plane stress,
    # eq. 5.8): von Mises (eq. 5.30) and bar compression against a direct FE solve per sample
    from tmfem.control.deployment.recovery import StressRecovery
    from tmfem.equilibrium.design import bar_axial_loads, membrane_state
    sysm = load_preset("1-4D")
    rc = StressRecovery(sysm, mesh_n=6)
    rng = np.random.default_rng(5)
    q = sysm.q + 2e-3 * rng.standard_normal((3, sysm.q.size))
    T = rng.uniform(5, 20, (3, len(sysm.tendons)))
    bar, vm = rc.bars_and_membrane(q, T)
    for k in range(3):
        E, _, sol = membrane_state(sysm, q[k], mesh_n=6)
        F3 = np.vstack([sol.corner_forces, np.zeros((1, sysm.N))])
        want = np.max(bar_axial_loads(sysm, q[k], T[k], -(E.state.R @ F3)))
        assert bar[k] == pytest.approx(want, rel=1e-9)
        assert vm[k] == pytest.approx(sol.max_von_mises, rel=1e-9)
    assert rc.critical_load == pytest.approx(891.9, rel=1e-3)       # 7.4.1


def test_stress_recovery_names_each_strength_limit_a_run_exceeds():
    # the strength checks of a run against the file's limits: the tendon yield stress (94.8 MPa
    # of the 1-4D's nylon, 7.4.1), the Euler load of the bars (eq. 5.31, 891.9 N) and the
    # membrane yield stress (61 MPa, eq. 5.30); below every limit nothing is named
    from tmfem.control.deployment.recovery import StressRecovery
    sysm = load_preset("1-4D")
    rc = StressRecovery(sysm, mesh_n=4)
    t = np.array([0.0, 0.5, 1.0])
    sig = np.full((3, len(sysm.tendons)), 50e6)
    bar_t, bar, vm = t[[0, 2]], np.array([10.0, 20.0]), np.array([1e6, 2e6])
    assert rc.failed_checks(t=t, tendon_stress=sig, bar_t=bar_t, bar_compression=bar, von_mises=vm) == []
    sig[1, 3] = 100e6
    failed = rc.failed_checks(t=t, tendon_stress=sig, bar_t=bar_t, bar_compression=np.array([10.0, 900.0]),
                              von_mises=np.array([70e6, 1e6]))
    assert len(failed) == 3
    assert failed[0].startswith(f"tendon yield: {sysm.tendons[3].name} at 100 MPa (t = 0.5 s)")
    assert "94.8 MPa" in failed[0]
    assert failed[1].startswith("bar buckling: compression 900 N (t = 1 s) above the Euler load 891.")
    assert failed[2].startswith("membrane yield: von Mises 70 MPa (t = 0 s) above the yield stress 61 MPa")


def test_1ND_delta_path_keeps_the_stretch_linear():
    # 1-N(D): psi_r from eq. 3.22 with Delta linear in the progress s between its end values
    # (closed form of eq. 3.22 via SymmetricConfig.membrane_delta); ends on the presets,
    # equilibria along it (eq. 3.41), the stage-count and rule conflicts refused
    from tmfem.control.deployment.run import equilibrium_checker
    f, i = load_preset("1-4D"), load_preset("1-4D-initial")
    ref = DeploymentReference(initial=i.symmetric, final=f.symmetric, N=4, q_names=list(f.q_names),
                              omega_r=0.7, r_mb=f.r_mb)
    D0, De = i.symmetric.membrane_delta(4, f.r_mb), f.symmetric.membrane_delta(4, f.r_mb)
    for s in (0.0, 0.3, 0.7, 1.0):
        assert ref.config(s).membrane_delta(4, f.r_mb) == pytest.approx(D0 + s * (De - D0), abs=1e-12)
    assert np.allclose(ref(0.0)[0], i.q, atol=1e-9)
    ref.check_equilibria(checker=equilibrium_checker(f), n=6)
    f23 = load_preset("2-3-deploy")
    with pytest.raises(InputError, match="one-stage"):
        DeploymentReference(initial=load_preset("2-3-deploy-initial").symmetric, final=f23.symmetric,
                            N=3, q_names=list(f23.q_names), omega_r=0.5, r_mb=f23.r_mb)


def test_partition_with_several_force_columns(model14):
    # F_q of eq. 5.41 is linear in F_hat: columns give the one-vector results
    m = model14
    M, F, B = m.matrices(m.z0, np.zeros(m.nz))
    G = np.random.default_rng(2).standard_normal(F.size)
    two = partition(M, np.column_stack([F, G]), B, nq=m.nq)
    for col, f in enumerate((F, G)):
        one = partition(M, f, B, nq=m.nq)
        assert np.allclose(two.F_q[:, col], one.F_q, rtol=1e-12, atol=1e-12)
        assert np.allclose(two.B_q, one.B_q) and np.allclose(two.F2[:, col], one.F2)


def test_setup_refuses_a_path_of_the_other_system_kind():
    from tmfem.reference.deployments import setup
    with pytest.raises(InputError, match=r"expected one of \['linear', 'delta'\]"):
        setup("1-4D", path="table-7-7-bases")
    with pytest.raises(InputError, match="allocation"):
        setup("1-4D", allocation="scale")
