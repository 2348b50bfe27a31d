"""Redundant shift-invert operator for the block eigensolver under ``mpiexec -n P > 1``.

Every rank factorises the *whole* K - sigma M sequentially (its own MUMPS Cholesky on
``COMM_SELF``), so that a block of right-hand sides B (n, b) can be split by columns: rank
r solves its b / P columns with its own factors, with no communication inside the
triangular solves,

    X[:, cols_r] = (K - sigma M)^-1 B[:, cols_r],

and the columns are exchanged afterwards (rows stay distributed as in the rest of the
block method: an ``Allgatherv`` of the right-hand sides' rows before the solve, an
``Alltoallv`` of the solutions' rows after it). PETSc 3.18's parallel MUMPS solve of
several right-hand sides costs as much per column as single solves (docs/guides/backends.md);
this one costs one sequential block solve of b / P columns per rank.

The price is memory: P copies of the factors on a node instead of one distributed copy.
MUMPS checks its own estimate before it allocates the factors: with ICNTL(23) = the
budget per rank (MB) it refuses a factorisation whose estimated working memory exceeds
it (INFOG(1) = -19, the estimate in INFOG(16)), which :func:`redundant_shift_invert`
reports as :class:`RedundantDoesNotFit`, collectively (every rank gets the same answer).
"""
from __future__ import annotations

import logging
import os
import time

import numpy as np

log = logging.getLogger(__name__)

#: share of the node's available memory that the ranks' redundant factors may take together
MEMORY_SHARE = 0.5


class RedundantDoesNotFit(Exception):
    """The sequential factorisation of some rank would exceed the memory budget: ``budget_mb``
    per rank, MUMPS' estimate ``estimate_mb`` (the largest over the ranks)."""

    def __init__(self, budget_mb: int, estimate_mb: int):
        super().__init__(f"the redundant factorisation of K - sigma M: MUMPS estimates "
                         f"{estimate_mb} MB per rank, the budget is {budget_mb} MB per rank")
        self.budget_mb, self.estimate_mb = budget_mb, estimate_mb


def available_mb() -> float:
    """MemAvailable of this node in MB (``/proc/meminfo``; free physical pages elsewhere)."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") / 2.0 ** 20


def default_budget_mb(comm) -> int:
    """Memory per rank for its redundant factors: :data:`MEMORY_SHARE` of the node's
    available memory shared by the ranks on that node; the smallest over all ranks (one
    budget for the collective decision)."""
    from mpi4py import MPI
    node = comm.Split_type(MPI.COMM_TYPE_SHARED)
    try:
        mine = MEMORY_SHARE * available_mb() / node.size
    finally:
        node.Free()
    return max(1, int(comm.allreduce(mine, op=MPI.MIN)))


class RedundantShiftInvert:
    """(K - sigma M)^-1 applied to row-distributed blocks, columns split over the ranks
    (module docstring). Build it with :func:`redundant_shift_invert`; ``destroy()`` frees
    the factors (each rank its own: not collective)."""

    def __init__(self, PETSc, comm, S, ksp, rows: tuple[int, int]):
        self.PETSc, self.comm = PETSc, comm          # comm: mpi4py communicator
        self._S, self._ksp = S, ksp
        self.F = ksp.getPC().getFactorMatrix()
        self.n = S.getSize()[0]
        bounds = comm.allgather(rows)          # every rank's rows [lo, hi) of the blocks
        self._row_counts = np.array([hi - lo for lo, hi in bounds])
        self._dense = {}

    def _cols(self, m: int) -> list[np.ndarray]:
        """Columns of a block of m solved by each rank (contiguous, as even as possible)."""
        return np.array_split(np.arange(m), self.comm.size)

    def _seq_dense(self, key, m: int):
        """A sequential dense Mat (n, m), one per key and m (reused across the blocks)."""
        PETSc = self.PETSc
        if (key, m) not in self._dense:
            D = PETSc.Mat().createDense((self.n, m), comm=PETSc.COMM_SELF)
            D.setUp()
            self._dense[(key, m)] = D
        return self._dense[(key, m)]

    def solve(self, X: np.ndarray) -> np.ndarray:
        """(K - sigma M)^-1 X for this rank's rows X (n_local, m) of a block; this rank's rows
        of the result."""
        from mpi4py import MPI
        comm, P = self.comm, self.comm.size
        n_loc, m = X.shape
        full = np.empty((self.n, m))
        comm.Allgatherv(np.ascontiguousarray(X), [full, self._row_counts * m, MPI.DOUBLE])
        cols = self._cols(m)
        mine = cols[comm.rank]
        Y = np.empty((self.n, mine.size))
        if mine.size:
            B, Xm = self._seq_dense("b", mine.size), self._seq_dense("x", mine.size)
            B.getDenseArray()[:] = full[:, mine]
            B.assemble()
            self.F.matSolve(B, Xm)
            Y[:] = Xm.getDenseArray()
        # rank s needs rows [lo_s, hi_s) of my columns; I need my rows of everyone's columns
        widths = np.array([c.size for c in cols])
        send_counts = self._row_counts * mine.size
        recv_counts = n_loc * widths
        recv = np.empty(int(recv_counts.sum()))
        comm.Alltoallv([Y, (send_counts, _displs(send_counts)), MPI.DOUBLE],
                       [recv, (recv_counts, _displs(recv_counts)), MPI.DOUBLE])
        out = np.empty((n_loc, m))
        start = 0
        for s in range(P):
            size = int(recv_counts[s])
            out[:, cols[s]] = recv[start:start + size].reshape(n_loc, widths[s])
            start += size
        return out

    def destroy(self) -> None:
        """Free this rank's dense work Mats, KSP (the factors) and gathered matrix."""
        for D in self._dense.values():
            D.destroy()
        self._dense.clear()
        self._ksp.destroy()
        self._S.destroy()


def _displs(counts: np.ndarray) -> np.ndarray:
    """Displacements of consecutive MPI buffer segments of the given counts."""
    return np.concatenate(([0], np.cumsum(counts)[:-1]))


def redundant_shift_invert(PETSc, A, budget_mb: int, make_ksp) -> RedundantShiftInvert:
    """Each rank's sequential MUMPS Cholesky of the whole symmetric parallel matrix A
    (= K - sigma M, gathered with ``MatCreateSubMatrices``), the factorisation refused by
    MUMPS when its estimate exceeds ``budget_mb`` per rank (ICNTL(23)). Collective.

    Parameters
    ----------
    PETSc : module
    A : PETSc Mat (MPIAIJ), symmetric; left intact
    budget_mb : int
        Memory per rank allowed to MUMPS for the factorisation (MB).
    make_ksp : callable
        ``make_ksp(S)``: the caller's KSP (``COMM_SELF``; type, PC, options database) of the
        sequential matrix S, not yet set up.

    Raises
    ------
    RedundantDoesNotFit
        On every rank when some rank's estimate exceeds the budget.
    PETSc.Error
        A failing factorisation (the caller names it).
    """
    comm = A.getComm().tompi4py()
    n = A.getSize()[0]
    cpu = time.process_time()
    everything = PETSc.IS().createStride(n, 0, 1, comm=PETSc.COMM_SELF)
    try:
        (S,) = A.createSubMatrices(everything)
    finally:
        everything.destroy()
    S.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    ksp = make_ksp(S)
    pc = ksp.getPC()
    pc.setFactorSetUpSolverType()
    F = pc.getFactorMatrix()
    F.setMumpsIcntl(23, int(budget_mb))
    try:
        ksp.setUp()
        failed = None
    except PETSc.Error as exc:
        failed = exc
    info = F.getMumpsInfog(1) if failed is None else 0
    estimate = F.getMumpsInfog(16)
    flags = comm.allgather((info == -19, failed is not None or info < 0, estimate))
    if any(f[0] for f in flags):
        ksp.destroy()
        S.destroy()
        raise RedundantDoesNotFit(int(budget_mb), max(f[2] for f in flags))
    if any(f[1] for f in flags):
        ksp.destroy()
        S.destroy()
        if failed is not None:
            raise failed
        raise PETSc.Error(76)          # PETSC_ERR_LIB: MUMPS' factorisation failed on some rank
    log.debug("redundant factorisation: n = %d, MUMPS estimate %d MB per rank (budget %d MB), "
              "gathered and factorised in %.2f s of CPU", n, estimate, budget_mb,
              time.process_time() - cpu)
    return RedundantShiftInvert(PETSc, comm, S, ksp, A.getOwnershipRange())
