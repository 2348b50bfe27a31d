"""Distributed assembly and rank-collective errors for runs under ``mpiexec -n P``.

Solver-layer facility of the PETSc backend; it knows element dofs and matrices, nothing of
the structure they come from.

* :func:`element_share` -- the contiguous block of elements this rank assembles.
* :class:`DistributedAssembler` -- each rank passes the element matrices of *its* share
  (groups of element matrices or of single entries, global dofs, mapped by a constraint
  matrix ``u = T u_r`` and restricted to the unknowns ``keep``); they become one parallel
  PETSc AIJ matrix (:class:`DistributedMatrix`) preallocated exactly from the union of the
  ranks' patterns; vectors (each rank's contribution to the full force) are summed into
  T^T f on the unknowns, each rank receiving its rows (those of its matrix rows). The
  pattern is exchanged once: each rank sends the (row, column) keys of its entries to the
  rank owning the row (PETSc's default row split), which builds the CSR pattern of its
  rows; every later assembly is one ``np.bincount`` per rank and one ``Alltoallv`` of
  values (the COO assembly of PETSc >= 3.19, which the petsc4py 3.18 of Debian bookworm
  does not expose).
* :class:`collective` -- a block every rank enters: an exception on any rank is raised on
  all ranks (with the failing rank's message), so no rank waits in a collective call for a
  rank that has died (the assemblers check their element arrays so).
* :func:`mpi_main` runs a program: output on rank 0 only, one error message, a non-zero
  exit code on every rank, never a hang (the caller prints what it is handed: library
  code writes nothing).

Summed vectors (residuals) are held as each rank's rows; states (positions, iterates) are
replicated (O(n) per rank); matrices and factorisations are distributed.
"""
from __future__ import annotations

import logging
import time

import numpy as np
import scipy.sparse as sp

from tmfem import errors
from tmfem.errors import InputError, TmfemError
from tmfem.solvers.petsc_loader import petsc_modules

log = logging.getLogger(__name__)


def comm_world():
    """mpi4py's COMM_WORLD (through petsc4py, so that PETSc is initialised first)."""
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


def mpi_main(main, *, report, comm=None, grace: float = 5.0) -> int:
    """Run ``main()`` on every rank; return its exit code (0, or the error's ``exit_code``).

    ``main`` returns the text to show (or None); ``report(text, error=False)`` receives it
    on rank 0 (the caller prints it: this module writes nothing). When ``main`` raises, the
    ranks agree by a non-blocking barrier: if every rank reaches it within ``grace``
    seconds (the error was raised on all ranks, or the others finished), rank 0 receives
    the lowest failing rank's message once, ``report(message, error=True)`` (prefixed
    ``rank r of P: `` when not every rank failed), and every rank returns the code. If not
    (the other ranks wait in a collective call for the failed one), the failing rank
    receives ``report("rank r of P: message", error=True)`` and aborts the MPI job with the
    code: a non-zero exit, never a hang. An unexpected exception (not a
    :class:`TmfemError`) is logged with its traceback.
    """
    comm = comm_world() if comm is None else comm
    text, failure = None, None
    try:
        text = main()
    except TmfemError as exc:
        failure = (exc.exit_code, str(exc))
    except Exception as exc:
        log.error("rank %d of %d: unexpected error", comm.rank, comm.size, exc_info=True)
        failure = (1, f"{type(exc).__name__}: {exc}")
    if comm.size > 1:
        req = comm.Ibarrier()
        t0 = time.monotonic()
        while not req.Test():
            if failure is not None and time.monotonic() - t0 > grace:
                report(f"rank {comm.rank} of {comm.size}: {failure[1]}", error=True)
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
            report(f"{where}{msg}", error=True)
        return code
    if comm.rank == 0 and text:
        report(text, error=False)
    return 0


def gather(vec) -> np.ndarray:
    """Full numpy copy (n,) of a distributed PETSc Vec on every rank."""
    local = vec.getArray(readonly=True)
    comm = vec.getComm().tompi4py()
    if comm.size == 1:
        return np.array(local)
    counts = np.array(comm.allgather(local.size))
    out = np.empty(int(counts.sum()))
    comm.Allgatherv(np.ascontiguousarray(local), [out, counts])
    return out


def rows_norm(rows: np.ndarray, comm) -> float:
    """The 2-norm of a vector held as each rank's rows (collective)."""
    rows = np.asarray(rows, dtype=float)
    return float(np.sqrt(comm.allreduce(float(rows @ rows)))) if comm.size > 1 \
        else float(np.linalg.norm(rows))


def rows_dot(a: np.ndarray, b: np.ndarray, comm) -> float:
    """a . b of two vectors held as each rank's rows (collective)."""
    d = float(np.asarray(a, dtype=float) @ np.asarray(b, dtype=float))
    return comm.allreduce(d) if comm.size > 1 else d


def rows_product(A, X: np.ndarray, vecs=None) -> np.ndarray:
    """This rank's rows (n_r, m) of A X, from its rows X (n_r, m) of a block of m vectors
    and a parallel PETSc Mat A (rows laid out as A's; collective). ``vecs``: work vectors
    (x, y) of A's layout to use, else created and freed here."""
    X = np.asarray(X, dtype=float)
    x, y = A.createVecs() if vecs is None else vecs
    AX = np.empty_like(X)
    try:
        for j in range(X.shape[1]):
            x.setArray(np.ascontiguousarray(X[:, j]))
            A.mult(x, y)
            AX[:, j] = y.getArray(readonly=True)
    finally:
        if vecs is None:
            x.destroy()         # petsc4py 3.18 frees a PETSc object on destroy() only
            y.destroy()
    return AX


def rows_gram(A, X: np.ndarray, comm) -> np.ndarray:
    """X^T A X (m, m) of a block of m vectors held as each rank's rows X (n_r, m) of a
    parallel PETSc Mat A (:func:`rows_product`), summed over the ranks (collective): the
    matrices of a Rayleigh-Ritz step without a full-length array on any rank."""
    G = np.asarray(X, dtype=float).T @ rows_product(A, X)
    return comm.allreduce(G) if comm.size > 1 else G


def gather_rows(local: np.ndarray, comm) -> np.ndarray:
    """Full array (n, m) on every rank of the row blocks (n_r, m) of the ranks, in rank
    order (one ``Allgatherv`` into the result: no other full-size copy); ``local`` itself
    on one rank."""
    local = np.ascontiguousarray(local, dtype=float)
    if comm.size == 1:
        return local
    m = local.shape[1]
    counts = np.array(comm.allgather(local.shape[0])) * m
    out = np.empty((int(counts.sum()) // m, m))
    comm.Allgatherv(local, [out, counts])
    return out


def unique_inverse(keys: np.ndarray):
    """``(u, inverse)`` with u the sorted distinct values of the int64 array ``keys`` and
    ``u[inverse] == keys`` (``inverse`` int32 when it fits): ``np.unique(keys,
    return_inverse=True)``, but on a *stable* sort (timsort), which is linear on data
    made of a few sorted runs -- the received pattern keys (one sorted run per sending
    rank), the node-pair expansion of :meth:`_EntryMap.pattern` -- where np.unique's
    quicksort is n log n; already sorted keys skip the sort."""
    keys = np.asarray(keys, dtype=np.int64)
    n = keys.size
    idx = np.int32 if n < 2**31 else np.int64
    if n == 0:
        return keys.copy(), np.zeros(0, idx)
    perm = None
    if not bool(np.all(keys[1:] >= keys[:-1])):
        perm = np.argsort(keys, kind="stable")
        keys = keys[perm]
    first = np.empty(n, bool)
    first[0] = True
    np.not_equal(keys[1:], keys[:-1], out=first[1:])
    u = keys[first]
    rank = np.cumsum(first, dtype=idx)
    rank -= 1
    if perm is None:
        return u, rank
    inverse = np.empty(n, idx)
    inverse[perm] = rank
    return u, inverse


class Pattern:
    """Identity of a sparsity pattern (one per :class:`DistributedAssembler`); the backend
    keys its factorisations by it and frees them when the pattern is gone. ``indptr``,
    ``indices``: this rank's rows of the pattern (CSR, columns sorted in each row; the
    assembler's own arrays, not copies)."""

    __slots__ = ("__weakref__", "indptr", "indices")

    def __init__(self, indptr=None, indices=None):
        self.indptr, self.indices = indptr, indices


class DistributedMatrix:
    """A parallel PETSc AIJ matrix assembled by a :class:`DistributedAssembler`.

    ``mat`` is the petsc4py Mat; ``version`` counts value updates (the backend refuses a
    solve of an older version); ``pattern`` identifies the sparsity pattern (matrices of one
    assembler share it, so that the backend keeps one factorisation and its analysis for
    them); ``shape``. The operations the solvers use are those of a scipy matrix: ``A @ x``
    (x (N,) or (N, m), full arrays on every rank), ``A.diagonal()`` and ``A + D`` with a
    diagonal scipy matrix D (a :class:`ShiftedMatrix`, formed by the backend when it
    factorises it)."""

    def __init__(self, mat, pattern, shape):
        self.mat, self.pattern, self.shape = mat, pattern, shape
        self.version = 0
        self._vecs = None

    def vecs(self):
        """Work vectors (x, y) of the matrix' layout, created once (creating a parallel Vec
        is collective)."""
        if self._vecs is None:
            self._vecs = self.mat.createVecs()
        return self._vecs

    def destroy(self) -> None:
        """Free the PETSc matrix and work vectors (collective)."""
        for obj in (self._vecs or ()) + (self.mat,):
            obj.destroy()
        self._vecs = None

    def diagonal(self) -> np.ndarray:
        """The diagonal (N,) on every rank."""
        d, _ = self.vecs()
        self.mat.getDiagonal(d)
        return gather(d)

    def __matmul__(self, x):
        x = np.asarray(x, dtype=float)
        n = self.shape[0]
        if x.shape[0] != n or x.ndim > 2:
            raise InputError(f"distributed matrix: expected x of {n} rows, found shape {x.shape}")
        lo, hi = self.mat.getOwnershipRange()
        local = rows_product(self.mat, x.reshape(n, -1)[lo:hi], self.vecs())
        return gather_rows(local, self.mat.getComm().tompi4py()).reshape(x.shape)

    def __add__(self, D):
        if not (sp.issparse(D) and D.shape == self.shape
                and sp.dia_matrix(D).offsets.tolist() in ([0], [])):
            raise InputError(f"distributed matrix: expected a diagonal scipy matrix of shape "
                             f"{self.shape} to add, found {type(D).__name__}"
                             + (f" {D.shape}" if hasattr(D, "shape") else ""))
        return ShiftedMatrix(self, np.asarray(D.diagonal(), dtype=float))

    __radd__ = __add__


class ShiftedMatrix:
    """``base + diag(d)`` of a :class:`DistributedMatrix` (the regularised tangent of a
    trust-region step), formed only in the backend's own copy of ``base``'s pattern."""

    def __init__(self, base: DistributedMatrix, d: np.ndarray):
        self.base, self.d, self.shape = base, d, base.shape
        self.pattern, self.version = base.pattern, (base.version, id(d))


class DistributedAssembler:
    """Assemble this rank's element matrices into one distributed matrix (module docstring).

    Parameters
    ----------
    groups : list of (dofs, kind)
        ``kind`` ``"element"``: dofs (ne_local, nd) of element matrices (nd, nd) of this
        rank's share, full numbering; ``"entry"``: dofs (m_local, 2) (row, column) of single
        entries (the share of an assembled matrix). A single dofs array is one element group.
    n : int
        Number of full dofs.
    T : sparse (n, n_r), optional
        Constraint map u = T u_r: matrices become T^T K T.
    keep : bool mask (n_r,), optional
        The unknowns (free dofs); the others are dropped and the result is numbered
        0 .. keep.sum() - 1 in their order.
    comm : mpi4py communicator, optional (COMM_WORLD)
    """

    def __init__(self, groups, n: int, *, T=None, keep=None, comm=None):
        self.PETSc, _ = petsc_modules()
        self.comm = comm_world() if comm is None else comm
        if isinstance(groups, np.ndarray) or (isinstance(groups, list) and groups
                                              and not isinstance(groups[0], tuple)):
            groups = [(groups, "element")]
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
        self.T, self.keep, self.n = T, keep, int(n)
        self._groups, keys, local = [], [], []
        offset = 0
        for dofs, kind in groups:
            g = _entry_map(np.asarray(dofs, dtype=np.int64), kind, n, T, number)
            self._groups.append(g)
            gkeys, ginv = g.pattern(self.N)
            g.drop_pattern_tables()
            keys.append(gkeys)
            local.append((offset, gkeys.size, ginv))
            offset += gkeys.size
        keys = np.concatenate(keys) if keys else np.zeros(0, np.int64)
        ukeys, inverse = unique_inverse(keys)
        del keys
        # each valid entry of each group -> its key (through the group's own candidate keys)
        parts = [inverse[off:off + size] if ginv is None else inverse[off + ginv]
                 for off, size, ginv in local]
        del local
        self._inverse = np.concatenate(parts) if parts else inverse[:0]
        del parts, inverse
        self._nu = ukeys.size
        # owners of the rows (PETSc's default split) and the exchange of the pattern
        P = self.comm.size
        base, extra = divmod(self.N, P)
        starts = np.array([r * base + min(r, extra) for r in range(P + 1)])
        self.lo, self.hi = int(starts[self.comm.rank]), int(starts[self.comm.rank + 1])
        self._row_counts = np.diff(starts).tolist()
        owner = np.searchsorted(starts, ukeys // self.N, side="right") - 1 if self.N else ukeys
        self._sendcounts = np.bincount(owner, minlength=P)
        self._recvcounts = np.array(self.comm.alltoall(self._sendcounts.tolist()))
        if P == 1:
            okeys, self._recv_inverse = ukeys, None
        else:
            recv = np.empty(int(self._recvcounts.sum()), np.int64)
            self.comm.Alltoallv([ukeys, self._sendcounts], [recv, self._recvcounts])
            okeys, self._recv_inverse = unique_inverse(recv)      # P sorted runs: a merge
            del recv
        del ukeys
        self._nnz = okeys.size
        if P > 1:
            self._route_own_entries()
        orow = okeys // self.N - self.lo if self.N else okeys
        self._indices = (okeys % self.N if self.N else okeys).astype(self.PETSc.IntType)
        self._indptr = np.zeros(self.hi - self.lo + 1, dtype=self.PETSc.IntType)
        np.cumsum(np.bincount(orow, minlength=self.hi - self.lo), out=self._indptr[1:])
        self._pattern = Pattern(self._indptr, self._indices)

    def _route_own_entries(self) -> None:
        """Sum the entries of this rank's own rows in place (P > 1): each valid entry's
        index (:attr:`_inverse`, into the distinct keys of this rank) becomes one into the
        matrix' values (its own rows, ``_nnz``) followed by the keys of the other ranks'
        rows, which alone are sent. An assembly then holds one array of this rank's values
        (as on one rank) instead of the distinct keys' values, the received ones and the
        summed ones; an entry's sum is the same (two ranks: bit for bit; more: the order of
        the ranks' partial sums differs)."""
        me = self.comm.rank
        sdispl = np.concatenate([[0], np.cumsum(self._sendcounts)])
        rdispl = np.concatenate([[0], np.cumsum(self._recvcounts)])
        lo, n_own = int(sdispl[me]), int(self._sendcounts[me])
        idx = np.int32 if self._nu + self._nnz < 2**31 else np.int64
        # distinct key j -> its value slot: the owned row entry, or nnz + its place among
        # the keys sent (the own block removed from the send order)
        target = np.arange(self._nnz - n_own, self._nnz - n_own + self._nu, dtype=idx)
        target[:lo] += n_own
        target[lo:lo + n_own] = self._recv_inverse[rdispl[me]:rdispl[me] + n_own]
        self._inverse = target[self._inverse]
        self._nu = self._nnz + self._nu - n_own
        self._recv_inverse = np.concatenate([self._recv_inverse[:rdispl[me]],
                                             self._recv_inverse[rdispl[me] + n_own:]])
        self._sendcounts = self._sendcounts.copy()
        self._recvcounts = self._recvcounts.copy()
        self._sendcounts[me] = self._recvcounts[me] = 0

    def _check(self, values, what):
        """Every rank agrees (one collective call) that the local arrays of all groups are
        finite and of the right shapes; the arrays as float."""
        with collective(self.comm, what):
            values = [np.asarray(v, dtype=float) for v in values]
            for Xe, g in zip(values, self._groups):
                if Xe.shape != g.value_shape:
                    raise InputError(f"{what}: expected arrays of shape {g.value_shape}, found "
                                     f"{Xe.shape}")
            bad = sum(int(np.sum(~np.isfinite(Xe))) for Xe in values)
            if bad:
                raise errors.ConvergenceError(f"{what}: expected finite element arrays, found {bad} "
                                              "non-finite entries")
        return values

    def matrix(self, *values, out: DistributedMatrix | None = None) -> DistributedMatrix:
        """Sum over all ranks of this rank's element matrices / entries, one array per group
        (element groups (ne_local, nd, nd), entry groups (m_local,)): a
        :class:`DistributedMatrix` (N, N); ``out`` (an earlier result of this assembler)
        is updated in place, keeping the PETSc objects (and a factorisation's analysis)."""
        if len(values) != len(self._groups):
            raise InputError(f"distributed matrix: expected {len(self._groups)} arrays (one per "
                             f"group), found {len(values)}")
        # sums in place, group by group in the order of the entries (np.add.at: the sums of
        # one np.bincount of all groups' values, without their concatenation and without
        # bincount's int64 copy of the int32 key indices)
        # (P > 1: the entries of this rank's rows go straight into the matrix' values, the
        # others into a send buffer behind them, :meth:`_route_own_entries`)
        vals = np.zeros(self._nu)
        off = 0
        for g, v in zip(self._groups, self._check(values, "distributed matrix")):
            part = g.weighted(v)
            np.add.at(vals, self._inverse[off:off + part.size], part)
            off += part.size
        data = vals[:self._nnz]
        if self._recv_inverse is not None:
            recv = np.empty(int(self._recvcounts.sum()))
            self.comm.Alltoallv([vals[self._nnz:], self._sendcounts], [recv, self._recvcounts])
            np.add.at(data, self._recv_inverse, recv)
            del recv
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

    def vector(self, f_local: np.ndarray) -> np.ndarray:
        """This rank's rows (``hi - lo``,) of T^T f summed over the ranks and restricted to
        the unknowns (the rows of its matrix rows: a PETSc Vec's local part), from this
        rank's contribution ``f_local`` (n,) to the full internal force: one
        ``Reduce_scatter``, no full-length sum on any rank."""
        f_local = np.asarray(f_local, dtype=float)
        with collective(self.comm, "distributed vector"):
            if f_local.shape != (self.n,):
                raise InputError(f"distributed vector: expected ({self.n},), found {f_local.shape}")
            bad = int(np.sum(~np.isfinite(f_local)))
            if bad:
                raise errors.ConvergenceError(f"distributed vector: expected finite element "
                                              f"vectors, found {bad} non-finite entries")
        local = (self.T.T @ f_local)[self.keep]
        if self.comm.size == 1:
            return local
        out = np.empty(self.hi - self.lo)
        self.comm.Reduce_scatter(local, out, recvcounts=self._row_counts)
        return out

    def scipy(self, D: DistributedMatrix) -> sp.csr_matrix:
        """The full matrix as scipy CSR on every rank (for checks and small problems)."""
        ip, ix, v = D.mat.getValuesCSR()
        rows = self.comm.allgather((np.diff(ip), ix, v))
        lens = np.concatenate([r[0] for r in rows])
        indptr = np.concatenate([[0], np.cumsum(lens)])
        return sp.csr_matrix((np.concatenate([r[2] for r in rows]),
                              np.concatenate([r[1] for r in rows]), indptr), shape=D.shape)


class _EntryMap:
    """Where the entries of one group of a :class:`DistributedAssembler` go: each full dof
    maps to up to p (unknown, weight) pairs of its row of T (p = 1 for plain dofs; padding
    weight 0), an entry (i, j, v) to the entries (a, b, T_ia T_jb v) on the unknowns."""

    def __init__(self, dofs, kind, n, T, number):
        self.kind = kind
        ne, nd = dofs.shape
        self.value_shape = (ne, nd, nd) if kind == "element" else (ne,)
        counts = np.diff(T.indptr)
        p = max(1, int(counts[dofs].max())) if dofs.size else 1
        # the unknowns (-1: none, fixed) and weights of the p entries of each full dof's row of T
        Cd = np.full((n, p), -1, np.int64)
        Wd = np.zeros((n, p))
        for i in range(p):                      # p is small (1 for plain dofs)
            has = np.flatnonzero(counts > i)
            pos = T.indptr[has] + i
            Cd[has, i] = number[T.indices[pos]]
            Wd[has, i] = T.data[pos]
        Wd[Cd < 0] = 0.0
        C, W = Cd[dofs], Wd[dofs]
        self.p, self.C, self.W, self.Cd, self.dofs, self.n = p, C, W, Cd, dofs, n
        self.block_size = _block_size(dofs) if kind == "element" else 1
        self.unit = p == 1 and bool(np.all(W == 1.0))     # plain dofs: the values as they are

    def _rows_cols(self):
        """Row and column indices of the entries, broadcast views ((ne, nd, p, nd, p) for
        element groups, (m, p, p) for entry groups)."""
        C = self.C
        if self.kind == "element":
            return C[:, :, :, None, None], C[:, None, None, :, :]
        return C[:, 0, :, None], C[:, 1, None, :]

    def keys(self, N: int) -> np.ndarray:
        """Linear keys row * N + column of the valid (unknown, unknown) entries."""
        rows, cols = self._rows_cols()
        keys = (rows * N + cols).ravel()
        self._set_valid(rows, cols)
        return keys if self.all_valid else keys[self.valid]

    def _set_valid(self, rows, cols) -> None:
        """Which entries (flattened like :meth:`weighted`) land on two unknowns."""
        self.all_valid = bool((self.C >= 0).all())
        if not self.all_valid:
            self.valid = ((rows >= 0) & (cols >= 0)).ravel()

    def pattern(self, N: int):
        """``(keys, inverse)``: candidate keys row * N + column of this group and, for each
        valid entry (flattened like :meth:`weighted`), the index of its key in them
        (``None``: the keys are the entries themselves, :meth:`keys`).

        Element groups whose local dofs come in blocks of b consecutive full dofs (the 3
        translations of a membrane node, the 5 or 6 dofs of a shell node: ``block_size``)
        are keyed per *block pair* (16 per 4-node membrane element instead of 144): the
        distinct block pairs (one sort of ne nb^2 keys), then each expanded to its
        (b p) x (b p) entries through T, laid out row by row (for unknowns numbered in
        the order of the full dofs the expansion is one sorted run, which
        :func:`unique_inverse` merges with the other groups in linear time). Two block
        pairs may share entries (dofs tied by T): the assembler's unique merges them."""
        bs = self.block_size
        if bs == 1:
            return self.keys(N), None
        ne, nd, p = self.C.shape
        nb, bp = nd // bs, bs * p
        first = self.dofs[:, ::bs]                                    # (ne, nb) block ids
        pairs, pinv = np.unique((first[:, :, None] * self.n + first[:, None, :]).ravel(),
                                return_inverse=True)
        # the entries of each distinct block pair (a, c): rows C[a .. a+b-1], cols C[c ..]
        Cd = self.Cd
        rows = Cd[(pairs // self.n)[:, None] + np.arange(bs)].reshape(-1, bp)     # (npairs, bp)
        cols = Cd[(pairs % self.n)[:, None] + np.arange(bs)].reshape(-1, bp)
        npairs = pairs.size
        # row-by-row layout: the pairs of one row block a (contiguous: pairs are sorted
        # by a) expand to  for ii: for pair: for jj  (position dest)
        a = pairs // self.n
        start = np.ones(npairs, bool)
        start[1:] = a[1:] != a[:-1]
        gstart = np.flatnonzero(start)
        grp = np.cumsum(start) - 1
        s0, cnt = gstart[grp], np.diff(np.append(gstart, npairs))[grp]
        ii, jj = np.arange(bp)[:, None], np.arange(bp)[None, :]
        dest = (s0[:, None, None] * (bp * bp) + ii * (cnt[:, None, None] * bp)
                + (np.arange(npairs) - s0)[:, None, None] * bp + jj)              # (npairs, bp, bp)
        full = np.empty(npairs * bp * bp, np.int64)
        full[dest.ravel()] = (rows[:, :, None] * N + cols[:, None, :]).ravel()
        ok = np.zeros(full.size, bool)
        ok[dest.ravel()] = ((rows[:, :, None] >= 0) & (cols[:, None, :] >= 0)).ravel()
        del rows, cols
        idx = np.int32 if full.size < 2**31 else np.int64
        where = np.cumsum(ok, dtype=idx) - 1                           # key index of a slot
        where = where[dest.ravel()]                                    # ... of (pair, ii, jj)
        keys = full[ok]
        del full, ok, dest
        # each element entry (e, k, i, q, l, j, r) -> slot (pair of (k, l), (i, q), (j, r))
        pinv = pinv.reshape(ne, nb, nb).astype(idx) * idx(bp * bp)
        off = (np.arange(bp)[:, None] * bp + np.arange(bp)).astype(idx).reshape(bs, p, bs, p)
        slot = pinv[:, :, None, None, :, None, None] + off[None, None, :, :, None, :, :]
        inverse = where[slot.ravel()]
        del slot
        R, Cc = self._rows_cols()
        self._set_valid(R, Cc)
        return keys, (inverse if self.all_valid else inverse[self.valid])

    def drop_pattern_tables(self) -> None:
        """Free what only :meth:`pattern` needs (the (n, p) table of every full dof's
        unknowns, the element dofs and their unknowns; the weights when they are all 1):
        the tables over all n full dofs are as large on every rank as on one."""
        self.Cd = self.C = self.dofs = None
        if self.unit:
            self.W = None

    def weighted(self, X) -> np.ndarray:
        """Values of the valid entries: T_ia T_jb X_ij, flattened like :meth:`keys`."""
        W = self.W
        if self.unit:
            v = X.ravel()
        elif self.kind == "element":
            if self.p == 1:
                v = (X * W[:, :, 0, None] * W[:, None, :, 0]).ravel()
            else:
                v = (X[:, :, None, :, None] * W[:, :, :, None, None] * W[:, None, None, :, :]).ravel()
        else:
            v = (X[:, None, None] * W[:, 0, :, None] * W[:, 1, None, :]).ravel()
        return v if self.all_valid else v[self.valid]


class _TiedEntries:
    """An entry group some of whose entries touch a dof that T ties to several unknowns (a
    corner tied to a bar top by a rigid link: up to 11 entries in its row of T): those
    entries in an :class:`_EntryMap` of their own, the others in one with a single unknown
    per dof. One map of the whole group would lay out every entry as p x p (row, column)
    pairs, p the largest row count of T among the group's dofs: 121 keys and values for
    each entry of a mass matrix with one such corner."""

    kind = "entry"
    block_size = 1

    def __init__(self, dofs, n, T, number, tied):
        self.value_shape = (dofs.shape[0],)
        self.parts = [(idx, _EntryMap(dofs[idx], "entry", n, T, number))
                      for idx in (np.flatnonzero(~tied), np.flatnonzero(tied))]

    def pattern(self, N: int):
        """``(keys, None)``: the keys of the untied entries, then of the tied ones."""
        return np.concatenate([m.keys(N) for _, m in self.parts]), None

    def drop_pattern_tables(self) -> None:
        for _, m in self.parts:
            m.drop_pattern_tables()

    def weighted(self, X) -> np.ndarray:
        """Values of the valid entries, in the order of :meth:`pattern`'s keys."""
        return np.concatenate([m.weighted(X[idx]) for idx, m in self.parts])


def _entry_map(dofs, kind, n, T, number):
    """The map of one group (:class:`_EntryMap`), its tied entries apart when only some of
    an entry group's entries touch dofs of more than one unknown (:class:`_TiedEntries`);
    the group's kind and dofs checked first."""
    if kind not in ("element", "entry"):
        raise InputError(f"distributed assembly: expected group kind 'element' or 'entry', "
                         f"found {kind!r}")
    if dofs.ndim != 2 or (kind == "entry" and dofs.shape[1] != 2) or \
            (dofs.size and (dofs.min() < 0 or dofs.max() >= n)):
        raise InputError(f"distributed assembly: expected {kind} dofs (m, {'2' if kind == 'entry' else 'nd'}) "
                         f"in [0, {n}), found shape {dofs.shape}"
                         + (f", range [{dofs.min()}, {dofs.max()}]" if dofs.size else ""))
    if kind == "entry" and dofs.size:
        tied = (np.diff(T.indptr)[dofs] > 1).any(axis=1)
        if tied.any() and not tied.all():
            return _TiedEntries(dofs, n, T, number, tied)
    return _EntryMap(dofs, kind, n, T, number)


def _block_size(dofs: np.ndarray) -> int:
    """The largest b <= 6 dividing nd such that every element's local dofs (ne, nd) come
    in blocks of b consecutive full dofs (a node's translations: 3); 1 when none (or no
    elements)."""
    ne, nd = dofs.shape
    if ne == 0:
        return 1
    for b in range(min(6, nd), 1, -1):
        if nd % b == 0:
            D = dofs.reshape(ne, nd // b, b)
            if np.array_equal(D, D[:, :, :1] + np.arange(b)):
                return b
    return 1
