"""General gridded LPV synthesis (lpvsyn): user basis functions, state and output feedback,
off-grid verification, refusals; compared with independent formulations."""
import control
import numpy as np
import pytest

from tmfem.control.linear.hinf_lmi import hinf_gamma
from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tmfem.control.lpv import lpvsyn
from tmfem.control.lpv.basis import Basis
from tmfem.control.lpv.examples import rotating_spring
from tmfem.control.lpv.plant import GriddedLPV
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.errors import InfeasibleController, InputError

#: the rotating saddle: negative stiffness along an axis that turns with rho/2
SADDLE = {"k0": 0.2, "k1": 1.0, "r": 1.0}
GRID = np.linspace(-np.pi, np.pi, 13)


@pytest.fixture(scope="module")
def trig_design():
    return lpvsyn(rotating_spring(**SADDLE), 2, 2, grid=GRID, rate_bounds=0.5,
                  basis=Basis.trigonometric(), backoff=0.05)


def frozen_lti_optimum(P, rho, nw, ny):
    """The LTI H-infinity optimum of the frozen plant (eliminated LMIs, tmfem.control.linear)."""
    return hinf_gamma(GeneralizedPlant.from_ss(control.ss(*P([rho])), nw=nw, ny=ny))[0]


def test_trigonometric_basis_certifies_and_verifies_off_the_grid(trig_design):
    r = trig_design
    v = r.verification
    assert v["passed"] and v["grid"] == [4 * 12 + 1]
    assert v["max_lmi_eig"] < 0 and v["min_lyapunov_eig"] > 0            # rate-bounded certificate
    assert v["max_closed_loop_real"] < 0 and v["max_frozen_norm"] <= r.gamma
    # lower bound: each frozen design point's LTI optimum (rho' = 0 is inside the rate box)
    bound = max(frozen_lti_optimum(rotating_spring(**SADDLE), x, 4, 2) for x in GRID)
    assert r.gamma_min >= bound * (1 - 1e-5)
    assert r.gamma_min <= 1.2 * bound
    # the controller between grid points: its frozen loop, assembled with python-control
    rho = 0.123
    K = r.controller.ss([rho])
    plant = control.ss(*rotating_spring(**SADDLE)([rho]))
    T = plant.lft(K, nu=2, ny=2)                                 # python-control LFT
    assert np.max(T.poles().real) < 0
    assert control.norm(T, p="inf") <= r.gamma


@pytest.mark.slow
def test_affine_basis_is_worse_than_the_trigonometric_one(trig_design):
    # the affine basis in rho cannot follow the turning axis: with the same rate bounds on the
    # same grid its optimum is far above the trigonometric basis' certified level
    r = lpvsyn(rotating_spring(**SADDLE), 2, 2, grid=GRID, rate_bounds=0.5, basis="affine")
    assert r.gamma_min > 1.2 * trig_design.gamma


def test_lti_plant_on_a_constant_grid_is_the_lti_optimum():
    sys = control.ss(*rotating_spring(**SADDLE)([0.7]))
    r = lpvsyn(sys, 2, 2, grid=np.linspace(-np.pi, np.pi, 5), rate_bounds=1.0, basis=Basis.trigonometric())
    g = hinf_gamma(GeneralizedPlant.from_ss(sys, nw=4, ny=2))[0]
    assert r.gamma_min == pytest.approx(g, rel=1e-4)
    assert r.verification["passed"]


def test_output_feedback_with_the_full_state_measured_is_state_feedback():
    # C2 = I, D21 = 0: the Y block of the output-feedback LMI is the state-feedback LMI, so
    # gamma_OF >= gamma_SF exactly, and X -> infinity approaches it
    sf = rotating_spring(output_feedback=False, **SADDLE)

    def full_information(rho):
        A, B, C, D = sf(rho)
        return A, B, np.vstack([C, np.eye(4)]), np.vstack([D, np.zeros((4, B.shape[1]))])
    grid = np.linspace(-np.pi, np.pi, 7)
    rs = lpvsyn(sf, 0, 2, grid=grid, rate_bounds=0.5, basis=Basis.trigonometric(), verify_refine=1)
    ro = lpvsyn(full_information, 4, 2, grid=grid, rate_bounds=0.5, basis=Basis.trigonometric(),
                verify_refine=1)
    assert rs.gamma_min * (1 - 1e-6) <= ro.gamma_min <= rs.gamma_min * (1 + 5e-3)
    assert rs.verification["frozen_passed"] and ro.verification["frozen_passed"]
    K = rs.controller.at([0.3])[3]                             # u = K(rho) x
    c = rs.certificate.at([0.3])                               # P, Q in the plant's coordinates
    np.testing.assert_allclose(K, np.linalg.solve(c["P"], c["Q"].T).T, rtol=1e-8, atol=1e-10)
    # the coefficients in the user's basis {1, cos, sin} give the same P(rho)
    Pk = rs.certificate.coefficients_in_user_basis()["P"]
    P_user = Pk[0] + np.cos(0.3) * Pk[1] + np.sin(0.3) * Pk[2]
    np.testing.assert_allclose(P_user, rs.certificate.scaled_at([0.3])["P"], rtol=1e-9, atol=1e-12)


def oscillator_gp():
    """x'' + (0.2 + 0.1 rho2) x' + (1 + rho1) x = u + w, p = [x; 0.3 u] on a 3 x 2 grid."""
    r1, r2 = np.array([0.0, 1.0, 2.0]), np.array([0.0, 1.0])
    R1, R2 = np.meshgrid(r1, r2, indexing="ij")
    A = np.zeros((3, 2, 2, 2))
    A[..., 0, 1] = 1.0
    A[..., 1, 0] = -(1 + R1)
    A[..., 1, 1] = -(0.2 + 0.1 * R2)
    col = np.broadcast_to([[0.0], [1.0]], (3, 2, 2, 1))
    return GeneralizedLPV.from_matrices(
        axes=[r1, r2], parameter_names=["k", "c"], rate_bounds=[[-0.5, 0.5], [-1.0, 1.0]], A=A, B1=col, B2=col,
        C1=np.broadcast_to([[1.0, 0.0], [0.0, 0.0]], (3, 2, 2, 2)), D11=np.zeros((3, 2, 2, 1)),
        D12=np.broadcast_to([[0.0], [0.3]], (3, 2, 2, 1)))


def test_affine_state_feedback_reproduces_the_chapter_8_synthesis():
    # the affine basis {1, rho_n1, rho_n2} is eq. 5.99; synthesize_state_feedback builds the same
    # LMIs (eqs. 5.95-5.96) as its own sparse conic program
    gp = oscillator_gp()
    ref = synthesize_state_feedback(gp)
    r = lpvsyn(gp, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine")
    assert r.gamma_min == pytest.approx(ref.gamma, rel=1e-4)
    assert r.verification["passed"]


def test_rate_dependent_controller_when_both_lyapunov_matrices_vary():
    P = rotating_spring(**SADDLE)
    grid = np.linspace(-np.pi, np.pi, 7)
    both = lpvsyn(P, 2, 2, grid=grid, rate_bounds=0.5, basis=Basis.trigonometric(), constant=None,
                  verify_refine=1)
    x_const = lpvsyn(P, 2, 2, grid=grid, rate_bounds=0.5, basis=Basis.trigonometric(), verify_refine=1)
    assert both.gamma_min <= x_const.gamma_min * (1 + 1e-5)         # a larger set of certificates
    assert both.controller.rate_dependent and not x_const.controller.rate_dependent
    with pytest.raises(InputError, match="rho_dot"):
        both.controller.at([0.0])
    Ak0 = both.controller.at([0.0], [0.0])[0]
    Ak1 = both.controller.at([0.0], [0.5])[0]
    assert not np.allclose(Ak0, Ak1)
    assert both.verification["frozen_passed"]


# ---------------------------------------------------------------------- refusals
def scalar(a=-1.0):
    return control.ss([[a]], [[1.0, 1.0]], [[1.0], [0.0]], [[0.0, 0.0], [0.0, 1.0]])


def test_grid_without_the_design_points_is_refused():
    gp = oscillator_gp()
    with pytest.raises(InputError, match="design points"):
        lpvsyn(gp, 0, 1, grid=[[0.0, 0.5], [0.0, 1.0]], rate_bounds=gp.rate_bounds)
    with pytest.raises(InputError, match="strictly increasing"):
        lpvsyn(scalar(), 0, 1, grid=[1.0, 0.0], rate_bounds=0.0)


@pytest.mark.parametrize("basis, match", [
    (Basis.from_functions([lambda r: 1.0, lambda r: abs(r[0])]), "kink"),
    (Basis.from_functions([lambda r: 1.0, lambda r: 1.0 / r[0]]), "finite"),
    (Basis.from_functions([lambda r: 1.0, lambda r: r[0] ** 2],
                          gradients=[lambda r: np.zeros(1), lambda r: np.array([r[0]])]), "gradient"),
    (Basis.from_functions([lambda r: 1.0, lambda r: 2.0]), "linearly independent"),
    ("quadratic", "expected a Basis"),
])
def test_bad_basis_is_refused(basis, match):
    with pytest.raises(InputError, match=match):
        lpvsyn(scalar(), 0, 1, grid=[-1.0, 0.0, 1.0], rate_bounds=1.0, basis=basis)


def test_inconsistent_plants_and_options_are_refused():
    A = np.zeros((3, 1, 1))
    with pytest.raises(InputError, match="shape"):
        lpvsyn((A, np.zeros((2, 1, 2)), np.zeros((3, 2, 1)), np.zeros((3, 2, 2))), 0, 1, grid=[0.0, 1.0, 2.0],
               rate_bounds=0.0)
    with pytest.raises(InputError, match="ncon"):
        lpvsyn(scalar(), 0, 2, grid=[0.0], rate_bounds=0.0)
    with pytest.raises(InputError, match="continuous-time"):
        lpvsyn(control.ss(0.5, [[1.0, 1.0]], [[1.0], [0.0]], [[0, 0], [0, 1.0]], 0.1), 0, 1, grid=[0.0],
               rate_bounds=0.0)
    with pytest.raises(InputError, match="D22"):
        lpvsyn(control.ss([[-1.0]], [[1.0, 1.0]], [[1.0], [1.0]], [[0.0, 0.0], [0.0, 1.0]]), 1, 1, grid=[0.0],
               rate_bounds=0.0)
    with pytest.raises(InputError, match="complex"):
        lpvsyn(lambda r: (np.array([[-1 + 1j]]), np.ones((1, 2)), np.ones((2, 1)), np.zeros((2, 2))), 0, 1,
               grid=[0.0], rate_bounds=0.0)
    with pytest.raises(InputError, match="unbounded"):
        lpvsyn(scalar(), 0, 1, grid=[-1.0, 0.0, 1.0], rate_bounds=np.inf, basis="affine")
    with pytest.raises(InputError, match="constant='Y'"):
        lpvsyn(scalar(), 0, 1, grid=[0.0], rate_bounds=0.0, constant="Y")
    with pytest.raises(InputError, match="interpolation"):
        lpvsyn(scalar(), 0, 1, grid=[0.0], rate_bounds=0.0, interpolation="spline")
    with pytest.raises(InputError, match="rate_bounds"):
        lpvsyn(scalar(), 0, 1, grid=[0.0], rate_bounds=None)


def test_not_stabilisable_grid_point_is_named_as_the_cause():
    # x' = rho x + w + b(rho) u with b = 0 at rho = 1: unstable there and no control authority
    def P(rho):
        r = float(rho[0])
        return np.array([[r]]), np.array([[1.0, 1.0 - r]]), np.array([[1.0], [0.0]]), np.array([[0.0, 0.0],
                                                                                                [0.0, 1.0]])
    with pytest.raises(InfeasibleController, match=r"'infeasible'.*rho = \[1.0\] is not stabilisable by u"):
        lpvsyn(P, 0, 1, grid=[-1.0, 0.0, 1.0], rate_bounds=0.0, basis="affine")


def test_gridded_arrays_are_interpolated_for_the_verification():
    gp = oscillator_gp()
    plant = GriddedLPV(axes=gp.axes, parameter_names=gp.parameter_names, rate_bounds=gp.rate_bounds, A=gp.A,
                       B=np.concatenate([gp.B1, gp.B2], -1), C=gp.C1, D=np.concatenate([gp.D11, gp.D12], -1),
                       state_names=["x", "v"], input_names=["w", "u"], output_names=["x", "u"])
    r = lpvsyn(plant, 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds, basis="affine", verify_refine=2)
    assert r.info["plant_interpolated"] and r.verification["grid"] == [5, 3]
    # the same design from the arrays (A, B, C, D)
    r2 = lpvsyn((plant.A, plant.B, plant.C, plant.D), 0, 1, grid=gp.axes, rate_bounds=gp.rate_bounds,
                basis="affine", verify_refine=2)
    assert r2.gamma_min == pytest.approx(r.gamma_min, rel=1e-6)


def test_a_design_that_fails_between_grid_points_is_refused():
    # seven points over a full turn: the certificate holds at the design points (with margin)
    # but not between them; the refusal names the verification, the report the worst point
    P = rotating_spring(output_feedback=False, **SADDLE)
    grid = np.linspace(-np.pi, np.pi, 7)
    with pytest.raises(InfeasibleController, match="verification failed"):
        lpvsyn(P, 0, 2, grid=grid, rate_bounds=0.5, basis=Basis.trigonometric(), backoff=0.05)
    r = lpvsyn(P, 0, 2, grid=grid, rate_bounds=0.5, basis=Basis.trigonometric(), backoff=0.05,
               require_verified=False)
    v = r.verification
    assert not v["passed"] and v["max_lmi_eig"] > 0
    rho_bad = v["max_lmi_eig_at"][0][0]
    assert np.min(np.abs(grid - rho_bad)) > 0.1                     # between design points


@pytest.mark.slow
def test_closed_loop_with_the_parameter_turning_at_its_rate_bound(trig_design):
    # time domain, independent of the LMIs: rho(t) = 0.5 t (the rate bound), a disturbance
    # burst w; the L2 gain of this one signal is a lower bound of the induced norm <= gamma,
    # and the state decays after the burst (stability under the fastest admissible turning)
    from scipy.integrate import solve_ivp
    P, ctrl = rotating_spring(**SADDLE), trig_design.controller
    nw = 4

    def w(t):
        return np.array([np.sin(1.3 * t), np.cos(0.7 * t), 0.3 * np.sin(5 * t), 0.0]) * (t < 15)

    def rhs(t, z):
        rho = np.array([0.5 * t - np.pi])
        A, B, C, D = P(rho)
        Ak, Bk, Ck, Dk = ctrl.at(rho)
        x, xk = z[:4], z[4:]
        y = C[4:] @ x + D[4:, :nw] @ w(t)
        u = Ck @ xk + Dk @ y
        return np.concatenate([A @ x + B[:, :nw] @ w(t) + B[:, nw:] @ u, Ak @ xk + Bk @ y])

    ts = np.linspace(0, 40, 801)
    sol = solve_ivp(rhs, (0, 40), np.zeros(8), t_eval=ts, rtol=1e-6, atol=1e-9)
    assert sol.success
    pe, we = 0.0, 0.0
    for k, t in enumerate(ts):
        rho = np.array([0.5 * t - np.pi])
        A, B, C, D = P(rho)
        Ak, Bk, Ck, Dk = ctrl.at(rho)
        x, xk = sol.y[:4, k], sol.y[4:, k]
        y = C[4:] @ x + D[4:, :nw] @ w(t)
        u = Ck @ xk + Dk @ y
        p = C[:4] @ x + D[:4, nw:] @ u
        pe += p @ p                      # rectangle rule on the same grid for both signals
        we += w(t) @ w(t)
    assert np.sqrt(pe / we) <= trig_design.gamma
    assert np.linalg.norm(sol.y[:, -1]) < 1e-2 * np.max(np.linalg.norm(sol.y, axis=0))


def wu_1996(rho):
    """The example of Wu, Yang, Packard & Becker (IJRNC 6 (1996) 983-998, Sec. 5) as coded with
    the conditions of Apkarian & Adams (1998) in github.com/boranzhao/LPV-demo (main.m): a plant
    turning with cos(rho), sin(rho), rho in [-pi, pi], first-order weights, cheap control
    (D12 = 1/280): badly scaled (its X, Y span five decades)."""
    c, s = np.cos(rho[0]), np.sin(rho[0])
    A = np.array([[0.75, 2, c, s, 0, 0], [0, 0.5, -s, c, 0, 0], [0, 0, -10, 0, 0, 0], [0, 0, 0, -10, 0, 0],
                  [0, 0, 0, 0, -0.2, 0], [0, 0, 0, 0, 0, -0.2]])
    B = np.zeros((6, 4))
    B[4, 0] = B[5, 1] = 4.0
    B[2, 2] = B[3, 3] = 10.0
    C1 = np.zeros((4, 6))
    C1[0, 0] = C1[1, 1] = 1.0
    C1[0, 4] = C1[1, 5] = -5.0
    D = np.zeros((6, 4))
    D[2, 2] = D[3, 3] = 1 / 280
    return A, B, np.vstack([C1, C1[:2]]), D


@pytest.mark.slow
def test_the_wu_1996_example_certifies_above_its_frozen_optimum():
    grid = np.arange(-5, 6) * np.pi / 5                                  # the grid of the demo
    r = lpvsyn(wu_1996, 2, 2, grid=grid, rate_bounds=1.0, basis=Basis.trigonometric(), backoff=0.05)
    assert r.verification["passed"]
    frozen = [frozen_lti_optimum(wu_1996, x, 2, 2) for x in grid[::3]]
    # the frozen plants differ by a rotation of the isotropic actuator states (x3, x4) and of u
    np.testing.assert_allclose(frozen, frozen[0], rtol=1e-5)
    assert frozen[0] < r.gamma_min < 2 * frozen[0]
