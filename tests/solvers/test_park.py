"""Park's three-step method started by the trapezoidal rule (eqs. 5.34-5.35)."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.park import LinearSecondOrder, park_integrate


def _oscillator(omega, zeta=0.0):
    M = np.eye(1)
    C = np.array([[2 * zeta * omega]])
    K = np.array([[omega**2]])
    return LinearSecondOrder(M, C, K)


def _error(dt, scheme, T=2.0, omega=2 * np.pi):
    res = park_integrate(_oscillator(omega), x0=[1.0], v0=[0.0], dt=dt,
                         n_steps=int(round(T / dt)), scheme=scheme)
    exact = np.cos(omega * res.t)            # closed form of x'' + w^2 x = 0
    return np.max(np.abs(res.x[:, 0] - exact))


@pytest.mark.parametrize("scheme", ["park", "trapezoidal"])
def test_second_order_accuracy(scheme):
    # closed-form harmonic oscillator; both schemes are second order (Park 1975)
    dts = np.array([0.02, 0.01, 0.005, 0.0025])
    errs = np.array([_error(dt, scheme) for dt in dts])
    rate = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert 1.85 < rate < 2.15, (rate, errs)


def test_damped_oscillator_closed_form():
    w, z = 3.0, 0.05
    res = park_integrate(_oscillator(w, z), x0=[0.0], v0=[1.0], dt=1e-3, n_steps=3000)
    wd = w * np.sqrt(1 - z**2)
    exact = np.exp(-z * w * res.t) * np.sin(wd * res.t) / wd   # closed form
    assert np.max(np.abs(res.x[:, 0] - exact)) < 1e-5


def test_stiff_mode_is_damped_not_amplified():
    # a soft and a very stiff uncoupled oscillator, omega_stiff dt = 1e4: Park must stay
    # bounded and damp the stiff mode (L-stability), while the soft mode stays accurate.
    M = np.eye(2)
    C = np.zeros((2, 2))
    K = np.diag([1.0, 1e12])
    res = park_integrate(LinearSecondOrder(M, C, K), x0=[1.0, 1.0], v0=[0.0, 0.0],
                         dt=0.01, n_steps=500)
    assert np.all(np.abs(res.x[:, 1]) <= 1.0 + 1e-12)
    assert abs(res.x[-1, 1]) < 1e-3
    assert np.max(np.abs(res.x[:, 0] - np.cos(res.t))) < 1e-3   # closed form cos t


def test_trapezoidal_conserves_energy_linear():
    # trapezoidal rule conserves the quadratic energy of a linear undamped system exactly
    K = np.array([[2.0, -1.0], [-1.0, 2.0]])
    M = np.diag([1.0, 2.0])
    res = park_integrate(LinearSecondOrder(M, np.zeros((2, 2)), K), x0=[1.0, 0.0],
                         v0=[0.0, 0.3], dt=0.1, n_steps=400, scheme="trapezoidal")
    E = 0.5 * np.einsum("ti,ij,tj->t", res.v, M, res.v) + 0.5 * np.einsum("ti,ij,tj->t", res.x, K, res.x)
    assert np.ptp(E) < 1e-12 * E[0] * 100


class _Pendulum:
    """Nonlinear pendulum theta'' + (g/L) sin(theta) = 0."""
    w2 = 9.81

    def residual(self, x, v, a, t):
        return a + self.w2 * np.sin(x)

    def jacobians(self, x, v, a, t):
        return np.diag(self.w2 * np.cos(x)), np.zeros((1, 1)), np.eye(1)


def test_nonlinear_pendulum_against_solve_ivp():
    res = park_integrate(_Pendulum(), x0=[2.0], v0=[0.0], dt=2e-3, n_steps=1500)
    ref = solve_ivp(lambda t, y: [y[1], -9.81 * np.sin(y[0])], (0, 3.0), [2.0, 0.0],
                    t_eval=res.t, rtol=1e-11, atol=1e-12)
    assert np.max(np.abs(res.x[:, 0] - ref.y[0])) < 5e-3
    # modified Newton (Jacobian once per step) converges to the same answer
    res2 = park_integrate(_Pendulum(), x0=[2.0], v0=[0.0], dt=2e-3, n_steps=1500,
                          jacobian="step")
    assert np.max(np.abs(res2.x - res.x)) < 1e-8
    assert res2.jacobian_evaluations == 1500


def test_sparse_jacobians_and_callback():
    import scipy.sparse as sp
    n = 50
    K = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n), format="csr") * 100.0
    sysd = LinearSecondOrder(np.eye(n), np.zeros((n, n)), K.toarray())
    syss = LinearSecondOrder(sp.identity(n, format="csr"), sp.csr_matrix((n, n)), K)
    x0 = np.sin(np.linspace(0, np.pi, n))
    v0 = np.zeros(n)
    rows = []
    rd = park_integrate(sysd, x0=x0, v0=v0, dt=0.01, n_steps=50)
    rs = park_integrate(syss, x0=x0, v0=v0, dt=0.01, n_steps=50, store=False,
                        callback=lambda t, x, v, a: rows.append(t))
    assert len(rows) == 51
    assert np.allclose(rs.x[0], rd.x[-1], atol=1e-12)


def test_errors():
    with pytest.raises(InputError):
        park_integrate(_oscillator(1.0), x0=[1.0], v0=[0.0], dt=-1.0, n_steps=3)
    with pytest.raises(InputError):
        park_integrate(_oscillator(1.0), x0=[1.0], v0=[0.0], dt=0.1, n_steps=3, scheme="rk4")

    class Diverge(_Pendulum):
        def jacobians(self, x, v, a, t):   # wrong sign: Newton cannot converge
            return -np.eye(1) * 1e3, np.zeros((1, 1)), -np.eye(1) * 1e-9
    with pytest.raises(ConvergenceError):
        park_integrate(Diverge(), x0=[2.0], v0=[0.0], a0=[0.0], dt=0.1, n_steps=5, max_iter=5)


class _HardDuffing:
    """x'' + x + k3 x^3 = 0 with k3 = 1e6: over one swing the tangent 1 + 3 k3 x^2 changes by
    far more than the factor 2 a kept (modified-Newton) matrix tolerates."""

    k3 = 1e6

    def residual(self, x, v, a, t):
        return a + x + self.k3 * x**3

    def jacobians(self, x, v, a, t):
        return np.diag(1 + 3 * self.k3 * x**2), np.zeros((1, 1)), np.eye(1)


def test_kept_matrix_restarts_with_full_newton_and_lands_on_the_same_solution():
    # the Park equations of a step have one solution near the predictor; full Newton
    # ("iteration") finds it, and the kept-matrix variants must find the same one. With this
    # stiffening spring the kept matrix makes the corrections grow, which triggers the restart
    kw = dict(x0=np.array([1.0]), v0=np.array([0.0]), dt=0.002, n_steps=500)
    full = park_integrate(_HardDuffing(), jacobian="iteration", **kw)
    reuse = park_integrate(_HardDuffing(), jacobian="reuse", **kw)
    step = park_integrate(_HardDuffing(), jacobian="step", **kw)
    assert reuse.restarts > 0 and full.restarts == 0
    np.testing.assert_allclose(reuse.x, full.x, atol=1e-8)
    np.testing.assert_allclose(step.x, full.x, atol=1e-8)
    assert reuse.jacobian_evaluations < full.jacobian_evaluations / 2


class _QuasiStaticArctan:
    """m x'' + arctan(x - A sin t) = 0 with m -> 0: a quasi-static dof, x = A sin t - tan(m a)
    (closed form), whose Newton matrix (K = 1 / (1 + (x - A sin t)^2), the mass term ~1e-8)
    makes plain Newton overshoot and diverge once the predictor misses by |z| > 1.39 (Newton
    on arctan), as the SBC shell's soft rotations do (docs/guides/sbc.md, "Free vibration on the
    fine mesh")."""

    m, A = 1e-9, 100.0

    def residual(self, x, v, a, t):
        return self.m * a + np.arctan(x - self.A * np.sin(t))

    def jacobians(self, x, v, a, t):
        z = x - self.A * np.sin(t)
        return np.diag(1.0 / (1.0 + z**2)), np.zeros((1, 1)), self.m * np.eye(1)


def test_line_search_converges_where_plain_newton_diverges():
    kw = dict(x0=[0.0], v0=[_QuasiStaticArctan.A], dt=0.5, n_steps=30)
    # the predictor misses x(t) by ~A dt^3 / 6 = 2.1 > 1.39: plain Newton diverges, named so
    with pytest.raises(ConvergenceError, match=r"Park step \d+ \(t = .* s, dt = 0.5 s\): "
                                               r"Newton diverged .* at the predictor"):
        park_integrate(_QuasiStaticArctan(), **kw)
    res = park_integrate(_QuasiStaticArctan(), line_search=True, **kw)
    exact = _QuasiStaticArctan.A * np.sin(res.t)
    assert res.steps == 30
    assert np.max(np.abs(res.x[:, 0] - exact)) < 1e-5       # tan(m a) with |a| <~ A / dt^2
    # where plain Newton converges, the line search takes every correction whole
    smooth = dict(x0=[0.0], v0=[_QuasiStaticArctan.A], dt=0.05, n_steps=100)
    a = park_integrate(_QuasiStaticArctan(), **smooth)
    b = park_integrate(_QuasiStaticArctan(), line_search=True, **smooth)
    np.testing.assert_array_equal(a.x, b.x)
    assert a.newton_iterations == b.newton_iterations
