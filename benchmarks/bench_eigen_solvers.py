"""The PETSc backend's eigen solvers alternating on one static solution (1-4 MTC + 12 modes).

    mpiexec -n 2 .venv/bin/python benchmarks/bench_eigen_solvers.py MESH [SOLVERS] [ROUNDS]
    mpiexec -n 2 .venv/bin/python benchmarks/bench_eigen_solvers.py 160 redundant,slepc 2

Solves the static equilibrium from the undeformed membrane once (mesh sequencing from
n = 10, as ``bench_backends.py``), then ``MTCModel.modes(k=12, at=x)`` with each eigen solver
of SOLVERS (``PetscBackend.eig_solver``: redundant, block, slepc; ``name:b`` sets the
right-hand sides per block, ``EIG_BLOCK`` or ``EIG_BLOCK_REDUNDANT``), ROUNDS times in
turn, so that the solvers meet the same matrices and nearly the same machine load. Rank 0
prints per call: wall s, CPU s of rank 0 and of the last rank, the solver that ran, the
largest relative frequency difference to the first call, the load average.
OPENBLAS_NUM_THREADS=1 is advised (2 threads were slower on 2 cores).
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_backends import system_1_4  # noqa: E402


def main(argv=None) -> int:
    import tmfem.solvers.petsc as tp
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.distributed import comm_world
    argv = sys.argv[1:] if argv is None else argv
    mesh = int(argv[0])
    solvers = (argv[1] if len(argv) > 1 else "redundant,slepc").split(",")
    rounds = int(argv[2]) if len(argv) > 2 else 2
    comm = comm_world()
    be = tp.PetscBackend()
    m = MTCModel(system_1_4(1.5025), mesh_n=mesh, tendon_elements=3, backend=be)
    res = m.equilibrium(sequence=10)
    ref, defaults = None, (tp.EIG_BLOCK, tp.EIG_BLOCK_REDUNDANT)
    for _ in range(rounds):
        for spec in solvers:
            solver, _, b = spec.partition(":")
            be.eig_solver = solver
            tp.EIG_BLOCK, tp.EIG_BLOCK_REDUNDANT = (int(b), int(b)) if b else defaults
            comm.Barrier()
            t, cpu = time.perf_counter(), time.process_time()
            modes = m.modes(k=12, at=res.x)
            t, cpu = time.perf_counter() - t, time.process_time() - cpu
            cpus = comm.gather(cpu)
            ref = modes.freq_hz if ref is None else ref
            if comm.rank == 0:
                print(f"{spec:14s} wall {t:6.2f} cpu0 {cpus[0]:6.2f} cpu{comm.size - 1} {cpus[-1]:6.2f} "
                      f"ran {be.last_eig_solver} maxrel {np.abs(modes.freq_hz / ref - 1).max():.1e} "
                      f"load {os.getloadavg()[0]:.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
