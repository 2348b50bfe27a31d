"""Run under mpiexec by tests/test_petsc_backend.py: the SBC model (MITC4 shells, beams,
cables) on the PETSc backend, its tangent and mass assembled rank by rank
(tmfem.fem.distributed: each rank evaluates its share of the shell elements), static
equilibrium from the undeformed membrane and 12 modes; rank 0 prints one JSON document.

usage: python tests/mpi/sbc_distributed.py PRESET MESH_N [--fail-rank R] [--nan-rank R]
--fail-rank R: the shell kernel of rank R raises (the other ranks wait in a collective call,
mpi_main aborts the job); --nan-rank R: rank R's shell element matrices are not finite
(caught collectively by the assembler: one clean error).
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
    ap.add_argument("--fail-rank", type=int, default=None)
    ap.add_argument("--nan-rank", type=int, default=None)
    args = ap.parse_args()
    from tmfem.models.sbc.model import SBCModel
    from tmfem.system import load_preset
    comm = comm_world()
    model = SBCModel(load_preset(args.preset), mesh_n=args.mesh_n, backend="petsc")
    shell = model.shell
    kernel = shell.element_arrays
    if args.fail_rank is not None and comm.rank == args.fail_rank:
        def failing(*a, **k):
            raise FloatingPointError("shell kernel produced NaN on purpose")
        shell.element_arrays = failing
    if args.nan_rank is not None and comm.rank == args.nan_rank:
        def nan(*a, **k):
            fe, Ke = kernel(*a, **k)
            return fe, (None if Ke is None else np.full_like(Ke, np.nan))
        shell.element_arrays = nan
    st = model.solve_static()
    md = model.modes(st.state, k=12, tangent=st.tangent)
    return json.dumps({"ranks": comm.size, "x": st.state.x.tolist(), "R": st.state.R.tolist(),
                       "omega2": md.omega2.tolist(), "iterations": st.iterations,
                       "predictor_iterations": st.predictor_iterations,
                       "distributed": model.distributed is not None})


if __name__ == "__main__":
    sys.exit(mpi_main(main, report=rank_report()))
