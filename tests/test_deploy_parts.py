"""Parts of the deployment controller (issue 13): reference (eq. 5.68), PFL partition
(eqs. 5.39-5.41), B_q check, RBF and projection (eqs. 5.44, 5.51-5.52), gains (eq. 5.69),
rest-length saturation and switching (eq. 5.70)."""
import numpy as np
import pytest

from tmfem.control.adaptive import Gains
from tmfem.control.pfl import check_input_matrix, partition
from tmfem.control.rbf import GaussianRBF, euler_step, projection
from tmfem.control.reference_trajectory import DeploymentReference, theta_reference
from tmfem.control.switching import SwitchingController, relative_error
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


def test_input_matrix_check_refuses_singular_and_nonsquare():
    with pytest.raises(SingularInputMatrix, match="square"):
        check_input_matrix(np.ones((3, 4)))
    with pytest.raises(SingularInputMatrix, match="condition number"):
        check_input_matrix(np.diag([1.0, 1e-14]))


def test_rbf_values():
    r = GaussianRBF(centres=[[0.0, 0.0], [1.0, 0.0]], sigma=0.5)
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
    from tmfem.control.deploy import RestLengthLimits

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


def test_switching_bumpless():
    # eq. 5.70 with q_e = (1, 2): switch at the first sample within R_c; a dynamic linear
    # controller then starts from a state giving the deployment controller's last input
    import control

    class Const:
        name = "first"

        def reset(self, t0, y0, dt):
            return np.zeros(0)

        def output(self, t, y, xc):
            return np.array([0.3])

        def update(self, t, y, xc):
            return xc
    q_e = np.array([1.0, 2.0])
    assert relative_error([1.01, 2.0], q_e) == pytest.approx(0.01)
    lin = LinearController(control.ss([[-1.0]], [[1.0, 0.0]], [[2.0]], [[0.0, 0.0]]),
                           u_e=[0.1], y_e=q_e, name="lin")
    sw = SwitchingController(first=Const(), second=lin, q_of_y=lambda y: y, q_e=q_e,
                             measure=lambda y: y, R_c=0.01)
    xc = sw.reset(0.0, np.array([1.5, 2.0]), 0.01)
    u = sw.output(0.0, np.array([1.5, 2.0]), xc)
    xc = sw.update(0.0, np.array([1.5, 2.0]), xc)
    assert sw.name == "first" and u[0] == 0.3
    y = np.array([1.005, 2.0])
    u = sw.output(0.01, y, xc)
    assert sw.switch_time == 0.01 and sw.name == "lin"
    assert u[0] == pytest.approx(0.3) and sw.switch_jump == pytest.approx(0.0, abs=1e-12)
