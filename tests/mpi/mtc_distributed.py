"""Run under mpiexec by tests/test_petsc_backend.py: the MTC model's tangent and mass assembled
rank by rank (tmfem.models.mtc.distributed), Newton to the static equilibrium from the design
and 12 modes with the PETSc backend; rank 0 prints one JSON document.

usage: python tests/mpi/mtc_distributed.py PRESET MESH_N [--replicated] [--fail-rank R] [--nan-rank R]
--fail-rank R: the element kernel of rank R raises (a failure on one rank: the other ranks
wait in a collective call, mpi_main aborts the job); --nan-rank R: rank R's element
matrices are not finite (caught collectively by the assembler: one clean error).
"""
import argparse
import json
import sys

import numpy as np

from tmfem.solvers.distributed import comm_world, mpi_main


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("preset")
    ap.add_argument("mesh_n", type=int)
    ap.add_argument("--fail-rank", type=int, default=None)
    ap.add_argument("--nan-rank", type=int, default=None)
    ap.add_argument("--replicated", action="store_true",
                    help="MTCModel(backend='petsc') itself: every rank assembles the whole model, "
                         "the static continuation from the undeformed membrane and the modes")
    args = ap.parse_args()
    from tmfem.models.mtc.distributed import DistributedMTC
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.newton import newton
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset
    comm = comm_world()

    def run():
        if args.replicated:
            model = MTCModel(load_preset(args.preset), mesh_n=args.mesh_n, backend="petsc")
            st = model.solve_static()
            md = model.modes(st.x, k=12)
            return json.dumps({"ranks": comm.size, "x": model.reduce(st.x).tolist(),
                               "omega2": md.omega2.tolist(), "iterations": st.iterations})
        model = MTCModel(load_preset(args.preset), mesh_n=args.mesh_n)
        d = DistributedMTC(model)
        be = PetscBackend()
        u0 = d.unknowns(model.reduce(model.initial_positions("design")))
        if args.fail_rank is not None:
            res = d.residual

            def failing(u):
                if comm.rank == args.fail_rank:
                    raise FloatingPointError("element kernel produced NaN on purpose")
                return res(u)
            d.residual = failing
        if args.nan_rank is not None and comm.rank == args.nan_rank:
            matrix = d.membrane.matrix
            d.membrane.matrix = lambda Ke, out=None: matrix(np.full_like(Ke, np.nan), out=out)
        sol = newton(d.residual, u0, tol=1e-9, backend=be)
        _, K = d.residual(sol.u)
        w, V = be.eigsh(K, d.mass(), 12, -1.0)
        return json.dumps({"ranks": comm.size, "x": d.positions(sol.u).tolist(),
                           "omega2": w.tolist(), "iterations": sol.iterations})
    return run()


if __name__ == "__main__":
    sys.exit(mpi_main(main))
