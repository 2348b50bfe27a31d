"""Gridded LPV state-feedback synthesis (eqs. 5.90-5.99) on small plants with known answers."""
import numpy as np
import pytest

from tmfem.control.lpv.plant import GriddedLPV
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.control.lpv.verify import verify
from tmfem.errors import InfeasibleController, InputError


def scalar_gp(a, rate=0.0):
    """x' = a(rho) x + w + u, p = [x; u] on a grid rho = 0, 1, ..."""
    a = np.asarray(a, dtype=float)
    s = (a.size,)
    return GeneralizedLPV.from_matrices(
        axes=[np.arange(a.size, dtype=float)], parameter_names=["r"], rate_bounds=[[-rate, rate]],
        A=a.reshape(s + (1, 1)), B1=np.ones(s + (1, 1)), B2=np.ones(s + (1, 1)),
        C1=np.broadcast_to([[1.0], [0.0]], s + (2, 1)), D11=np.zeros(s + (2, 1)),
        D12=np.broadcast_to([[0.0], [1.0]], s + (2, 1)))


def gamma_scalar(a):
    """Closed form for x' = a x + w + u, p = [x; u], a < 0: static state feedback is optimal,
    |T(jw)| = sqrt(1 + k^2) / |jw - (a + k)| peaks at w = 0; minimising over k gives k = 1/a."""
    k = 1.0 / a
    return np.sqrt(1 + k ** 2) / abs(a + k)


@pytest.mark.parametrize("solver", ["CLARABEL", "SCS"])
def test_scalar_plant_closed_form(solver):
    r = synthesize_state_feedback(scalar_gp([-1.0]), solver=solver)
    assert r.gamma == pytest.approx(gamma_scalar(-1.0), rel=1e-4)        # 1/sqrt(2)
    assert r.gain([0.0])[0, 0] == pytest.approx(1 / -1.0, rel=1e-2)


def test_two_point_grid_zero_rate_is_the_worst_point():
    # with two grid points the affine P(rho), Q(rho) of eq. 5.99 take any values at both, so
    # the gridded optimum is the larger of the two pointwise optima
    r = synthesize_state_feedback(scalar_gp([-1.0, -2.0]))
    assert r.gamma == pytest.approx(max(gamma_scalar(-1.0), gamma_scalar(-2.0)), rel=1e-4)


def test_rate_bound_cannot_lower_gamma():
    g0 = synthesize_state_feedback(scalar_gp([-1.0, -0.2, 0.5])).gamma
    g1 = synthesize_state_feedback(scalar_gp([-1.0, -0.2, 0.5], rate=5.0)).gamma
    assert g1 >= g0 * (1 - 1e-5)


def lti_plant():
    A = np.array([[0.0, 1.0, 0.0], [-2.0, -0.1, 1.0], [0.0, 0.0, 0.5]])
    B1 = np.array([[1.0, 0.0], [0.0, 0.3], [0.2, 0.0]])
    B2 = np.array([[0.0], [1.0], [1.0]])
    C1 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    D12 = np.array([[0.0], [0.5]])
    return A, B1, B2, C1, D12


def riccati_gamma(A, B1, B2, C1, D12, lo=1e-2, hi=1e2, tol=1e-6):
    """Independent LTI state-feedback H-inf optimum (C1^T D12 = 0): gamma is achievable iff
    the Hamiltonian [[A, B1 B1^T / g^2 - B2 R^-1 B2^T], [-C1^T C1, -A^T]] (R = D12^T D12) has
    no imaginary-axis eigenvalue and its stable subspace gives X = X2 X1^-1 >= 0; bisection."""
    import scipy.linalg as sla
    n = A.shape[0]
    R = D12.T @ D12

    def ok(g):
        H = np.block([[A, B1 @ B1.T / g ** 2 - B2 @ np.linalg.solve(R, B2.T)], [-C1.T @ C1, -A.T]])
        if np.min(np.abs(np.linalg.eigvals(H).real)) < 1e-9:
            return False
        T, Z, sdim = sla.schur(H, sort="lhp")
        X = Z[n:, :n] @ np.linalg.inv(Z[:n, :n])
        return sdim == n and np.linalg.eigvalsh((X + X.T) / 2).min() > -1e-9
    while hi - lo > tol * hi:
        mid = np.sqrt(lo * hi)
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return hi


def test_single_point_zero_rate_is_the_lti_state_feedback_problem():
    """On one grid point with zero rate bounds eqs. 5.95-5.96 are the LTI state-feedback
    bounded-real LMI: its gamma equals the Riccati/Hamiltonian bisection optimum (independent)
    and the closed-loop H-inf norm of K = Q P^-1 (python-control / SLICOT ab13dd)."""
    import control
    A, B1, B2, C1, D12 = lti_plant()
    nw = 2
    gp = GeneralizedLPV.from_matrices(axes=[[0.0]], parameter_names=["r"], rate_bounds=[[0, 0]],
                                      A=A[None], B1=B1[None], B2=B2[None], C1=C1[None],
                                      D11=np.zeros((1, 2, nw)), D12=D12[None])
    r = synthesize_state_feedback(gp, margin=1e-9)
    assert r.gamma == pytest.approx(riccati_gamma(A, B1, B2, C1, D12), rel=1e-4)
    K = r.gain([0.0])
    cl = control.ss(A + B2 @ K, B1, C1 + D12 @ K, np.zeros((2, nw)))
    assert control.norm(cl, p="inf") <= r.gamma * (1 + 1e-6)
    assert control.norm(cl, p="inf") >= r.gamma * (1 - 1e-3)


def oscillator_plant(shift=0.0):
    """x'' + 0.1 x' + (1 + rho) x = u + w, rho in [0, 2]: A affine in rho, so the multilinear
    interpolation between grid points is exact and the finer grid is the true plant."""
    rho = np.array([0.0, 1.0, 2.0])
    A = np.array([[[shift, 1.0], [-(1 + r), -0.1 + shift]] for r in rho])
    B = np.broadcast_to([[0.0], [1.0]], (3, 2, 1))
    C = np.broadcast_to(np.eye(2)[:1], (3, 1, 2))
    return GriddedLPV(axes=[rho], parameter_names=["rho"], A=A, B=B, C=C, D=np.zeros((3, 1, 1)),
                      rate_bounds=[[-0.5, 0.5]], state_names=["x", "v"], input_names=["u"],
                      output_names=["x"])


def gp_of(plant):
    s = plant.grid_shape
    return GeneralizedLPV.from_matrices(
        axes=plant.axes, parameter_names=plant.parameter_names, rate_bounds=plant.rate_bounds,
        A=plant.A, B1=plant.B, B2=plant.B, C1=np.concatenate([plant.C, np.zeros(s + (1, 2))], -2),
        D11=np.zeros(s + (2, 1)), D12=np.broadcast_to([[0.0], [0.3]], s + (2, 1)))


def test_interpolation_is_exact_for_affine_plant_and_refuses_outside():
    pl = oscillator_plant()
    A, *_ = pl.at([0.7])
    np.testing.assert_allclose(A, [[0, 1], [-1.7, -0.1]], atol=1e-14)
    assert [a.size for a in pl.refined(4)] == [9]
    with pytest.raises(InputError, match="outside the grid"):
        pl.at([2.5])


def _polynomial_plant(interpolation):
    """A 1x1 plant on a 5 x 3 grid with a(r, s) = r^3 - 2 r s^2 + s + 1, cubic in r and
    quadratic in s: what the tensor splines of degree min(3, n - 1) reproduce exactly."""
    r, s = np.linspace(0.0, 2.0, 5), np.array([0.0, 0.5, 1.5])
    a = lambda x, y: x**3 - 2 * x * y**2 + y + 1.0          # noqa: E731
    A = np.array([[[[a(x, y)]] for y in s] for x in r])
    one = np.ones((5, 3, 1, 1))
    return a, GriddedLPV(axes=[r, s], parameter_names=["r", "s"], A=A, B=one, C=one, D=0 * one,
                         rate_bounds=[[-1, 1], [-1, 1]], state_names=["x"], input_names=["u"],
                         output_names=["y"], interpolation=interpolation)


def test_spline_interpolation_is_exact_for_a_cubic_quadratic_field():
    """GriddedLPV(interpolation="spline") reproduces a field cubic along the 5-point axis and
    quadratic along the 3-point one between grid points (closed form), and both methods the
    grid values; the multilinear interpolation misses the off-grid value; an unknown method
    is refused."""
    a, spline = _polynomial_plant("spline")
    _, linear = _polynomial_plant("multilinear")
    for rho in ([0.5, 0.5], [1.0, 1.5], [0.0, 0.0]):
        assert spline.at(rho)[0][0, 0] == pytest.approx(a(*rho), abs=1e-12)
        assert linear.at(rho)[0][0, 0] == pytest.approx(a(*rho), abs=1e-12)
    for rho in ([0.3, 0.2], [1.7, 1.1], [1.25, 0.9]):
        assert spline.at(rho)[0][0, 0] == pytest.approx(a(*rho), abs=1e-12)
        assert abs(linear.at(rho)[0][0, 0] - a(*rho)) > 1e-3
    with pytest.raises(InputError, match="interpolation expected one of"):
        _polynomial_plant("cubic")



@pytest.mark.parametrize("interpolation", ["multilinear", "spline"])
def test_names_interpolated_together_are_those_interpolated_one_at_a_time(interpolation):
    """interpolate(("A", "B", "C", "D"), rho): one interpolant of the stacked values gives
    each matrix bitwise as its own interpolant does (source: one name at a time, a fresh plant
    for each name, so that nothing it built for another name is reused)."""
    _, pl = _polynomial_plant(interpolation)
    rng = np.random.default_rng(3)
    pl.A = pl.A + rng.standard_normal(pl.A.shape)              # four different fields
    pl.B, pl.C, pl.D = (M + rng.standard_normal(M.shape) for M in (pl.B, pl.C, pl.D))
    for rho in ([0.3, 0.2], [1.7, 1.1], [2.0, 1.5], [0.0, 0.5]):
        together = pl.interpolate(("A", "B", "C", "D"), rho)
        for nm, value in zip("ABCD", together):
            _, one = _polynomial_plant(interpolation)
            setattr(one, nm, getattr(pl, nm))
            np.testing.assert_array_equal(value, one.interpolate(nm, rho))

def test_off_grid_verification_passes_and_refuses_a_wrong_plant():
    pl = oscillator_plant()
    ctrl = synthesize_state_feedback(gp_of(pl))
    fine = gp_of(pl.resampled(pl.refined(4)))
    v = verify(ctrl, fine)
    assert v.passed and v.grid == (9,) and v.max_lmi_eig < 0 and v.max_cl_real < 0
    # the same controller on a plant with every eigenvalue shifted by +3/s is refused
    bad = gp_of(oscillator_plant(shift=3.0).resampled(pl.refined(4)))
    with pytest.raises(InfeasibleController, match="fails its verification"):
        verify(ctrl, bad)
    assert not verify(ctrl, bad, allow_failure=True).passed


def test_eigenvalue_optimization_finds_a_feasible_point_above_the_optimum_only():
    # the conic optimum (Clarabel) of the oscillator; EIGOPT at a fixed level above it returns a
    # controller whose re-computed LMIs are negative and that passes the off-grid check, below
    # it none (a feasibility method cannot beat the optimum)
    pl = oscillator_plant()
    g_opt = synthesize_state_feedback(gp_of(pl)).gamma
    r = synthesize_state_feedback(gp_of(pl), solver="EIGOPT", gamma=1.3 * g_opt)
    assert r.solver == "EIGOPT" and r.gamma == 1.3 * g_opt and r.max_lmi_eig < 0 and r.min_P_eig > 0
    assert verify(r, gp_of(pl.resampled(pl.refined(4)))).passed
    with pytest.raises(InfeasibleController):
        synthesize_state_feedback(gp_of(pl), solver="EIGOPT", gamma=0.97 * g_opt)
    with pytest.raises(InputError, match="fixed level"):
        synthesize_state_feedback(gp_of(pl), solver="EIGOPT")


def test_threaded_eigendecompositions_give_the_serial_optimization():
    # source: the same optimisation without threads (workers=1), both at one BLAS thread: the
    # threads decompose disjoint parts of the stack, so every evaluation is bit for bit the same
    from threadpoolctl import threadpool_limits
    from tmfem.control.lpv.eigopt import EigOpt
    from tmfem.control.lpv.coordinates import Coordinates
    pl = oscillator_plant()
    gp = gp_of(pl.resampled(pl.refined(2)))              # 5 grid points x 2 rate vertices
    co = Coordinates.of(gp)
    g = 1.3 * synthesize_state_feedback(gp_of(pl)).gamma
    runs = []
    for workers in (1, 2, 3):
        e = EigOpt(gp, T=co.T, c_of=co.c_of, dvs=co.dvs, gamma=g, workers=workers)
        with threadpool_limits(limits=1, user_api="blas"):
            z, top, reason = e.solve(g, e.riccati_start(g), t_schedule=(1e-3,), max_iter=20)
        runs.append((z, top, reason, e.evaluations))
        assert e._pool is None                            # the threads end with the solve
    for z, top, reason, n in runs[1:]:
        assert np.array_equal(z, runs[0][0]) and (top, reason, n) == runs[0][1:]
    assert runs[0][3] > 1
    with pytest.raises(InputError, match="workers a positive integer"):
        EigOpt(gp, T=co.T, c_of=co.c_of, dvs=co.dvs, gamma=g, workers=0)


def test_gamma_bisection_reaches_the_conic_optimum():
    # the oscillator of docs/guides/lpv.md: Clarabel's optimum is the reference. The bisection between
    # the pointwise lower bound and 2 x it (continuation in gamma) stops when hi - lo <= 1e-3 hi:
    # its gamma is feasible (>= the optimum) and within 1e-3 (+ the 5e-4 by which the proven bound
    # lies below the optimum) of it, and passes the 4x finer check
    from tmfem.control.lpv.bisect import bisect_gamma
    from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
    pl = oscillator_plant()
    gp = gp_of(pl)
    g_opt = synthesize_state_feedback(gp).gamma
    lb = pointwise_state_feedback_bound(gp).lower_bound
    assert lb <= g_opt * (1 + 1e-5)
    ctrl, br = bisect_gamma(gp, lower=lb, upper=2 * lb, rtol=1e-3)
    assert br.converged and br.stopped == "tolerance"
    assert g_opt * (1 - 1e-5) <= ctrl.gamma <= g_opt * (1 + 1.5e-3)
    assert verify(ctrl, gp_of(pl.resampled(pl.refined(4)))).passed
    # the bracket as reported: every feasible level at or above the returned one, every level not
    # found below it (a level not found is not a proof: the proven bound is lb)
    assert br.feasible == ctrl.gamma and br.lower_bound == lb
    assert min(lv["gamma"] for lv in br.levels if lv["result"] == "feasible") == ctrl.gamma
    assert all(lv["gamma"] < ctrl.gamma for lv in br.levels if lv["result"] == "not found")
    assert [lv["start"] for lv in br.levels][:2] == ["riccati", "continuation"]
    assert "does not prove" in br.to_dict()["gamma_note"]
    # a given start (continuation from an earlier design): that design is feasible at 1.01 x its
    # gamma, so the first level needs no iteration (the coordinates are carried over exactly)
    _, br2 = bisect_gamma(gp, lower=lb, upper=1.01 * ctrl.gamma, rtol=1e-2, start=ctrl)
    assert br2.levels[0]["start"] == "given design" and br2.levels[0]["result"] == "feasible"
    assert br2.levels[0]["evaluations"] == 0


def test_gamma_bisection_refusals():
    from tmfem.control.lpv.bisect import bisect_gamma
    gp = gp_of(oscillator_plant())
    with pytest.raises(InputError, match="lower < upper"):
        bisect_gamma(gp, lower=1.0, upper=0.5)
    with pytest.raises(InputError, match="rtol"):
        bisect_gamma(gp, lower=0.1, upper=1.0, rtol=0.0)
    # an upper level below the optimum (0.3): no feasible point to bisect from
    with pytest.raises(InfeasibleController):
        bisect_gamma(gp, lower=0.1, upper=0.25)
    # no time for the first level
    with pytest.raises(InfeasibleController, match="time budget"):
        bisect_gamma(gp, lower=0.1, upper=1.0, time_budget=1e-9)


def sampled_radius(ctrl, plant, dt):
    """Largest spectral radius of the zero-order-hold loop A_d + B_d K(rho) over the grid of
    ``plant`` (python-control sample_system for the discretisation)."""
    import control
    out = 0.0
    for idx, rho in plant.points():
        sd = control.sample_system(control.ss(plant.A[idx], plant.B[idx], np.eye(2), 0), dt, method="zoh")
        out = max(out, np.abs(np.linalg.eigvals(sd.A + sd.B @ ctrl.gain(rho))).max())
    return out


def test_sampled_loop_constraint_makes_the_controller_stable_when_sampled():
    # the H-infinity state feedback does not bound the gain: the oscillator's Clarabel optimum
    # (gains ~1e5) and EIGOPT's point at 1.3 x it are unstable when sampled with a zero-order
    # hold at dt = 0.2 s; with the discrete Lyapunov LMI at that step (sample_time) every frozen
    # sampled loop of the 4x finer grid is stable, the continuous LMIs still hold there
    pl = oscillator_plant()
    fine = pl.resampled(pl.refined(4))
    g_opt = synthesize_state_feedback(gp_of(pl)).gamma
    free = synthesize_state_feedback(gp_of(pl), solver="EIGOPT", gamma=1.3 * g_opt)
    assert sampled_radius(free, fine, 0.2) > 1
    r = synthesize_state_feedback(gp_of(pl), solver="EIGOPT", gamma=1.3 * g_opt, sample_time=0.2)
    assert sampled_radius(r, fine, 0.2) < 1
    v = verify(r, gp_of(fine), sample_time=0.2)
    assert v.passed and v.max_sampled_radius == pytest.approx(sampled_radius(r, fine, 0.2), rel=1e-9)
    with pytest.raises(InputError, match="EIGOPT only"):
        synthesize_state_feedback(gp_of(pl), sample_time=0.2)
