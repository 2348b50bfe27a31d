"""Run under mpiexec by tests/solvers/test_petsc_backend.py: ``tmfem ARGS...`` with the working
directory DIR/rank<r> of each rank r, so that relative output paths show which ranks wrote
files (only rank 0 may).

usage: python tests/mpi/in_rank_dir.py DIR tmfem-arguments...
"""
import os
import sys
from pathlib import Path

rank = int(os.environ.get("OMPI_COMM_WORLD_RANK") or os.environ.get("PMI_RANK") or 0)
where = Path(sys.argv[1]) / f"rank{rank}"
where.mkdir(parents=True, exist_ok=True)
os.chdir(where)

from tmfem.cli import main  # noqa: E402

sys.exit(main(sys.argv[2:]))
