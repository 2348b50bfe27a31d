"""Run under mpiexec by tests/test_petsc_backend.py: the MTC model on the PETSc backend, whose
tangent and mass are assembled rank by rank (tmfem.fem.distributed: each rank evaluates its
share of the membrane elements), static equilibrium and 12 modes; rank 0 prints one JSON
document.

usage: python tests/mpi/mtc_distributed.py PRESET MESH_N [--start design|undeformed]
                                            [--fail-rank R] [--nan-rank R]
--fail-rank R: the membrane kernel of rank R raises (a failure on one rank: the other ranks
wait in a collective call, mpi_main aborts the job); --nan-rank R: rank R's element
matrices are not finite (caught collectively by the assembler: one clean error).
"""
import argparse
import json
import sys

import numpy as np

from tmfem.cli import rank_report
from tmfem.solvers.distributed import comm_world, mpi_main


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("preset")
    ap.add_argument("mesh_n", type=int)
    ap.add_argument("--start", default="undeformed")
    ap.add_argument("--fail-rank", type=int, default=None)
    ap.add_argument("--nan-rank", type=int, default=None)
    args = ap.parse_args()
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    comm = comm_world()
    model = MTCModel(load_preset(args.preset), mesh_n=args.mesh_n, backend="petsc")
    element = model.membrane_element
    kernel = element.element_arrays
    if args.fail_rank is not None and comm.rank == args.fail_rank:
        def failing(*a, **k):
            raise FloatingPointError("element kernel produced NaN on purpose")
        element.element_arrays = failing
    if args.nan_rank is not None and comm.rank == args.nan_rank:
        def nan(*a, **k):
            fe, Ke = kernel(*a, **k)
            return fe, np.full_like(Ke, np.nan)
        element.element_arrays = nan
    st = model.solve_static(start=args.start)
    md = model.modes(st.x, k=12)
    return json.dumps({"ranks": comm.size, "x": model.reduce(st.x).tolist(),
                       "omega2": md.omega2.tolist(), "iterations": st.iterations,
                       "distributed": model.distributed is not None})


if __name__ == "__main__":
    sys.exit(mpi_main(main, report=rank_report()))
