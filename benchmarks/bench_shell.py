"""MITC4 speed: the Levy plate (4.5.1) on 10x10 ... 80x80 meshes.

For each mesh: the free dofs, the assembly time of the shell residual and tangent (element
kernel + CSR assembly), the time of one sparse factorisation and solve of the tangent
(scipy backend), and the time of one full Newton iteration (residual and tangent with the
constraint map, solve, update) at P = 100, averaged over a few repetitions.

    .venv/bin/python benchmarks/bench_shell.py [--max-n 80]
"""
import argparse
import time

import numpy as np

from tmfem.reference.benchmarks.shell_levy_plate import model
from tmfem.solvers.backends import get_backend


def timed(fn, repeat=3):
    best = np.inf
    out = None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-n", type=int, default=80)
    n_max = ap.parse_args().max_n
    print(f"{'mesh':>7} {'dofs':>7} {'kernel [s]':>10} {'assembly [s]':>12} {'solve [s]':>9} "
          f"{'Newton it. [s]':>14}")
    for n in (10, 20, 40, 80):
        if n > n_max:
            break
        s, c = model(n=n, P_max=100.0)
        st = s.reference_state()
        sh = s.shells[0]
        free = np.flatnonzero(s.constraints.free)
        t_kernel, _ = timed(lambda: sh.element_arrays(st))
        t_asm, (f, K) = timed(lambda: sh.internal(st))
        r, Kr = s.residual(st, 1.0)
        Kf = Kr[free][:, free]
        be = get_backend()
        t_solve, du = timed(lambda: be.factorize(Kf)(r[free]))

        def newton_iteration():
            rr, KK = s.residual(st, 1.0)
            d = np.zeros(rr.size)
            d[free] = -be.factorize(KK[free][:, free])(rr[free])
            return st.advanced(s.constraints.full(d), s.dofmap)
        t_it, _ = timed(newton_iteration)
        print(f"{n:>3}x{n:<3} {free.size:>7} {t_kernel:>10.3f} {t_asm:>12.3f} {t_solve:>9.3f} {t_it:>14.3f}")


if __name__ == "__main__":
    main()
