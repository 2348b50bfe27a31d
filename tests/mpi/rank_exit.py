"""Run under mpiexec by tests/cli/test_hostile_mpi.py: ``tmfem ARGS...`` as a child process of
this rank, whose exit code is written to DIR/rank<r>.exit (mpiexec reports its own status
when it is signalled, not the ranks'). This process ignores SIGINT and SIGTERM, which reach
the child (mpiexec signals the ranks' process groups), and exits with the child's code.

usage: python tests/mpi/rank_exit.py DIR tmfem-arguments...
"""
import os
import signal
import subprocess
import sys
from pathlib import Path

rank = int(os.environ.get("OMPI_COMM_WORLD_RANK") or os.environ.get("PMI_RANK") or 0)
signal.signal(signal.SIGINT, signal.SIG_IGN)
signal.signal(signal.SIGTERM, signal.SIG_IGN)
code = subprocess.call([sys.executable, "-m", "tmfem", *sys.argv[2:]])
(Path(sys.argv[1]) / f"rank{rank}.exit").write_text(f"{code}\n")
sys.exit(code)
