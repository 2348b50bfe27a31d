"""Run under mpiexec by tests/solvers/test_petsc_backend.py: a finite-element model on the PETSc
backend, its tangent and mass assembled rank by rank (tmfem.fem.distributed: each rank
evaluates its share of the membrane or shell elements), static equilibrium and 12 modes;
rank 0 prints one JSON document.

usage: python tests/mpi/fe_distributed.py PRESET|SYSTEM.toml MESH_N [--model mtc|sbc]
                                          [--start design|undeformed] [--fail-rank R] [--nan-rank R]
                                          [--options="-snes_type newtonls ..."] [--sequence N]
--model: the MTC model (membrane, bars, tendons; default) or the SBC model (MITC4 shells,
beams, cables; static from the undeformed membrane through the MTC predictor);
--start: the MTC model's start; --fail-rank R: the membrane/shell kernel of rank R raises
(a failure on one rank: the other ranks wait in a collective call, mpi_main aborts the
job); --nan-rank R: rank R's element matrices are not finite (caught collectively by the
assembler: one clean error); --options: PETSc options of the backend; --sequence: the MTC
static solve with mesh sequencing down to N (coarse levels built, solved and released). The MTC document has
``m_orth``: max |Phi^T M Phi - I| of the modes with the scipy mass of the model.
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
    ap.add_argument("--model", choices=("mtc", "sbc"), default="mtc")
    ap.add_argument("--start", default="undeformed")
    ap.add_argument("--fail-rank", type=int, default=None)
    ap.add_argument("--nan-rank", type=int, default=None)
    ap.add_argument("--options", default=None)
    ap.add_argument("--sequence", type=int, default=None)
    args = ap.parse_args()
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset, load_system
    comm = comm_world()
    system = load_system(args.preset) if args.preset.endswith(".toml") else load_preset(args.preset)
    backend = PetscBackend(options=args.options)
    if args.model == "mtc":
        from tmfem.models.mtc.model import MTCModel
        model = MTCModel(system, mesh_n=args.mesh_n, backend=backend)
        element = model.membrane_element
    else:
        from tmfem.models.sbc.model import SBCModel
        model = SBCModel(system, mesh_n=args.mesh_n, backend=backend)
        element = model.shell
    kernel = element.element_arrays
    if args.fail_rank is not None and comm.rank == args.fail_rank:
        def failing(*a, **k):
            raise FloatingPointError("element kernel produced NaN on purpose")
        element.element_arrays = failing
    if args.nan_rank is not None and comm.rank == args.nan_rank:
        def nan(*a, **k):
            fe, Ke = kernel(*a, **k)
            return fe, (None if Ke is None else np.full_like(Ke, np.nan))
        element.element_arrays = nan
    out = {"ranks": comm.size, "distributed": model.distributed is not None}
    if args.model == "mtc":
        st = model.equilibrium(start=args.start, sequence=args.sequence)
        md = model.modes(k=12, at=st.x)
        S = md.shapes
        m_orth = np.abs(S.T @ (model.mass() @ S) - np.eye(S.shape[1])).max()
        out.update(x=model.reduce(st.x).tolist(), iterations=st.iterations, m_orth=float(m_orth))
    else:
        st = model.equilibrium()
        md = model.modes(k=12, at=st)
        out.update(x=st.state.x.tolist(), R=st.state.R.tolist(), iterations=st.iterations,
                   predictor_iterations=st.predictor_iterations)
    return json.dumps(dict(out, omega2=md.omega2.tolist()))


if __name__ == "__main__":
    sys.exit(mpi_main(main, report=rank_report()))
