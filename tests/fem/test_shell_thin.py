"""Thin shells: Jacobi-equilibrated Newton solves (docs/guides/shells.md, "Thin shells").

Sources: closed forms of diagonal systems (the equilibrated solve is the same solution; a
pivot-ratio singularity test of the unscaled matrix is a false alarm), the membrane of
dissertation 4.5.4 at its 51 um thickness (h/a = 2.55e-5): condition numbers of the reduced
tangent (numpy 2-norm) and the Newton residual relative to the load Fw = 0.1 N.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from tmfem.reference.benchmarks.shell_square_membrane import shell_square_membrane
from tmfem.solvers.backends import SingularMatrix, get_backend
from tmfem.solvers.newton import factorize, jacobi_scaling, newton


def test_equilibrated_solve_is_the_same_solution_and_no_false_singularity():
    # a well-posed SPD system whose dofs differ in stiffness by 1e15 (rotations of a 1 um
    # shell against its translations): unscaled, the pivot ratio 1e-15 reads as singular
    rng = np.random.default_rng(0)
    Q = np.linalg.qr(rng.standard_normal((6, 6)))[0]
    B = Q @ np.diag([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]) @ Q.T          # cond 6
    s = np.array([1.0, 1.0, 1.0, 1e-8, 1e-8, 1e-8])
    A = B * np.outer(s, s)                                          # A = S B S
    x = rng.standard_normal(6) / s                                  # soft dofs move more
    b = A @ x
    with pytest.raises(SingularMatrix):
        factorize(A, get_backend())
    for M in (A, sp.csr_matrix(A)):
        got = factorize(M, get_backend(), equilibrate=True)(b)
        np.testing.assert_allclose(got, x, rtol=1e-12)
    d = jacobi_scaling(A)
    np.testing.assert_allclose(np.diag(A * np.outer(d, d)), 1.0)
    X = np.stack([x, 2 * x], axis=1)                                 # several right-hand sides
    np.testing.assert_allclose(factorize(A, get_backend(), equilibrate=True)(A @ X), X, rtol=1e-12)


def test_thin_prestressed_membrane_reaches_full_newton_convergence():
    s, st, stage1, path, _ = shell_square_membrane(n=5, steps=1, thickness=51e-6)
    free = np.flatnonzero(s.constraints.free)
    _, Kp = s.residual(stage1.state, 0.0)
    A = Kp[free][:, free].toarray()
    d = jacobi_scaling(A)
    c, cs = np.linalg.cond(A), np.linalg.cond(A * np.outer(d, d))
    assert c > 1e10                         # measured 1.7e10 (docs/guides/shells.md)
    assert cs < 1e-2 * c                    # measured 3.3e7
    # stage 2 (Fw = 0.1 N at B) in one step, Newton to 3e-10 of the load, Jacobi-scaled solves
    res = newton(lambda t: s.residual(t, 1.0), stage1.state, free=s.constraints.free, tol=3e-10,
                 scale=0.1, line_search=False, update=s.advance, equilibrate=True)
    assert res.converged and not res.floor_limited
    assert res.residual_history[-1] <= 3e-10 * 0.1
    assert res.iterations <= 10
    # the same equilibrium as the default solve (tol 1e-8)
    np.testing.assert_allclose(res.u.x, st.state.x, atol=1e-9)
