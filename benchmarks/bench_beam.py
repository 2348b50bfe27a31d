"""Speed of the four-node beam element: assembly and Newton iterations vs number of elements.

    .venv/bin/python benchmarks/bench_beam.py [--sizes 100,1000,10000]

A clamped straight cantilever (rectangle 1 x 0.1 m, E = 1.2e6 Pa, L = 12 m as in 4.5.2) of
n elements under an end moment (lambda = 0.05, one load step from the straight state). Per
size it prints the dofs, the time of the residual alone, of residual + tangent (kernel and
sparse assembly), of the factorisation + solve of the tangent, and of one full Newton
iteration (assembly, constraint reduction, solve, finite-rotation update), with the
iterations to converge; the truss kernel on the same number of nodes is the baseline.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from timing import best


def main(argv=None):
    from tmfem.fem.beam import BeamElement, BeamSection, BeamSet, line_mesh
    from tmfem.fem.constraints import ConstraintMap
    from tmfem.fem.dofmap import DofMap
    from tmfem.fem.element import State
    from tmfem.fem.truss import TrussSet, truss_internal
    from tmfem.solvers.newton import newton
    from tmfem.solvers.backends import get_backend

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="100,1000,10000")
    args = ap.parse_args(argv)
    print(f"{'elements':>8} {'dofs':>7} {'residual':>9} {'res+tang':>9} {'solve':>8} "
          f"{'newton/it':>10} {'its':>4} {'truss r+t':>9}   [s]")
    for n in [int(s) for s in args.sizes.split(",")]:
        L = 12.0
        X, conn = line_mesh([0, 0, 0], [L, 0, 0], n_elements=n)
        nn = X.shape[1]
        dm = DofMap(np.full(nn, 6))
        sec = BeamSection.rectangle(a=1.0, b=0.1)
        beam = BeamElement(BeamSet(conn=conn, section=sec, E=1.2e6, nu=0.0, rho=1.0, v1=[0, 1, 0]), dm, X=X)
        cm = ConstraintMap.build(dm, fixed_dofs=dm.node_dofs([0]).ravel())
        fext = np.zeros(dm.ndof)
        fext[dm.node_dofs([nn - 1])[0, 4]] = -0.05 * 2 * np.pi * 1.2e6 * sec.I_s / L
        rng = np.random.default_rng(0)
        s = State.reference(X, dm).advanced(1e-3 * rng.standard_normal(dm.ndof), dm)
        t_res = best(lambda: beam.internal(s, tangent=False))
        t_tan = best(lambda: beam.internal(s))
        K = cm.tangent(beam.internal(s)[1])
        idx = np.flatnonzero(cm.free)
        Kf = K[idx][:, idx]
        be = get_backend()
        t_solve = best(lambda: be.factorize(Kf)(np.ones(idx.size)))
        calls = []

        def residual(st):
            calls.append(1)
            f, Kt = beam.internal(st)
            return cm.residual(f - fext), cm.tangent(Kt)

        t0 = time.perf_counter()
        res = newton(residual, State.reference(X, dm), free=cm.free, tol=1e-6, line_search=False,
                     update=lambda st, du: st.advanced(cm.full(du), dm))
        t_newton = (time.perf_counter() - t0) / max(res.iterations, 1)
        ts = TrussSet(conn=np.stack([np.arange(nn - 1), np.arange(1, nn)]), L=L / (nn - 1), EA=1.0,
                      rhoA=1.0, tension_only=np.zeros(nn - 1, bool))
        t_truss = best(lambda: truss_internal(X, ts))
        print(f"{n:>8} {dm.ndof:>7} {t_res:>9.4f} {t_tan:>9.4f} {t_solve:>8.4f} {t_newton:>10.4f} "
              f"{res.iterations:>4} {t_truss:>9.4f}")


if __name__ == "__main__":
    main()
