"""The scheduled LPV controller (eqs. 5.98-5.99 as a simulation controller) and the pointwise
lower bound of the LPV gamma, on small plants with known answers."""
import numpy as np
import pytest
import scipy.linalg as sla

from tmfem.control.linear.hinf_lmi import hinf_gamma
from tmfem.control.linear.hinf_riccati import state_feedback_gamma
from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
from tmfem.control.lpv.controller import LPVController
from tmfem.control.lpv.plant import GriddedLPV
from tmfem.control.lpv.generalized_plant import interconnection_8_1
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.errors import InputError

X0 = 0.5        # equilibrium position of the oscillator at every grid point


def oscillator(rho=(0.0, 1.0, 2.0)):
    """x'' + 0.1 x' + (1 + rho) x = u about x_e = X0, u_e = (1 + rho) X0; y = [x, x']."""
    rho = np.asarray(rho, dtype=float)
    k = rho.size
    return GriddedLPV(axes=[rho], parameter_names=["rho"],
                      A=np.array([[[0, 1], [-(1 + r), -0.1]] for r in rho]),
                      B=np.broadcast_to([[0.0], [1.0]], (k, 2, 1)), C=np.broadcast_to(np.eye(2), (k, 2, 2)),
                      D=np.zeros((k, 2, 1)), rate_bounds=[[-0.2, 0.2]], state_names=["x", "v"],
                      input_names=["u"], output_names=["x", "v"],
                      x_e=np.array([[X0, 0.0]] * k), u_e=np.array([[(1 + r) * X0] for r in rho]),
                      y_e=np.array([[X0, 0.0]] * k))


def test_scheduled_controller_tracks_a_step_with_integral_action():
    pl = oscillator()
    design = synthesize_state_feedback(interconnection_8_1(pl, tracked=["x"], W_u=0.5))
    q_d = 0.7
    c = LPVController(design, pl, state_index=[0, 1], q_index=[0], rho_index=[2], reference=lambda t: [q_d])
    # the true plant frozen at rho = 1.3 (between grid points), exact zero-order-hold steps
    rho, dt = 1.3, 0.01
    A = np.array([[0, 1], [-(1 + rho), -0.1]])
    B = np.array([[0.0], [1.0]])
    E = sla.expm(np.block([[A, B], [np.zeros((1, 3))]]) * dt)
    Ad, Bd = E[:2, :2], E[:2, 2:]
    x = np.array([X0, 0.0])
    y = np.concatenate([x, [rho]])
    xc = c.reset(0.0, y, dt)
    # bumpless start at the equilibrium: u = u_e(rho) (interpolated: (1 + rho) X0)
    assert c.output(0.0, y, xc) == pytest.approx([(1 + rho) * X0], rel=1e-12)
    for k in range(6000):
        y = np.concatenate([x, [rho]])
        u = c.output(k * dt, y, xc)
        xc = c.update(k * dt, y, xc)
        x = Ad @ x + Bd @ u
    # integral action: zero steady-state error, and the static balance (1 + rho) x = u
    assert x[0] == pytest.approx(q_d, abs=1e-6)
    assert u[0] == pytest.approx((1 + rho) * q_d, abs=1e-5)


def test_scheduled_controller_holds_rho_in_the_grid_and_refuses_bad_indices():
    pl = oscillator()
    design = synthesize_state_feedback(interconnection_8_1(pl, tracked=["x"]))
    c = LPVController(design, pl, state_index=[0, 1], q_index=[0], rho_index=[2], reference=lambda t: [X0])
    assert c.rho([0.0, 0.0, 5.0]) == pytest.approx([2.0])
    with pytest.raises(InputError, match="scheduling indices"):
        LPVController(design, pl, state_index=[0], q_index=[0], rho_index=[2], reference=lambda t: [X0])
    with pytest.raises(InputError, match="dt > 0"):
        c.reset(0.0, np.zeros(3), 0.0)
    # equilibria at the reference's parameters: at the equilibrium state with zero integrators
    # the output is u_e(rho_r) = (1 + rho_r) X0 (rho_r = 0.5), not u_e of the measured 1.3
    cr = LPVController(design, pl, state_index=[0, 1], q_index=[0], rho_index=[2], reference=lambda t: [X0],
                       reference_rho=lambda t: [0.5])
    assert cr.output(0.0, [X0, 0.0, 1.3], np.zeros(1)) == pytest.approx([1.5 * X0], rel=1e-12)
    with pytest.raises(InputError, match="rho_r"):
        LPVController(design, pl, state_index=[0, 1], q_index=[0], rho_index=[2], reference=lambda t: [X0],
                      reference_rho=[0.5])


def test_state_feedback_riccati_test_matches_the_lmi():
    # the eliminated LMIs with y = x (Clarabel; equal to the static state-feedback optimum:
    # with C2 = I, D21 = 0 the dual LMI is ||D11|| < gamma) and the Riccati test: one optimum
    rng = np.random.default_rng(2)
    n, nw, nu = 4, 3, 2
    A = rng.standard_normal((n, n))
    A -= (np.max(np.linalg.eigvals(A).real) - 0.3) * np.eye(n)
    from tmfem.control.linear.hinf_lmi import GeneralizedPlant
    C1 = np.vstack([rng.standard_normal((2, n)), np.zeros((nu, n))])
    D12 = np.vstack([np.zeros((2, nu)), np.eye(nu)])
    D11 = np.zeros((4, nw))
    D11[0, 0] = 3.0
    P = GeneralizedPlant(A=A, B1=rng.standard_normal((n, nw)), B2=rng.standard_normal((n, nu)), C1=C1,
                         C2=np.eye(n), D11=D11, D12=D12, D21=np.zeros((n, nw)), D22=np.zeros((n, nu)),
                         state_names=[f"x{i}" for i in range(n)], w_names=[f"w{i}" for i in range(nw)],
                         u_names=["u0", "u1"], p_names=[f"p{i}" for i in range(4)],
                         y_names=[f"y{i}" for i in range(n)])
    g_lmi, _ = hinf_gamma(P)
    g_are = state_feedback_gamma(P.A, P.B1, P.B2, P.C1, P.D11, P.D12)
    # Clarabel's point is feasible (an upper bound), 8e-5 above here
    assert g_are <= g_lmi * (1 + 1e-6) and g_are == pytest.approx(g_lmi, rel=2e-4)


def test_pointwise_bound_is_below_the_lpv_gamma():
    # the gridded LMI at a grid point implies the frozen state-feedback problem there
    pl = oscillator()
    gp = interconnection_8_1(pl, tracked=["x"])
    b = pointwise_state_feedback_bound(gp)
    design = synthesize_state_feedback(gp)
    assert b.gamma.shape == (3,) and b.lower_bound == pytest.approx(b.gamma.max())
    assert b.lower_bound <= design.gamma * (1 + 1e-5)
    # a single grid point with zero rates: the LPV synthesis is the LTI problem
    one = interconnection_8_1(oscillator(rho=[1.0]), tracked=["x"])
    one.rate_bounds = np.zeros((1, 2))
    assert synthesize_state_feedback(one).gamma == pytest.approx(
        pointwise_state_feedback_bound(one).lower_bound, rel=1e-4)
