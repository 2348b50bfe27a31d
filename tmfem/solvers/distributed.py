"""Distributed assembly and rank-collective errors for runs under ``mpiexec -n P``.

Solver-layer facility of the PETSc backend; it knows element dofs and matrices, nothing of
the structure they come from.

* :func:`element_share` -- the contiguous block of elements this rank assembles.
* :class:`DistributedAssembler` -- each rank passes the element vectors/matrices of *its*
  share (global dofs, optionally mapped by a constraint matrix ``u = T u_r`` and restricted
  to the unknowns ``keep``); matrices become one parallel PETSc AIJ matrix
  (:class:`DistributedMatrix`) preallocated exactly from the union of the ranks' patterns,
  vectors a full array on every rank. The pattern is exchanged once: each rank sends the
  (row, column) keys of its entries to the rank owning the row (PETSc's default row split),
  which builds the CSR pattern of its rows; every later assembly is one ``np.bincount`` per
  rank and one ``Alltoallv`` of values (the COO assembly of PETSc >= 3.19, which the
  petsc4py 3.18 of Debian bookworm does not expose).
* :class:`collective` -- a block every rank enters: an exception on any rank is raised on
  all ranks (with the failing rank's message), so no rank waits in a collective call for a
  rank that has died (the assemblers check their element arrays so).
* :func:`mpi_main` runs a program: output on rank 0 only, one error message, a non-zero
  exit code on every rank, never a hang.

Vectors are replicated (O(n) per rank), matrices and factorisations distributed.
"""
from __future__ import annotations

import sys
import traceback

import numpy as np
import scipy.sparse as sp

from tmfem import errors
from tmfem.errors import InputError, TmfemError


def comm_world():
    """mpi4py's COMM_WORLD (through petsc4py, so that PETSc is initialised first)."""
    from tmfem.solvers.petsc import petsc_modules
    PETSc, _ = petsc_modules()
    return PETSc.COMM_WORLD.tompi4py()


def element_share(ne: int, comm=None) -> slice:
    """Elements [lo, hi) of ``ne`` assembled by this rank: contiguous blocks of
    ne // P (+1 on the first ne % P ranks)."""
    comm = comm_world() if comm is None else comm
    base, extra = divmod(int(ne), comm.size)
    r = comm.rank
    lo = r * base + min(r, extra)
    return slice(lo, lo + base + (1 if r < extra else 0))


class collective:
    """Context manager entered by every rank: if the block raises on any rank, every rank
    raises a :class:`TmfemError` of the failing rank's type with its message (the lowest
    failing rank's), so that no rank is left waiting in a collective call."""

    def __init__(self, comm=None, what: str = ""):
        self.comm = comm_world() if comm is None else comm
        self.what = what

    def __enter__(self):
        return self

    def __exit__(self, etype, exc, tb):
        if etype is not None and not issubclass(etype, Exception):
            return False                       # KeyboardInterrupt, SystemExit: let them pass
        mine = None if exc is None else (etype.__name__, str(exc), isinstance(exc, TmfemError))
        allinfo = self.comm.allgather(mine)
        failed = [(r, info) for r, info in enumerate(allinfo) if info is not None]
        if not failed:
            return False
        r, (name, msg, known) = failed[0]
        cls = getattr(errors, name, None) if known else None
        if cls is None:
            cls = _find_tmfem_error(name) if known else TmfemError
        where = f"rank {r} of {self.comm.size}" if self.comm.size > 1 else ""
        others = f" (and {len(failed) - 1} other rank(s))" if len(failed) > 1 else ""
        text = f"{where}{others}: {msg}" if where else msg
        if not known:
            text = f"{self.what + ': ' if self.what else ''}{name}: {text}"
        raise cls(text) from None


def _find_tmfem_error(name: str):
    """The TmfemError subclass called ``name`` (also those defined outside tmfem.errors)."""
    todo = [TmfemError]
    while todo:
        c = todo.pop()
        if c.__name__ == name:
            return c
        todo.extend(c.__subclasses__())
    return TmfemError


def mpi_main(main, *, comm=None, grace: float = 5.0, label: str = "") -> int:
    """Run ``main()`` on every rank; return its exit code (0, or the error's ``exit_code``).

    ``main`` returns the text to print (or None); rank 0 prints it. When ``main`` raises,
    the ranks agree by a non-blocking barrier: if every rank reaches it within ``grace``
    seconds (the error was raised on all ranks, or the others finished), rank 0 prints the
    lowest failing rank's message once as ``error: ...`` and every rank returns the code.
    If not (the other ranks wait in a collective call for the failed one), the failing rank
    prints its message and aborts the MPI job with the code: a non-zero exit, never a hang.
    ``label`` prefixes the error line (the CLI's ``"tmfem static: "``).
    """
    import time
    comm = comm_world() if comm is None else comm
    text, failure = None, None
    try:
        text = main()
    except TmfemError as exc:
        failure = (exc.exit_code, str(exc))
    except Exception as exc:
        traceback.print_exc()
        failure = (1, f"{type(exc).__name__}: {exc}")
    if comm.size > 1:
        req = comm.Ibarrier()
        t0 = time.monotonic()
        while not req.Test():
            if failure is not None and time.monotonic() - t0 > grace:
                print(f"{label}error: rank {comm.rank} of {comm.size}: {failure[1]}", file=sys.stderr,
                      flush=True)
                comm.Abort(failure[0])
            time.sleep(0.01)
        failures = comm.allgather(failure)
    else:
        failures = [failure]
    bad = [(r, f) for r, f in enumerate(failures) if f is not None]
    if bad:
        r, (code, msg) = bad[0]
        if comm.rank == 0:
            where = f"rank {r} of {comm.size}: " if comm.size > 1 and len(bad) < comm.size else ""
            print(f"{label}error: {where}{msg}", file=sys.stderr, flush=True)
        return code
    if comm.rank == 0 and text:
        print(text, flush=True)
    return 0


class DistributedMatrix:
    """A parallel PETSc AIJ matrix assembled by a :class:`DistributedAssembler`.

    ``mat`` is the petsc4py Mat; ``version`` counts value updates (the backend refuses a
    solve of an older version); ``pattern`` identifies the sparsity pattern; ``shape``."""

    def __init__(self, mat, pattern, shape):
        self.mat, self.pattern, self.shape = mat, pattern, shape
        self.version = 0


class DistributedAssembler:
    """Assemble this rank's element vectors/matrices into replicated vectors and one
    distributed matrix (module docstring).

    Parameters
    ----------
    dofs : ndarray (ne_local, nd)
        Global dofs of the elements of this rank's share (full numbering, ``n`` dofs).
    n : int
        Number of full dofs.
    T : sparse (n, n_r), optional
        Constraint map u = T u_r: vectors become T^T f and matrices T^T K T.
    keep : bool mask (n_r,), optional
        The unknowns (free dofs); the others are dropped and the result is numbered
        0 .. keep.sum() - 1 in their order.
    comm : mpi4py communicator, optional (COMM_WORLD)
    """

    def __init__(self, dofs, n: int, *, T=None, keep=None, comm=None):
        from tmfem.solvers.petsc import petsc_modules
        self.PETSc, _ = petsc_modules()
        self.comm = comm_world() if comm is None else comm
        dofs = np.asarray(dofs, dtype=np.int64)
        if dofs.ndim != 2 or (dofs.size and (dofs.min() < 0 or dofs.max() >= n)):
            raise InputError(f"distributed assembly: expected dofs (ne, nd) in [0, {n}), found shape "
                             f"{dofs.shape}" + (f", range [{dofs.min()}, {dofs.max()}]" if dofs.size else ""))
        ne, nd = dofs.shape
        T = sp.identity(n, format="csr") if T is None else sp.csr_matrix(T)
        if T.shape[0] != n:
            raise InputError(f"distributed assembly: expected T with {n} rows, found {T.shape}")
        nr = T.shape[1]
        keep = np.ones(nr, bool) if keep is None else np.asarray(keep, bool)
        if keep.shape != (nr,):
            raise InputError(f"distributed assembly: expected keep of shape ({nr},), found {keep.shape}")
        number = np.full(nr, -1, np.int64)
        number[keep] = np.arange(int(keep.sum()))
        self.N = int(keep.sum())
        # each element dof -> up to p (unknown, weight) pairs of its T row; padding weight 0
        counts = np.diff(T.indptr)
        p = max(1, int(counts[dofs].max())) if dofs.size else 1
        C = np.full((ne, nd, p), -1, np.int64)
        W = np.zeros((ne, nd, p))
        for i in range(p):                      # p is small (1 for plain dofs)
            has = counts[dofs] > i
            pos = T.indptr[dofs] + i
            C[has, i] = number[T.indices[pos[has]]]
            W[has, i] = T.data[pos[has]]
        W[C < 0] = 0.0
        self._p, self._C, self._W = p, C, W
        # vector entries: (ne, nd, p)
        self._vrows = np.where(C >= 0, C, 0).ravel()
        # matrix entries: (ne, nd, p, nd, p)
        rows = np.broadcast_to(C[:, :, :, None, None], (ne, nd, p, nd, p)).ravel()
        cols = np.broadcast_to(C[:, None, None, :, :], (ne, nd, p, nd, p)).ravel()
        valid = (rows >= 0) & (cols >= 0)
        self._valid = valid
        keys = rows[valid] * self.N + cols[valid]
        ukeys, self._inverse = np.unique(keys, return_inverse=True)
        self._nu = ukeys.size
        # owners of the rows (PETSc's default split) and the exchange of the pattern
        P = self.comm.size
        base, extra = divmod(self.N, P)
        starts = np.array([r * base + min(r, extra) for r in range(P + 1)])
        self.lo, self.hi = int(starts[self.comm.rank]), int(starts[self.comm.rank + 1])
        owner = np.searchsorted(starts, ukeys // self.N, side="right") - 1
        self._sendcounts = np.bincount(owner, minlength=P)
        self._recvcounts = np.array(self.comm.alltoall(self._sendcounts.tolist()))
        recv = np.empty(int(self._recvcounts.sum()), np.int64)
        self.comm.Alltoallv([ukeys, self._sendcounts], [recv, self._recvcounts])
        okeys, self._recv_inverse = np.unique(recv, return_inverse=True)
        self._nnz = okeys.size
        orow = okeys // self.N - self.lo
        self._indices = (okeys % self.N).astype(self.PETSc.IntType)
        self._indptr = np.zeros(self.hi - self.lo + 1, dtype=self.PETSc.IntType)
        np.cumsum(np.bincount(orow, minlength=self.hi - self.lo), out=self._indptr[1:])
        self._pattern = object()

    def _weighted(self, Xe, kind: str) -> np.ndarray:
        """Element arrays times the constraint weights, flattened like the entry lists."""
        W = self._W
        if kind == "vector":
            return (np.asarray(Xe, float)[:, :, None] * W).ravel()
        Ke = np.asarray(Xe, float)
        if self._p == 1:
            return (Ke * W[:, :, 0, None] * W[:, None, :, 0]).ravel()
        return (Ke[:, :, None, :, None] * W[:, :, :, None, None] * W[:, None, None, :, :]).ravel()

    def _check(self, Xe, shape, what):
        """Every rank agrees that the local arrays are finite and of the right shape."""
        with collective(self.comm, what):
            Xe = np.asarray(Xe, dtype=float)
            if Xe.shape != shape:
                raise InputError(f"{what}: expected element arrays of shape {shape}, found {Xe.shape}")
            bad = int(np.sum(~np.isfinite(Xe)))
            if bad:
                raise errors.ConvergenceError(f"{what}: expected finite element arrays, found {bad} "
                                              "non-finite entries")
        return Xe

    def vector(self, fe) -> np.ndarray:
        """Sum over all ranks of the element vectors ``fe`` (ne_local, nd): (N,) on every rank."""
        fe = self._check(fe, self._C.shape[:2], "distributed vector")
        local = np.bincount(self._vrows, weights=self._weighted(fe, "vector"), minlength=self.N)
        out = np.empty_like(local)
        from mpi4py import MPI
        self.comm.Allreduce(local, out, op=MPI.SUM)
        return out

    def matrix(self, Ke, *, out: DistributedMatrix | None = None) -> DistributedMatrix:
        """Sum over all ranks of the element matrices ``Ke`` (ne_local, nd, nd): a
        :class:`DistributedMatrix` (N, N); ``out`` (an earlier result of this assembler)
        is updated in place, keeping the PETSc objects (and a factorisation's analysis)."""
        ne, nd = self._C.shape[:2]
        Ke = self._check(Ke, (ne, nd, nd), "distributed matrix")
        vals = np.bincount(self._inverse, weights=self._weighted(Ke, "matrix")[self._valid],
                           minlength=self._nu)
        recv = np.empty(int(self._recvcounts.sum()))
        self.comm.Alltoallv([vals, self._sendcounts], [recv, self._recvcounts])
        data = np.bincount(self._recv_inverse, weights=recv, minlength=self._nnz)
        PETSc = self.PETSc
        nloc = self.hi - self.lo
        if out is None:
            mat = PETSc.Mat().createAIJ(size=((nloc, self.N), (nloc, self.N)),
                                        csr=(self._indptr, self._indices, data),
                                        comm=PETSc.COMM_WORLD)
            mat.assemble()
            return DistributedMatrix(mat, self._pattern, (self.N, self.N))
        if out.pattern is not self._pattern:
            raise InputError("distributed matrix: out= must come from the same assembler")
        out.mat.setValuesCSR(self._indptr, self._indices, data)
        out.mat.assemble()
        out.version += 1
        return out

    def scipy(self, D: DistributedMatrix) -> sp.csr_matrix:
        """The full matrix as scipy CSR on every rank (for checks and small problems)."""
        ip, ix, v = D.mat.getValuesCSR()
        rows = self.comm.allgather((np.diff(ip), ix, v))
        lens = np.concatenate([r[0] for r in rows])
        indptr = np.concatenate([[0], np.cumsum(lens)])
        return sp.csr_matrix((np.concatenate([r[2] for r in rows]),
                              np.concatenate([r[1] for r in rows]), indptr), shape=D.shape)
