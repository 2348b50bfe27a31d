"""Element benchmarks of dissertation 4.5.3-4.5.4 and closed-form vibration problems.

Each function builds a small problem from the truss/membrane kernels and the solvers and
returns plain arrays, so that ``demos/element_benchmarks.py`` prints and plots them and
``tests/fem/test_element_benchmarks.py`` compares them with their closed forms:

* :func:`two_bar_arch` -- the two-bar (von Mises) arch of 4.5.3 by arc length, with the
  closed-form total-Lagrangian (Green strain) and engineering-strain load curves;
* :func:`square_membrane` -- the square membrane under corner forces of 4.5.4;
* :func:`prestressed_square_membrane_modes` -- a square membrane under uniform isotropic
  prestress, f_mn = (1/2a) sqrt(N/(rho h)) sqrt(m^2 + n^2);
* :func:`taut_string_modes`, :func:`beaded_string_modes` -- prestressed truss chains.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.optimize import minimize_scalar

from tmfem.errors import InputError
from tmfem.fem.membrane import MembraneTL
from tmfem.fem.truss import TrussSet, truss_internal, truss_mass
from tmfem.mesh.polygon import polygon_quad_mesh
from tmfem.solvers import arc_length, load_stepping, lowest_modes
from tmfem.solvers.newton import submatrix
from tmfem.solvers.backends import get_backend
from tmfem.system.materials import MembraneMaterial

# --------------------------------------------------------------------------- 4.5.3 arch


def arch_load_green(v, *, a, b, EA):
    """Closed-form total-Lagrangian (Green strain, St.Venant-Kirchhoff) load of the two-bar arch:
    P = (EA / L0^3)(b - v)(2 b v - v^2), apex displacement v downward (benchmarks.json
    ``von_mises_truss_formulas``)."""
    L0 = np.hypot(a, b)
    v = np.asarray(v, dtype=float)
    return EA / L0**3 * (b - v) * (2 * b * v - v**2)


def arch_load_engineering(v, *, a, b, EA):
    """Closed-form load with engineering strain (L - L0)/L0 and rotated axial force:
    P = 2 EA z (L0 - L) / (L0 L), z = b - v, L = sqrt(a^2 + z^2)."""
    L0 = np.hypot(a, b)
    z = b - np.asarray(v, dtype=float)
    L = np.hypot(a, z)
    return 2 * EA * z * (L0 - L) / (L0 * L)


def arch_limit_loads(*, a, b, EA) -> dict:
    """Limit loads: Green closed form P* = 2 EA b^3 / (3 sqrt(3) L0^3) at v* = b (1 - 1/sqrt 3);
    engineering strain by bounded maximisation over 0 < v < b."""
    L0 = np.hypot(a, b)
    eng = minimize_scalar(lambda v: -arch_load_engineering(v, a=a, b=b, EA=EA), bounds=(0.0, b),
                          method="bounded", options=dict(xatol=1e-12 * b))
    return dict(P_green=2 * EA * b**3 / (3 * np.sqrt(3) * L0**3), v_green=b * (1 - 1 / np.sqrt(3)),
                P_eng=float(-eng.fun), v_eng=float(eng.x))


@dataclass
class ArchPath:
    """Arc-length path of the two-bar arch: apex displacement v (down), load P, the closed
    forms at the same v, the largest load on the path before v = b, and the closed-form
    limit loads."""

    v: np.ndarray
    P: np.ndarray
    P_green: np.ndarray
    P_eng: np.ndarray
    P_max_fe: float
    limits: dict
    steps: int


def two_bar_arch(*, a: float, b: float, EA: float, v_end: float | None = None,
                 n_per_b: int = 40) -> ArchPath:
    """Two-bar arch of 4.5.3 (supports at (-a, 0), (a, 0), apex (0, b)) under a downward apex
    load, traced through its limit point by the cylindrical arc-length method.

    Two truss elements (eqs. 4.23-4.24) with rest length L0 = sqrt(a^2 + b^2); the apex moves in
    the plane (x, y free), the path stops at v_end (default 2.2 b, past the inverted state).
    """
    if not (a > 0 and b > 0 and EA > 0):
        raise InputError(f"arch: expected a, b, EA > 0, found a={a}, b={b}, EA={EA}")
    X = np.array([[-a, a, 0.0], [0.0, 0.0, b], [0.0, 0.0, 0.0]])
    L0 = np.hypot(a, b)
    ts = TrussSet(conn=[[0, 1], [2, 2]], L=[L0, L0], EA=[EA, EA], rhoA=[0.0, 0.0],
                  tension_only=[False, False])
    limits = arch_limit_loads(a=a, b=b, EA=EA)
    P_ref = limits["P_green"]

    def internal(u):
        r = truss_internal(X + u.reshape(-1, 3).T, ts)
        return r.f / P_ref, r.K / P_ref            # load factor in units of P*
    f_ext = np.zeros(9)
    f_ext[7] = -1.0
    v_end = 2.2 * b if v_end is None else v_end
    dl = b / n_per_b
    path = arc_length(internal, f_ext, np.zeros(9), free=[6, 7], dl=dl, dl_max=dl,
                      n_steps=int(20 * n_per_b * v_end / b), stop=lambda u, lam: -u[7] > v_end)
    v = -path.u[:, 7]
    P = path.lam * P_ref
    return ArchPath(v=v, P=P, P_green=arch_load_green(v, a=a, b=b, EA=EA),
                    P_eng=arch_load_engineering(v, a=a, b=b, EA=EA),
                    P_max_fe=float(P[v < b].max()), limits=limits, steps=len(path.lam) - 1)


# --------------------------------------------------------------------------- 4.5.4 membrane


@dataclass
class SquareMembraneResult:
    """Square membrane of 4.5.4. ``u`` (3, nn) displacements; ``lines`` maps y -> (x, w);
    ``u_inplane`` is the state after the in-plane corner forces only (stage 1);
    ``w_linear`` (nn,) the deflection of the linearised prestressed membrane under Fw about
    that state; ``newton_iterations`` per load step of stage 2."""

    model: MembraneTL
    u: np.ndarray
    u_inplane: np.ndarray
    w_linear: np.ndarray
    lines: dict
    corner_forces: np.ndarray
    newton_iterations: list
    fixed: np.ndarray


def square_membrane(*, n: int = 10, a: float = 2.0, F: float = 2.749, Fw: float = 0.1,
                    material: MembraneMaterial | None = None, load: str = "diagonal",
                    lines=(0.4, 1.0, 1.6)) -> SquareMembraneResult:
    """Square membrane under corner forces (dissertation 4.5.4, Figure 4.9).

    Corners O (0, 0), A (a, 0), B (a, a), C (0, a). Boundary conditions as printed: O fixed,
    A free in x only, B free in x, y, z, C free in y only; every other node free. Loads:
    with ``load="diagonal"`` (our reading of Figure 4.9, the symmetric corner force F_Delta of
    eq. 3.21) a force F pulls each corner away from the centre, of which the supports take the
    constrained components, and Fw acts on B along +z; ``load="axes"`` puts F along x at A,
    along y at C and (F, F) at B (a symmetric load sqrt 2 times larger). ``n`` elements per side
    of each of the 4 quadrants (n = 10 is the 20 x 20 mesh of 4.5.4).

    Solved in two stages: the in-plane forces with the out-of-plane dofs held (a flat,
    unstressed membrane has no transverse stiffness), then Fw by adaptive load stepping.
    """
    if load not in ("diagonal", "axes"):
        raise InputError(f"square membrane: expected load 'diagonal' or 'axes', found {load!r}")
    material = material or MembraneMaterial(E=1.65e8, nu=0.34, rho=1400.0, h=51e-6)
    mesh = polygon_quad_mesh(np.array([[0, a, a, 0], [0, 0, a, a]], float), n)
    mem = MembraneTL(mesh=mesh, material=material)
    O, A, B, C = mesh.corners
    nn = mem.nn
    fixed = np.zeros((nn, 3), bool)
    fixed[O] = True
    fixed[A, [1, 2]] = True
    fixed[C, [0, 2]] = True
    f = np.zeros((nn, 3))
    s = F / np.sqrt(2) if load == "diagonal" else F
    f[A, 0] = s
    f[B, :2] = s
    f[C, 1] = s
    fz = np.zeros((nn, 3))
    fz[B, 2] = Fw
    X = mem.X

    def residual(u, lam, mu):
        fi, K = mem.internal(X + u.reshape(-1, 3).T)
        return fi - lam * f.ravel() - mu * fz.ravel(), K
    free1 = ~fixed
    free1[:, 2] = False
    st1 = load_stepping(lambda u, lam: residual(u, lam, 0.0), np.zeros(3 * nn), free=free1.ravel(),
                        scale=F, store=False)
    u1 = st1.u[-1]
    # linearised prestressed membrane: K_zz w = Fw e_B about the in-plane state
    _, K1 = mem.internal(X + u1.reshape(-1, 3).T)
    zfree = np.flatnonzero((~fixed[:, 2]))
    zdofs = 3 * zfree + 2
    solve = get_backend().factorize(submatrix(K1, zdofs))
    w_lin = np.zeros(nn)
    w_lin[zfree] = solve(fz.ravel()[zdofs])
    st2 = load_stepping(lambda u, mu: residual(u, 1.0, mu), u1, free=(~fixed).ravel(), dlam0=0.25,
                        scale=F, store=False)
    u = st2.u[-1].reshape(-1, 3).T
    out = {}
    for y in lines:
        sel = np.flatnonzero(np.isclose(mesh.p[1], y, atol=1e-9 * a))
        if sel.size == 0:
            raise InputError(f"square membrane: no mesh line at y = {y} for n = {n}")
        o = np.argsort(mesh.p[0, sel])
        out[float(y)] = (mesh.p[0, sel[o]], u[2, sel[o]])
    return SquareMembraneResult(model=mem, u=u, u_inplane=u1.reshape(-1, 3).T, w_linear=w_lin,
                                lines=out, corner_forces=f.T + fz.T, newton_iterations=st2.iterations,
                                fixed=fixed)


# --------------------------------------------------------------------------- vibrations


def prestressed_square_membrane_modes(*, n: int, a: float = 1.0, strain: float = 1e-3, k: int = 6,
                                      material: MembraneMaterial | None = None) -> dict:
    """Lowest modes of a square membrane with clamped edges under uniform isotropic prestress.

    The reference square (side a) is stretched uniformly by (1 + strain) and its edges are
    held there, a uniform equilibrium with 2nd Piola-Kirchhoff stress
    S0 = E_mod/(1 - nu) E, E = ((1+strain)^2 - 1)/2. Closed form (benchmarks.json
    ``rectangular_membrane_uniform_tension``, written in reference quantities, N = S0 h per
    unit reference length, rho h per unit reference area):
    f_mn = (1 / 2a) sqrt(N / (rho h)) sqrt(m^2 + n^2).
    Returns FE and closed-form frequencies (lowest k) and the number of dofs.
    """
    material = material or MembraneMaterial(E=1.65e8, nu=0.34, rho=1400.0, h=51e-6)
    mesh = polygon_quad_mesh(np.array([[0, a, a, 0], [0, 0, a, a]], float), n)
    mem = MembraneTL(mesh=mesh, material=material)
    x = mem.X.copy()
    x[:2] *= 1 + strain
    f, K = mem.internal(x)
    p = mesh.p
    edge = np.isclose(p[0], 0) | np.isclose(p[0], a) | np.isclose(p[1], 0) | np.isclose(p[1], a)
    free = np.repeat(~edge, 3)
    modes = lowest_modes(K, mem.mass(), k=k, free=free)
    E = ((1 + strain) ** 2 - 1) / 2
    S0 = material.E / (1 - material.nu) * E
    mn = np.array([(i, j) for i in range(1, 8) for j in range(1, 8)])
    f_exact = np.sort(0.5 / a * np.sqrt(S0 / material.rho) * np.hypot(mn[:, 0], mn[:, 1]))[:k]
    return dict(freq_fe=modes.freq_hz, freq_exact=f_exact, h=a / (2 * n), ndof=int(free.sum()),
                residual_force=float(abs(f[free]).max()), modes=modes)


def _chain(n_el, length, EA, rhoA, tension):
    """A straight chain of n_el truss elements along x, end nodes fixed, stretched to ``length``
    by the tension ``tension`` (rest length from the closed form of the element law)."""
    # N = EA E l / L with E = (l^2 - L^2)/(2 L^2): solve for L per element (monotone in L)
    le = length / n_el
    from scipy.optimize import brentq
    L = brentq(lambda L: EA * (le**2 - L**2) / (2 * L**2) * le / L - tension, 0.5 * le, le,
               xtol=1e-300, rtol=4 * np.finfo(float).eps)
    X = np.zeros((3, n_el + 1))
    X[0] = np.linspace(0.0, length, n_el + 1)
    conn = np.array([np.arange(n_el), np.arange(1, n_el + 1)])
    ts = TrussSet(conn=conn, L=np.full(n_el, L), EA=np.full(n_el, EA), rhoA=np.full(n_el, rhoA),
                  tension_only=np.ones(n_el, bool))
    r = truss_internal(X, ts)
    free = np.ones((n_el + 1, 3), bool)
    free[[0, -1]] = False
    return X, ts, r, free.ravel()


def taut_string_modes(*, n_el: int, length: float, tension: float, mu: float, EA: float,
                      k: int = 6, lumped: bool = False) -> dict:
    """Transverse modes of a taut string of truss elements with consistent (or lumped) mass.

    ``mu`` is the mass per unit *current* length; closed form (benchmarks.json ``taut_string``):
    f_n = n/(2 length) sqrt(tension/mu), each twice (two transverse planes).
    """
    X, ts0, r0, free = _chain(n_el, length, EA, 1.0, tension)
    ts = TrussSet(conn=ts0.conn, L=ts0.L, EA=ts0.EA, rhoA=np.full(n_el, mu * (length / n_el) / ts0.L[0]),
                  tension_only=ts0.tension_only)
    M = truss_mass(ts, X.shape[1], lumped=lumped)
    modes = lowest_modes(r0.K, M, k=k, free=free)
    nn = np.arange(1, k // 2 + 2)
    f_exact = np.repeat(nn / (2 * length) * np.sqrt(tension / mu), 2)[:k]
    return dict(freq_fe=modes.freq_hz, freq_exact=f_exact, N=r0.N, h=length / n_el, modes=modes)


def beaded_string_modes(*, n_beads: int, spacing: float, tension: float, bead_mass: float,
                        EA: float) -> dict:
    """N point masses on a massless string (N + 1 truss elements, lumped bead masses).

    Closed form (benchmarks.json ``beaded_string``): omega_k = 2 sqrt(T/(m l)) sin(k pi/(2(N+1))),
    k = 1..N, each twice (two transverse planes); EA >> T keeps the axial modes above them.
    """
    n_el = n_beads + 1
    X, ts, r, free = _chain(n_el, spacing * n_el, EA, 0.0, tension)
    m = np.full(3 * (n_el + 1), bead_mass)
    M = sp.diags(m).tocsr()
    modes = lowest_modes(r.K, M, k=2 * n_beads, free=free)
    kk = np.arange(1, n_beads + 1)
    omega = 2 * np.sqrt(tension / (bead_mass * spacing)) * np.sin(kk * np.pi / (2 * (n_beads + 1)))
    return dict(omega_fe=modes.omega, omega_exact=np.repeat(omega, 2), modes=modes, N=r.N)
