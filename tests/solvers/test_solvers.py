"""Newton, load stepping, arc length, eigen and backends (tmfem.solvers)."""
import numpy as np
import pytest
import scipy.sparse as sp

from tmfem.errors import BackendUnavailable, ConvergenceError, InputError
from tmfem.fem.truss import TrussSet, truss_internal
from tmfem.solvers import arc_length, get_backend, load_stepping, lowest_modes
from tmfem.solvers.newton import newton


def bar_problem(P, EA=1e4, L=1.0):
    """One bar along x from a fixed node; the free end carries P along x."""
    ts = TrussSet(conn=[[0], [1]], L=[L], EA=[EA], rhoA=[1.0], tension_only=[False])
    X = np.array([[0.0, L], [0.0, 0.0], [0.0, 0.0]])

    def residual(u, lam=1.0):
        r = truss_internal(X + u.reshape(-1, 3).T, ts)
        f_ext = np.zeros(6)
        f_ext[3] = lam * P
        return r.f - f_ext, r.K
    return residual


def test_newton_single_bar_closed_form_and_quadratic_rate():
    # source: closed form -- EA (l^2 - L^2) l / (2 L^3) = P is a cubic in l (np.roots)
    EA, L, P = 1e4, 1.0, 800.0
    res = newton(bar_problem(P, EA, L), np.zeros(6), free=[3], tol=1e-12)
    roots = np.roots([EA / (2 * L**3), 0.0, -EA / (2 * L), -P])
    l = roots[np.isreal(roots) & (roots.real > 0)].real.max()
    assert res.converged
    assert res.u[3] == pytest.approx(l - L, rel=1e-12)
    h = np.array(res.residual_history)
    # quadratic convergence in the last steps: r_{k+1} <= C r_k^2 with a modest C
    ratios = h[2:] / h[1:-1] ** 2
    assert np.all(ratios[:-1] < 1.0) and len(h) <= 8


def test_load_stepping_matches_newton_and_reports_failure():
    EA, P = 1e4, 800.0
    direct = newton(bar_problem(P, EA), np.zeros(6), free=[3], tol=1e-12)
    path = load_stepping(bar_problem(P, EA), np.zeros(6), free=[3], dlam0=0.25, tol=1e-12)
    assert path.lam[-1] == 1.0 and len(path.lam) >= 3
    assert path.u[-1][3] == pytest.approx(direct.u[3], rel=1e-10)

    # r = arctan(u) - 2 lam has no root for lam > pi/4: the stepping must stop there, saying so
    def residual_lam(u, lam):
        with np.errstate(over="ignore"):
            return np.arctan(u) - 2.0 * lam, sp.csr_matrix(np.diag(1.0 / (1.0 + u**2)))
    with pytest.raises(ConvergenceError) as info:
        load_stepping(residual_lam, np.zeros(1), dlam0=0.1, dlam_min=1e-3, max_iter=30)
    err = info.value
    assert np.pi / 4 - 0.01 < err.load_factor < np.pi / 4 + 0.01
    assert err.step is not None and len(err.residual_history) > 0
    assert "load factor" in str(err)


def test_newton_singular_tangent_raises_with_history():
    # a cable with zero stress has no transverse stiffness: singular tangent, not NaN
    ts = TrussSet(conn=[[0], [1]], L=[1.0], EA=[1.0], rhoA=[1.0], tension_only=[True])
    X = np.array([[0.0, 1.0], [0.0, 0.0], [0.0, 0.0]])

    def residual(u):
        r = truss_internal(X + u.reshape(-1, 3).T, ts)
        return r.f - np.array([0, 0, 0, 0, 1.0, 0]), r.K
    with pytest.raises(ConvergenceError, match="singular") as info:
        newton(residual, np.zeros(6), free=[3, 4])
    assert info.value.residual_history == [1.0]


def von_mises_arch(a, b, EA):
    X = np.array([[-a, a, 0.0], [0.0, 0.0, b], [0.0, 0.0, 0.0]])
    L0 = np.hypot(a, b)
    ts = TrussSet(conn=[[0, 1], [2, 2]], L=[L0, L0], EA=[EA, EA], rhoA=[1.0, 1.0],
                  tension_only=[False, False])

    def internal(u):
        r = truss_internal(X + u.reshape(-1, 3).T, ts)
        return r.f, r.K
    f_ext = np.zeros(9)
    f_ext[7] = -1.0          # downward unit load on the apex
    return internal, f_ext, L0


def test_arc_length_passes_the_limit_point_of_the_two_bar_arch():
    # source: closed-form total-Lagrangian curve, benchmarks.json von_mises_truss_formulas
    # 'green_SVK_TL': P = (EA/L0^3)(b - v)(2 b v - v^2); limit P* = 2 EA b^3 / (3 sqrt(3) L0^3)
    a, b, EA = 2.5, 0.025, 5e7               # von_mises_truss_numbers case 2 (SI units)
    internal, f_ext, L0 = von_mises_arch(a, b, EA)
    path = arc_length(internal, f_ext, np.zeros(9), free=[6, 7], dl=b / 40, dl_max=b / 40,
                      n_steps=400, stop=lambda u, lam: -u[7] > 2.2 * b)
    v = -path.u[:, 7]
    P = path.lam
    P_green = EA / L0**3 * (b - v) * (2 * b * v - v**2)
    np.testing.assert_allclose(P, P_green, atol=1e-8 * 19.24)
    assert v.max() > 2 * b                       # through the limit point, snap-through, inversion
    assert np.any((v > b) & (P < -1.0))          # the descending (negative load) branch is traced
    P_star = 2 * EA * b**3 / (3 * np.sqrt(3) * L0**3)
    assert P_star == pytest.approx(19.24212, rel=1e-6)   # benchmarks.json von_mises_truss_numbers
    # sampled every b/40: the largest sampled load is within (b/80)^2 P''/2 of the limit load
    assert P[v < b].max() == pytest.approx(P_star, rel=5e-3)
    assert P[v < b].max() <= P_star * (1 + 1e-12)
    np.testing.assert_allclose(path.u[:, 6], 0.0, atol=1e-12)   # symmetric path


def test_eigen_ring_repeated_pairs_and_rigid_mode():
    # source: closed form -- a ring of N equal masses m joined by springs k (circulant) has
    # omega_j^2 = (4 k / m) sin^2(pi j / N), j = 0..N/2, doubly repeated for 0 < j < N/2.
    # N = 800 > 600 takes the ARPACK shift-invert path; K is singular (rigid rotation, j = 0).
    N, k, m = 800, 3.0, 2.0
    e = np.ones(N)
    K = sp.diags([2 * k * e, -k * e[:-1], -k * e[:-1]], [0, 1, -1], format="lil")
    K[0, N - 1] = K[N - 1, 0] = -k
    K = K.tocsr()
    M = sp.identity(N, format="csr") * m
    modes = lowest_modes(K, M, k=9)
    j = np.array([0, 1, 1, 2, 2, 3, 3, 4, 4])
    np.testing.assert_allclose(modes.omega2, 4 * k / m * np.sin(np.pi * j / N) ** 2, atol=1e-10, rtol=1e-9)
    V = modes.shapes
    np.testing.assert_allclose(V.T @ (M @ V), np.eye(9), atol=1e-9)
    np.testing.assert_allclose(K @ V - (M @ V) * modes.omega2, 0.0, atol=1e-8)
    # each pair spans both the cos and the sin wave of its harmonic
    n = np.arange(N)
    for jj, cols in ((1, [1, 2]), (4, [7, 8])):
        basis = np.stack([np.cos(2 * np.pi * jj * n / N), np.sin(2 * np.pi * jj * n / N)], axis=1)
        proj = np.linalg.lstsq(basis, V[:, cols], rcond=None)
        assert np.linalg.norm(basis @ proj[0] - V[:, cols]) < 1e-8


def test_eigen_dense_path_free_dofs_and_errors():
    # source: closed form -- fixed-fixed spring chain of n masses: omega_j^2 = (4k/m) sin^2(j pi / (2(n+1)))
    n, k, m = 30, 5.0, 0.5
    K = sp.diags([2 * k * np.ones(n + 2), -k * np.ones(n + 1), -k * np.ones(n + 1)], [0, 1, -1]).tocsr()
    M = sp.identity(n + 2, format="csr") * m
    free = np.zeros(n + 2, bool)
    free[1:-1] = True
    modes = lowest_modes(K, M, k=4, free=free)
    jj = np.arange(1, 5)
    np.testing.assert_allclose(modes.omega2, 4 * k / m * np.sin(jj * np.pi / (2 * (n + 1))) ** 2, rtol=1e-12)
    assert np.all(modes.shapes[[0, -1]] == 0.0)
    np.testing.assert_allclose(modes.freq_hz, np.sqrt(modes.omega2) / (2 * np.pi))
    with pytest.raises(InputError, match="1 <= k <= 30"):
        lowest_modes(K, M, k=31, free=free)


def test_backends():
    assert get_backend().name == "scipy" and get_backend("scipy").name == "scipy"
    with pytest.raises(InputError, match="expected one of"):
        get_backend("mumps")
    # 'petsc' (tmfem.solvers.petsc; tests/solvers/test_petsc_backend.py): available where petsc4py is
    # installed, else refused naming the install command (simulated there)
    try:
        import petsc4py  # noqa: F401
        import slepc4py  # noqa: F401
    except ImportError:
        with pytest.raises(BackendUnavailable, match="make install"):
            get_backend("petsc")
    else:
        assert get_backend("petsc").name == "petsc"


def test_nested_dissection_ordering_solves_and_reduces_fill():
    # source: independent formulation -- the reordered factorisation solves the same system as
    # SuperLU's default (COLAMD + partial pivoting), and nested dissection of an m x m grid has
    # less fill than the natural (banded) order, O(m^2 log m) vs O(m^3)
    import scipy.sparse.linalg as spla
    from tmfem.solvers.backends import ScipyBackend, nested_dissection
    m = 80
    T = sp.diags([2 * np.ones(m), -np.ones(m - 1), -np.ones(m - 1)], [0, 1, -1])
    A = (sp.kron(T, sp.identity(m)) + sp.kron(sp.identity(m), T)).tocsc()
    perm = nested_dissection(A)
    assert np.array_equal(np.sort(perm), np.arange(m * m))
    Ap = sp.csc_matrix(A[perm][:, perm])
    nd = spla.splu(Ap, permc_spec="NATURAL", options=dict(SymmetricMode=True), diag_pivot_thresh=0.0)
    nat = spla.splu(A, permc_spec="NATURAL", options=dict(SymmetricMode=True), diag_pivot_thresh=0.0)
    assert nd.L.nnz < 0.5 * nat.L.nnz
    be = ScipyBackend()
    assert A.shape[0] >= be.nd_threshold
    b = np.random.default_rng(0).normal(size=m * m)
    x = be.factorize(A)(b)
    np.testing.assert_allclose(x, spla.splu(A).solve(b), rtol=1e-10, atol=1e-12)
    x2 = be.factorize(2.0 * A)(b)              # cached ordering, new values
    np.testing.assert_allclose(x2, 0.5 * x, rtol=1e-10, atol=1e-12)


def test_newton_without_a_root_raises_instead_of_looping():
    # r(u) = u^2 + 1 has no real root: Newton must stop with a ConvergenceError that carries
    # its residual history (stalled, singular or max_iter), never return or hang
    def residual(u):
        return u**2 + 1.0, sp.csr_matrix(np.diag(2.0 * u))
    with pytest.raises(ConvergenceError) as info:
        newton(residual, np.array([0.7]), max_iter=40)
    h = info.value.residual_history
    assert len(h) > 1 and min(h) >= 1.0
    assert any(s in str(info.value) for s in ("stalled", "singular", "within 40 iterations"))
