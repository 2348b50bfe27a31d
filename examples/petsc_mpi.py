"""The PETSc backend under MPI: a finite-element model solved on several ranks.

Run it under ``mpiexec``; every rank runs the same script, builds the same model and takes
part in every solve: each rank evaluates and assembles its share of the membrane elements into
one parallel PETSc matrix, MUMPS factorises it on all ranks, and SLEPc's Krylov-Schur eigen
solver works on the parallel factors. ``mpi_main`` returns the text to print on rank 0 only
and turns an error on any rank into one message and an exit code (never a hang).

    mpiexec -n 2 .venv/bin/python examples/petsc_mpi.py [--mesh 20] [--json]
    mpiexec --allow-run-as-root --oversubscribe -n 2 ...     # as root / more ranks than cores

It needs petsc4py, slepc4py and mpi4py (``make install`` builds them; docs/guides/backends.md).
"""
import argparse
import json
import sys

from tmfem.cli import rank_report
from tmfem.models.mtc.model import MTCModel
from tmfem.solvers.distributed import mpi_main
from tmfem.system import load_preset


def run(mesh: int, as_json: bool) -> str:
    """Static equilibrium from the undeformed membrane and the 12 lowest modes of the 1-4
    system's MTC model with the PETSc backend; the text rank 0 prints."""
    model = MTCModel(load_preset("1-4"), mesh_n=mesh, backend="petsc")
    static = model.equilibrium()
    modes = model.modes(k=12, at=static)
    from mpi4py import MPI
    out = {"ranks": MPI.COMM_WORLD.size, "mesh": mesh, "free_dofs": int(model.topology.T.shape[1]),
           "freq_hz": modes.freq_hz.tolist()}
    if as_json:
        return json.dumps(out)
    return (f"1-4 MTC on {out['ranks']} rank(s), 4x{mesh}x{mesh} mesh, {out['free_dofs']} free dofs\n"
            "frequencies [Hz]: "
            + " ".join(f"{f:.5f}" for f in modes.freq_hz))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=int, default=20)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    return mpi_main(lambda: run(args.mesh, args.json), report=rank_report())


if __name__ == "__main__":
    sys.exit(main())
