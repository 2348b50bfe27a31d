"""Run under mpiexec by tests/solvers/test_petsc_backend.py: two matrices whose rows on rank 0 have the
same pattern and whose rows on the last rank differ. The backend's pattern cache must take
the same branch on every rank (else one rank creates a Mat while another updates one: a
hang). Rank 0 prints the relative residuals of the two solves as JSON."""
import json
import sys

import numpy as np
import scipy.sparse as sp

from tmfem.cli import rank_report
from tmfem.solvers.distributed import mpi_main


def main():
    from tmfem.solvers.petsc import PetscBackend
    be = PetscBackend()
    n = 40
    A = sp.diags([-np.ones(n - 1), 4 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tolil()
    B = A.copy()
    B[n - 1, 0] = -0.5                        # a new entry in the last row only (unsymmetric: LU)
    B = B.tocsr()
    B.eliminate_zeros()
    b = np.linspace(1, 2, n)
    out = []
    for M in (A.tocsr(), B, A.tocsr()):
        x = be.factorize(M)(b)
        out.append(float(np.linalg.norm(M @ x - b) / np.linalg.norm(b)))
    return json.dumps(out)


if __name__ == "__main__":
    sys.exit(mpi_main(main, report=rank_report()))
