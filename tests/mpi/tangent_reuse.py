"""Run under mpiexec by tests/solvers/test_petsc_backend.py: the MTC model's distributed tangent
evaluated twice at the design configuration while rank 1 (only) still holds the first tangent.
A tangent is refilled only when no rank references it, so every rank makes the same collective
call (a new matrix on all of them here) instead of one refilling while another creates. Rank 0
prints one JSON document: the Frobenius norms of the two tangents and whether the second is a
new matrix.

usage: python tests/mpi/tangent_reuse.py PRESET MESH_N
"""
import json
import sys

from tmfem.cli import rank_report
from tmfem.solvers.distributed import comm_world, mpi_main


def main():
    from tmfem.fem.element import State
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset
    comm = comm_world()
    model = MTCModel(load_preset(sys.argv[1]), mesh_n=int(sys.argv[2]), backend=PetscBackend())
    dist = model.distributed
    state = State(x=model.initial_positions("design"))
    _, K = dist.residual(state)
    first, handle = K.mat.norm(), K.mat.handle
    held = K if comm.rank == 1 else None
    del K
    _, K = dist.residual(state)
    doc = {"first": first, "second": K.mat.norm(), "new": comm.allgather(K.mat.handle != handle)}
    del held
    if comm.rank == 0:
        print(json.dumps(doc))


if __name__ == "__main__":
    sys.exit(mpi_main(main, report=rank_report()))
