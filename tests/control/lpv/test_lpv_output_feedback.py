"""Observer-based LPV output feedback (tmfem.control.lpv.output_feedback) on the oscillator of
docs/guides/lpv.md (not a tensegrity), against python-control and closed forms."""
import control
import numpy as np
import pytest
import scipy.linalg as sla

from tmfem.control.lpv.output_feedback import (LPVOutputController, design_output_feedback, kalman_gain,
                                      sampled_closed_loops, verify_output_feedback)
from tmfem.control.lpv.plant import GriddedLPV
from tmfem.control.lpv.generalized_plant import interconnection_8_1
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.errors import InfeasibleController, InputError
from tmfem.simulation.controllers import LinearController, MeasurementNoise

X0 = 0.5
W_E, W_U = 0.5, 0.5


def oscillator(rho=(0.0, 1.0, 2.0), shift=0.0):
    """x'' + 0.1 x' + (1 + rho) x = u (A shifted by ``shift`` I) about x_e = X0; output x."""
    rho = np.asarray(rho, dtype=float)
    k = rho.size
    return GriddedLPV(axes=[rho], parameter_names=["rho"],
                      A=np.array([[[shift, 1], [-(1 + r), -0.1 + shift]] for r in rho]),
                      B=np.broadcast_to([[0.0], [1.0]], (k, 2, 1)), C=np.broadcast_to([[1.0, 0.0]], (k, 1, 2)),
                      D=np.zeros((k, 1, 1)), rate_bounds=[[-0.2, 0.2]], state_names=["x", "v"],
                      input_names=["u"], output_names=["y"], x_e=np.array([[X0, 0.0]] * k),
                      u_e=np.array([[(1 + r) * X0] for r in rho]), y_e=np.array([[X0]] * k))


@pytest.fixture(scope="module")
def design():
    pl = oscillator()
    sf = synthesize_state_feedback(interconnection_8_1(pl, tracked=["y"], W_e=W_E, W_u=W_U))
    return pl, design_output_feedback(sf, pl, tracked=["y"], measured=["y"], W_d=0.3, W_n=0.01)


def test_kalman_gain_is_python_controls_lqe():
    pl = oscillator()
    A, B, C = pl.A[1], pl.B[1], pl.C[1]
    L, _, _ = control.lqe(A, B, C, 0.3 ** 2 * np.eye(1), 0.01 ** 2 * np.eye(1))
    np.testing.assert_allclose(kalman_gain(A, B, C, W_d=0.3, W_n=0.01), L, rtol=1e-8)


def test_separation_at_a_grid_point(design):
    # the frozen loop at a design point (true plant = estimator model) has the eigenvalues of
    # A + B2 K (state feedback on [x, xi]) and of A - L C (separation principle)
    pl, d = design
    A, B, C = pl.A[2], pl.B[2], pl.C[2]
    rho = [2.0]
    Acl = d.frozen_closed_loop(A, B, C, rho, W_e=W_E, W_u=W_U)[0]
    gp = interconnection_8_1(pl, tracked=["y"], W_e=W_E, W_u=W_U)
    K = d.state_feedback.gain(rho)
    L = d.estimator.B[2][:, 1:]
    want = np.concatenate([np.linalg.eigvals(gp.A[2] + gp.B2[2] @ K), np.linalg.eigvals(A - L @ C)])
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(Acl)), np.sort_complex(want), atol=1e-9)


def test_closed_loop_matches_python_control_interconnect(design):
    # an independent assembly of the frozen loop off the grid (rho = 1.3): plant, integrator
    # and estimator as named python-control blocks joined by control.interconnect
    pl, d = design
    rho = [1.3]
    A, B, C, _ = pl.at(rho)
    Am, Bm, Cm, L, Kx, Kxi = d.model(rho)
    W_d, W_n = d.W_d, d.W_n
    G = control.ss(A, np.hstack([B, W_d * B]), C, 0, inputs=["u", "nd"], outputs=["q"], name="G")
    sens = control.summing_junction(inputs=["q", "nn"], output="ym", name="sens")
    nn = control.ss([], [], [], [[W_n]], inputs=["n"], outputs=["nn"], name="Wn")
    integ = control.ss([[0.0]], [[1.0, -1.0]], [[1.0]], 0, inputs=["qd", "ym"], outputs=["xi"], name="I")
    est = control.ss(Am - L @ Cm, np.hstack([Bm, L]), np.eye(2), 0, inputs=["u", "ym"],
                     outputs=["e0", "e1"], name="est")
    law = control.ss([], [], [], np.hstack([Kx, Kxi]), inputs=["e0", "e1", "xi"], outputs=["u"], name="K")
    er = control.summing_junction(inputs=["qd", "-q"], output="eq", name="err")
    W = control.ss([], [], [], np.diag([W_E, W_U]), inputs=["eq", "u"], outputs=["p0", "p1"], name="W")
    T = control.interconnect([G, sens, nn, integ, est, law, er, W], inputs=["qd", "nd", "n"],
                             outputs=["p0", "p1"])
    Acl, Bcl, Ccl, Dcl = d.frozen_closed_loop(A, B, C, rho, W_e=W_E, W_u=W_U)
    mine = control.ss(Acl, Bcl, Ccl, Dcl)
    np.testing.assert_allclose(np.sort_complex(T.poles()), np.sort_complex(mine.poles()), atol=1e-8)
    assert control.norm(mine, p="inf") == pytest.approx(control.norm(T, p="inf"), rel=1e-6)
    for w in (0.0, 0.7, 3.0):
        np.testing.assert_allclose(mine(1j * w), T(1j * w), atol=1e-9)


def test_off_grid_verification_passes_and_refuses_a_wrong_plant(design):
    pl, d = design
    fine = pl.resampled(pl.refined(4))
    v = verify_output_feedback(d, fine, W_e=W_E, W_u=W_U, dt=0.01)
    assert v.passed and v.grid == (9,) and v.max_cl_real < 0 and v.max_sampled_radius < 1
    # at dt = 0.01 s the sampled loop is close to the continuous one: radius ~ exp(dt max Re)
    assert v.max_sampled_radius == pytest.approx(np.exp(0.01 * v.max_cl_real), abs=1e-3)
    # its norm is at least the feedthrough W_e of q_d to e_r (D11, no controller changes it)
    assert v.max_hinf >= W_E * (1 - 1e-9) and np.isfinite(v.max_hinf)
    bad = oscillator(shift=3.0).resampled(pl.refined(4))
    with pytest.raises(InfeasibleController, match="frozen-parameter verification"):
        verify_output_feedback(d, bad, W_e=W_E, W_u=W_U)
    assert not verify_output_feedback(d, bad, W_e=W_E, W_u=W_U, allow_failure=True).passed


@pytest.mark.slow
def test_controller_steps_are_the_sampled_loop_and_track_a_step(design):
    pl, d = design
    rho, dt = 1.3, 0.01
    A, B, C, _ = pl.at([rho])
    E = sla.expm(np.block([[A, B], [np.zeros((1, 3))]]) * dt)
    Ad, Bd = E[:2, :2], E[:2, 2:]
    q_d = 0.7
    c = LPVOutputController(d, measured_index=[0], rho_index=[1], reference=lambda t: [q_d])
    x = np.array([X0 + 0.05, 0.0])                            # off the equilibrium
    xc = c.reset(0.0, [x[0], rho], dt)
    # the first steps follow the transition matrix of sampled_closed_loops with q_d = X0
    # (deviations from the equilibrium interpolated at rho: x_e = X0, u_e = (1 + rho) X0)
    c0 = LPVOutputController(d, measured_index=[0], rho_index=[1], reference=lambda t: [X0])
    M = sampled_closed_loops(d, A, B, C, [rho], dt)[0]
    s = np.concatenate([x - [X0, 0], [0.0], [0.0, 0.0]])
    xk, xck = x.copy(), c0.reset(0.0, [x[0], rho], dt)
    for k in range(5):
        y = [xk[0], rho]
        u = c0.output(k * dt, y, xck)
        xck = c0.update(k * dt, y, xck)
        xk = Ad @ xk + Bd @ u
        s = M @ s
        np.testing.assert_allclose(np.concatenate([xk - [X0, 0], xck[2:], xck[:2] - [X0, 0]]), s, atol=1e-12)
    for k in range(8000):
        y = [x[0], rho]
        u = c.output(k * dt, y, xc)
        xc = c.update(k * dt, y, xc)
        x = Ad @ x + Bd @ u
    # integral action through the measured output: zero error, static balance (1 + rho) x = u
    assert x[0] == pytest.approx(q_d, abs=1e-6)
    assert u[0] == pytest.approx((1 + rho) * q_d, abs=1e-5)


def test_bad_input_is_refused(design):
    pl, d = design
    with pytest.raises(InputError, match="must be measured"):
        design_output_feedback(d.state_feedback, pl, tracked=["y"], measured=["v"])
    with pytest.raises(InputError, match="unknown"):
        design_output_feedback(d.state_feedback, pl, tracked=["y"], measured=["z"])
    with pytest.raises(InputError, match="W_n expected > 0"):
        design_output_feedback(d.state_feedback, pl, tracked=["y"], measured=["y"], W_n=0.0)
    with pytest.raises(InputError, match="scheduling indices"):
        LPVOutputController(d, measured_index=[0], rho_index=[], reference=lambda t: [X0])


def test_measurement_noise_is_one_seeded_sample_per_step():
    K = np.array([[2.0, -1.0]])
    base = LinearController(K, u_e=[0.0], y_e=[0.0, 0.0])
    base.reset(0.0, np.zeros(2), 0.01)
    c = MeasurementNoise(base, sigma=[0.1, 0.2], seed=3)
    xc = c.reset(0.0, np.zeros(2), 0.01)
    y = np.array([1.0, 1.0])
    n = np.random.default_rng(3).standard_normal((2, 2))     # reset's sample, then t = 0.01's
    u1 = c.output(0.01, y, xc)
    assert u1 == pytest.approx(K @ (y + np.array([0.1, 0.2]) * n[1]))
    assert c.output(0.01, y, xc) == pytest.approx(u1)               # same step, same sample
    assert c.name == base.name
    with pytest.raises(InputError, match="sigma >= 0"):
        MeasurementNoise(base, sigma=-1.0)


def test_reference_rho_and_scheduling_on_the_estimate(design):
    pl, d = design
    xc = np.array([X0 + 0.02, 0.1, 0.3])                     # [x^, v^, xi]
    y = [X0 + 0.01, 1.3]
    base = LPVOutputController(d, measured_index=[0], rho_index=[1], reference=lambda t: [X0])
    base.reset(0.0, y, 0.01)
    # about rho_r: x_e = X0 at every grid point, so only the feed-forward u_e(rho_r) changes:
    # u(rho_r) - u(rho) = (rho_r - rho) X0 (u_e = (1 + rho) X0, interpolated exactly)
    ref = LPVOutputController(d, measured_index=[0], rho_index=[1], reference=lambda t: [X0],
                              reference_rho=lambda t: [0.4])
    ref.reset(0.0, y, 0.01)
    assert ref.output(0.0, y, xc) - base.output(0.0, y, xc) == pytest.approx([(0.4 - 1.3) * X0], abs=1e-12)
    # scheduling on the estimate: the parameters read from x^ by name ("x" here, rho = x^ = 0.52)
    ax = GriddedLPV(**{**{k: getattr(pl, k) for k in ("axes", "A", "B", "C", "D", "rate_bounds", "state_names",
                                                     "input_names", "output_names", "x_e", "u_e", "y_e")},
                       "parameter_names": ["x"]})
    dx = design_output_feedback(d.state_feedback, ax, tracked=["y"], measured=["y"], W_d=0.3, W_n=0.01)
    est = LPVOutputController(dx, measured_index=[0], rho_index=[1], reference=lambda t: [X0], schedule="estimate")
    est.reset(0.0, y, 0.01)
    assert est.output(0.0, y, xc) == pytest.approx(base.output(0.0, [y[0], xc[0]], xc), abs=1e-12)
    with pytest.raises(InputError, match="among the plant states"):
        LPVOutputController(d, measured_index=[0], rho_index=[1], reference=lambda t: [X0], schedule="estimate")


def test_estimator_is_driven_by_the_saturated_input(design):
    # with input_limits the estimate advances with the input the plant receives:
    # x^+ differs by Gamma_u (u_sat - u) (the zero-order-hold step of step_matrices)
    pl, d = design
    rho, dt = 1.3, 0.01
    y, xc = [X0 + 0.01, rho], np.array([X0 + 0.02, 0.1, 0.3])
    kw = dict(measured_index=[0], rho_index=[1], reference=lambda t: [X0])
    free = LPVOutputController(d, **kw)
    lim = LPVOutputController(d, **kw, input_limits=lambda u, ym: np.minimum(u, 0.5))
    free.reset(0.0, y, dt), lim.reset(0.0, y, dt)
    u = free.output(0.0, y, xc)
    assert lim.output(0.0, y, xc) == pytest.approx(u)            # the command itself is unchanged
    assert u[0] > 0.5
    Gu = d.step_matrices([rho], dt)[1]
    np.testing.assert_allclose(lim.update(0.0, y, xc)[:2] - free.update(0.0, y, xc)[:2], Gu @ (0.5 - u), atol=1e-14)


def test_spline_estimator_interpolation(design, tmp_path):
    """``interpolation="spline"``: the estimator's model through the grid points (here affine
    in rho, so both methods give the true A between them), its gains L(rho) the parabola
    through the three grid gains (the multilinear ones differ off the grid), the method
    saved with the design; an unknown method is refused."""
    pl, d = design
    ds = design_output_feedback(d.state_feedback, pl, tracked=["y"], measured=["y"], W_d=0.3,
                                W_n=0.01, interpolation="spline")
    assert ds.estimator.interpolation == "spline" and d.estimator.interpolation == "multilinear"
    rho = [0.7]
    np.testing.assert_allclose(ds.estimator.at(rho)[0], [[0, 1], [-1.7, -0.1]], atol=1e-13)
    L = ds.estimator.B[:, :, 1:]
    parabola = np.polynomial.polynomial.polyval(0.7, np.polynomial.polynomial.polyfit([0, 1, 2], L[:, :, 0], 2))
    np.testing.assert_allclose(ds.estimator.at(rho)[1][:, 1], parabola, rtol=1e-12)
    assert np.abs(d.estimator.at(rho)[1][:, 1] - parabola).max() > 1e-6
    ds.save(tmp_path / "of.npz")
    assert str(np.load(tmp_path / "of.npz")["interpolation"]) == "spline"
    with pytest.raises(InputError, match="interpolation expected one of"):
        design_output_feedback(d.state_feedback, pl, tracked=["y"], measured=["y"], interpolation="cubic")
