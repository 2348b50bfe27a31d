"""The Riccati test of the eliminated H-infinity LMIs (tmfem.control.linear.hinf_riccati):
stabilising solutions only, two independent Riccati solvers, three-valued verdicts,
monotone in gamma, and a bisection that moves only on verified evidence.

Sources: scipy's ``solve_continuous_are`` (the failure it reports is reproduced here), the
closed form of ``family.first_order`` (Zhou, Doyle & Glover 1996, Thm. 16.4), the printed
optimum of Skogestad & Postlethwaite Example 2.17 (2.21), python-control's closed-loop norm.
"""
import control
import numpy as np
import pytest
import scipy.linalg as sla

from tests.control.linear.family import family, first_order, skogestad_postlethwaite_2_17
from tmfem.control.linear.hinf_central import verified_gamma
from tmfem.control.linear.hinf_riccati import bisect_verified, riccati_test, Verdict
from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tmfem.errors import InfeasibleController


def _gp(P, ny, nu):
    return GeneralizedPlant.from_system(P, nmeas=ny, ncon=nu).scaled()[0]


def test_a_repeated_weight_pole_does_not_read_as_infeasible():
    # S&P 2.17 design 2: the weight (s/sqrt(M) + w_B)^2 / (s + w_B sqrt(A))^2 gives A a
    # triple eigenvalue at -0.1 that y does not see; scipy's solver rejects the dual Riccati
    # equation ("eigenvalues too close to the imaginary axis") at every gamma, SLICOT SG02AD
    # solves it, and the level is feasible above the printed optimum 2.21
    G = _gp(*skogestad_postlethwaite_2_17(2)[:3])
    g = 3.0
    A, B1, C2, D21 = G.A.T, G.C1.T, G.B1.T, G.D11.T
    B = np.hstack([B1, G.C2.T])
    D = np.hstack([D21, G.D21.T])
    Rm = D.T @ D
    Rm[:B1.shape[1], :B1.shape[1]] -= g ** 2 * np.eye(B1.shape[1])
    with pytest.raises(np.linalg.LinAlgError, match="imaginary axis"):
        sla.solve_continuous_are(A, B, C2.T @ C2, Rm, s=C2.T @ D)
    assert riccati_test(G, 0.0, g).status == "feasible"


@pytest.mark.parametrize("name", ["regular-6", "d11-5", "badly-scaled-6", "near-integrator-5",
                                  "unstable-6", "skogestad-2.17-design1", "skogestad-2.17-design2"])
def test_verdicts_are_monotone_in_gamma(name):
    # infeasibility certificates only below every feasible level (no false "infeasible"
    # above a feasible gamma, no "feasible" below a certified infeasible one)
    P, ny, nu, _ = family()[name]
    G = _gp(P, ny, nu)
    it = verified_gamma(G, rtol=1e-4)
    grid = it.gamma * np.logspace(-0.5, 1.0, 40)
    st = [riccati_test(G, 0.0, g).status for g in grid]
    feas = [i for i, s in enumerate(st) if s == "feasible"]
    infeas = [i for i, s in enumerate(st) if s == "infeasible"]
    assert feas and max(infeas, default=-1) < min(feas)
    assert all(s == "feasible" for s in st[min(feas):])
    assert all(grid[i] <= it.gamma for i in infeas)


def test_verified_bisection_brackets_the_closed_form():
    for a in (-1.0, 0.0, 1.0):
        P, ny, nu, g_opt = first_order(a)
        it = verified_gamma(_gp(P, ny, nu), rtol=1e-6)
        assert it.lower <= g_opt <= it.gamma <= g_opt * (1 + 2e-6)
        K, T, nrm = it.evidence                       # the controller at the upper end
        assert nrm <= it.gamma * (1 + 1e-6)
        assert float(control.norm(T, p="inf")) == pytest.approx(nrm, rel=1e-9)


def test_bisection_does_not_move_down_on_unverified_levels():
    # a test that says "feasible" everywhere but a certifier that accepts only gamma >= 2:
    # the reported level is >= 2 (never below the evidence), and the levels in between are
    # recorded as unknown, not certified infeasible
    it = bisect_verified(lambda g: Verdict("feasible"), lambda g: (g >= 2.0, g, "" if g >= 2.0 else "no"),
                         lower=0.0, rtol=1e-3, gamma_max=1e3, what="synthetic")
    assert 2.0 <= it.gamma <= 2.0 * (1 + 2e-3)
    assert it.lower == 0.0 and it.unknown and all(g < 2.0 for g, _ in it.unknown)
    with pytest.raises(InfeasibleController, match="synthetic"):
        bisect_verified(lambda g: Verdict("unknown", "numerical"), lambda g: (True, None, ""),
                        lower=0.0, rtol=1e-3, gamma_max=10.0, what="synthetic")


def _care_problem(seed, n=12, m=3):
    """A stabilisable, detectable random CARE with Rm > 0 and a cross term S."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n)) - 2.0 * np.eye(n)
    B = rng.standard_normal((n, m))
    C = rng.standard_normal((n, n)) / np.sqrt(n)
    Rm = np.eye(m) + 0.1 * np.diag(rng.random(m))
    S = 0.1 * rng.standard_normal((n, m))
    return A, B, C.T @ C + np.eye(n), Rm, S


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_hamiltonian_schur_solution_is_scipys(seed):
    # Laub's method against scipy's pencil QZ on well-conditioned problems: the same X, and
    # it satisfies the Riccati equation
    from tmfem.control.linear.hinf_riccati import hamiltonian_schur_care
    A, B, Q, Rm, S = _care_problem(seed)
    X = hamiltonian_schur_care(A, B, Q, Rm, S)
    ref = sla.solve_continuous_are(A, B, Q, Rm, s=S)
    np.testing.assert_allclose(X, ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())
    G = X @ B + S
    residual = A.T @ X + X @ A + Q - G @ np.linalg.solve(Rm, G.T)
    assert np.abs(residual).max() < 1e-9 * np.abs(Q).max()


def test_the_hamiltonian_schur_solver_takes_over_when_the_pencil_solvers_fail(monkeypatch):
    # on a lightly damped two-stage plant of 90 states scipy's QZ reordering failed ("too far
    # from generalized Schur form") for the dual equation at every level and SG02AD with it;
    # the bisection then stayed at 22 times the optimum. With both pencil solvers failing the
    # stabilising solution still comes back, from the Hamiltonian matrix
    import tmfem.control.linear.hinf_riccati as hr

    def fail(*args, **kwargs):
        raise ValueError("Reordering of (A, B) failed")
    monkeypatch.setattr(hr.sla, "solve_continuous_are", fail)
    monkeypatch.setattr(control, "care", fail)
    A, B, Q, Rm, S = _care_problem(3)
    X, why = hr._stabilizing_care(A, B, Q, Rm, S)
    assert why is None
    F = np.linalg.solve(Rm, B.T @ X + S.T)
    assert np.linalg.eigvals(A - B @ F).real.max() < 0
    with pytest.raises(np.linalg.LinAlgError, match="Hamiltonian eigenvalues"):
        hr.hamiltonian_schur_care(np.zeros((2, 2)), np.zeros((2, 1)), np.zeros((2, 2)), np.eye(1),
                                  np.zeros((2, 1)))
