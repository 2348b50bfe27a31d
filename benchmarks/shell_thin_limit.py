"""Thin-shell limit of the MITC4 element: conditioning, locking and Newton convergence.

The square membrane of 4.5.4 (a = 2 m, corner forces) on a 10 x 10 mesh with the shell
thickness h from 1 mm down to 1 um (the dissertation's 51 um is h/a = 2.55e-5). Prints per h:
the 2-norm condition number of the reduced tangent at the flat unloaded state and at the
prestressed state (stage 1 of 4.5.4), with and without symmetric diagonal (Jacobi) scaling,
the smallest/largest LU pivot of the unloaded tangent without and with the scaling (the
dense solver calls a matrix singular below 1e-14), the Newton residual history of the last
load step of stage 2 (relative to the load), Newton for stage 2 in one step to 1e-10 of the
load without and with Jacobi-equilibrated solves (final ||r||/||F||, iterations), the
centre deflection of the shell and of the membrane element, and the linear centre deflection
of a simply supported plate under pressure against Kirchhoff's 0.00406 q a^4/D (shear locking
would make it too small as h -> 0).

    .venv/bin/python benchmarks/shell_thin_limit.py
"""
import numpy as np
import scipy.linalg as sla
from skfem import MeshQuad

from tmfem.errors import ConvergenceError

from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure
from tmfem.reference.benchmarks.shell_square_membrane import shell_square_membrane
from tmfem.solvers.newton import jacobi_scaling, newton


def cond(K, free):
    A = K[free][:, free].toarray()
    d = jacobi_scaling(A)
    return np.linalg.cond(A), np.linalg.cond(A * d[:, None] * d[None, :])


def pivot_ratio(K, free):
    """min/max |LU pivot| of the reduced tangent, unscaled and Jacobi-scaled."""
    A = K[free][:, free].toarray()
    d = jacobi_scaling(A)
    out = []
    for M in (A, A * d[:, None] * d[None, :]):
        p = np.abs(np.diag(sla.lu_factor(M)[0]))
        out.append(p.min() / p.max())
    return out


def tight_newton(s, stage1, equilibrate):
    """Stage 2 of 4.5.4 in one load step, Newton to 1e-10 of the load Fw = 0.1 N."""
    try:
        res = newton(lambda t: s.residual(t, 1.0), stage1.state, free=s.constraints.free, tol=1e-10,
                     scale=0.1, line_search=False, update=s.advance, equilibrate=equilibrate)
    except ConvergenceError as exc:
        return f"failed ({str(exc)[:40]})"
    return f"{res.residual_history[-1] / 0.1:.1e} ({res.iterations} it.)"


def plate(h, n=16, a=2.0, E=1e9, nu=0.3):
    xs = np.linspace(0, a, n + 1)
    s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=E, nu=nu, thickness=h))
    edge = s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(x, a) | np.isclose(y, 0) | np.isclose(y, a))
    s.fix(edge, "uz")
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) & np.isclose(y, 0)), ["ux", "uy"])
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, a) & np.isclose(y, 0)), "uy")
    s.pressure(1.0, follower=False)
    c = int(s.nodes_where(lambda x, y, z: np.isclose(x, a / 2) & np.isclose(y, a / 2))[0])
    w = abs(s.displacements(s.solve_linear())[2, c])
    return w / (0.00406235 * a**4 / (E * h**3 / (12 * (1 - nu**2))))


def main():
    from tmfem.reference.element_benchmarks import square_membrane
    from tmfem.system.materials import MembraneMaterial
    print(f"{'h [m]':>8} {'h/a':>8} {'cond K0':>9} {'cond K0 sc':>10} {'cond Kp':>9} {'cond Kp sc':>10} "
          f"{'piv K0':>8} {'piv K0 sc':>9} {'Newton 1e-10 plain':>19} {'equilibrated':>19} "
          f"{'w_c shell/membrane-1':>21} {'plate w/Kirchhoff':>18}  Newton ||r||/||F|| (last step)")
    for h in (1e-3, 1e-4, 51e-6, 1e-5, 1e-6):
        s, st, st1, path, mesh = shell_square_membrane(n=5, steps=4, thickness=h)
        free = s.constraints.free
        _, K0 = s.residual(s.reference_state(), 0.0)
        _, Kp = s.residual(st1.state, 0.0)
        c0, c0s = cond(K0, free)
        cp, cps = cond(Kp, free)
        p0, p0s = pivot_ratio(K0, free)
        n_plain, n_eq = tight_newton(s, st1, False), tight_newton(s, st1, True)
        mem = square_membrane(n=5, material=MembraneMaterial(E=1.65e8, nu=0.34, rho=1400.0, h=h))
        centre = int(np.argmin(np.hypot(mesh.p[0] - 1, mesh.p[1] - 1)))
        ratio = s.displacements(st)[2, centre] / mem.u[2, centre] - 1
        hist = " ".join(f"{r / 0.1:.1e}" for r in path[-1].residual_history)
        print(f"{h:8.1e} {h / 2:8.1e} {c0:9.2e} {c0s:10.2e} {cp:9.2e} {cps:10.2e} {p0:8.1e} {p0s:9.1e} "
              f"{n_plain:>19} {n_eq:>19} {ratio:21.2e} "
              f"{plate(h):18.4f}  {hist}")


if __name__ == "__main__":
    main()
