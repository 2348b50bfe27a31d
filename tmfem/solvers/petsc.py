"""PETSc/SLEPc backend: KSP linear solves (MUMPS by default) and SLEPc shift-invert eigensolves.

Implements the :class:`tmfem.solvers.backends.Backend` protocol through petsc4py/slepc4py:

``factorize(A) -> solve``
    KSP ``preonly`` with MUMPS: Cholesky (symmetric LDL^T, MUMPS ``SYM=2``, also for
    indefinite tangents) when A is symmetric, LU otherwise. ``solver="iterative"``: CG
    (symmetric) or GMRES with GAMG, stopping on the *unpreconditioned* residual
    ||b - A x|| <= rtol ||b|| (PETSc's default preconditioned norm stops 10-100x short of
    the requested accuracy).
``eigsh(K, M, k, sigma) -> (w, V)``
    The generalised Hermitian problem K v = w M v (eq. 5.32) by SLEPc's EPS: Krylov-Schur
    with shift-and-invert about ``sigma`` (ST ``sinvert``, the factorisation of K - sigma M
    by MUMPS Cholesky), on one rank and on the distributed factors under ``mpiexec -n P``;
    the k eigenvalues nearest to sigma, then a Rayleigh-Ritz step in the span of their
    vectors (from each rank's rows, :func:`~tmfem.solvers.distributed.rows_gram`), so that
    the vectors are M-orthonormal (the B-inner product) and repeated eigenvalues come out
    as full M-orthonormal pairs; V is gathered once, at the end.

Matrices are scipy sparse matrices (the same on every rank) or a
:class:`tmfem.solvers.distributed.DistributedMatrix` assembled rank by rank. Vectors in
and out are full numpy arrays on every rank; under ``mpiexec -n P`` the matrix rows and
the factorisation are distributed over the P ranks (MUMPS in parallel).

PETSc options: every KSP/PC/EPS/ST reads the options database after the defaults above,
so ``PETSC_OPTIONS="-ksp_type cg -pc_type hypre"`` in the environment, the ``options=``
argument (a dict ``{"ksp_type": "cg"}`` or a string ``"-ksp_type cg -pc_type gamg"``)
override them as PETSc users expect; ``options=`` wins over the environment. The eigen
solver's factorisation reads the ``st_`` prefix (``-st_pc_factor_mat_solver_type``),
SLEPc its ``eps_`` options (``-eps_tol``, ``-eps_ncv``).
"""
from __future__ import annotations

import gc
import hashlib
import logging
import weakref
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.distributed import (DistributedMatrix, ShiftedMatrix, gather, gather_rows,
                                       rows_gram)
from tmfem.solvers.mumps import is_singular, mumps_error, mumps_factor, mumps_failure
from tmfem.solvers.petsc_loader import petsc_modules
from tmfem.solvers.petsc_options import option_error, option_used, parse_options, set_from_options
from tmfem.solvers.singular import SingularMatrix

log = logging.getLogger(__name__)


#: PETSc's KSP converged reasons by value (for messages)
_KSP_REASONS = {-2: "DIVERGED_NULL", -3: "DIVERGED_ITS", -4: "DIVERGED_DTOL",
                -5: "DIVERGED_BREAKDOWN", -6: "DIVERGED_BREAKDOWN_BICG",
                -7: "DIVERGED_NONSYMMETRIC", -8: "DIVERGED_INDEFINITE_PC", -9: "DIVERGED_NANORINF",
                -10: "DIVERGED_INDEFINITE_MAT", -11: "DIVERGED_PC_FAILED"}


def _factorisation_failure(ksp, singular: str, what: str):
    """The error of a failed factorisation by ``ksp``: MUMPS' named error when its code is
    not that of a singular matrix (:mod:`tmfem.solvers.mumps`), else a
    :class:`SingularMatrix` ``f"{what}: {singular}"``."""
    failure = mumps_failure(ksp)
    if failure is not None and not is_singular(failure[0]):
        return mumps_error(*failure, what)
    code = f" (MUMPS INFOG(1) = {failure[0]})" if failure is not None else ""
    return SingularMatrix(f"{what}: {singular}{code}")


@dataclass(eq=False)
class _Factorisation:
    """A cache entry of :class:`PetscBackend`: the Mat of one sparsity pattern and its KSP
    (MUMPS' analysis and factors), with the bookkeeping of its solves."""
    mat: object                      #: PETSc Mat holding the latest matrix of the pattern
    ksp: object                      #: PETSc KSP factorising it
    generation: int                  #: bumped at each refactorisation; -1 once destroyed
    symmetric: bool                  #: Cholesky (True) or LU
    serial: int                      #: creation count, the same on every rank (``_reap``)
    #: mass pattern -> whether it lies within this pattern (:meth:`PetscBackend._analysed`)
    mass_within: weakref.WeakKeyDictionary = field(default_factory=weakref.WeakKeyDictionary)
    #: the PETSc object that owns ``ksp`` (a SNES, whose hooks the KSP calls), or None
    owner: object = None


class PetscBackend:
    """PETSc/SLEPc backend (module docstring).

    Parameters
    ----------
    solver : {"direct", "iterative"}
        MUMPS factorisation (default) or a Krylov method with algebraic multigrid.
    rtol : float
        Relative tolerance of the iterative solver on the unpreconditioned residual,
        ||b - A x|| <= rtol ||b||; set it at or below the Newton tolerance (an iterative
        step with rtol = 1e-10 leaves the Newton residual of a 1e-9 target intact).
        Ignored by nothing: ``solver="direct"`` refuses an explicit rtol.
    options : dict or str, optional
        PETSc options database entries (``{"pc_type": "hypre"}`` or ``"-pc_type hypre"``),
        applied after the defaults and after ``PETSC_OPTIONS``.
    eig_tol : float
        Relative residual tolerance of the eigenpairs (||Op x - theta x|| <= eig_tol |theta|
        of the shift-invert operator, both eigen solvers).
    """

    name = "petsc"

    #: the models assemble their tangents rank by rank into distributed matrices for it
    #: (:class:`tmfem.solvers.distributed.DistributedAssembler`)
    distributed_assembly = True

    def __init__(self, *, solver: str = "direct", rtol: float | None = None, options=None,
                 eig_tol: float = 1e-12):
        self.PETSc, self.SLEPc = petsc_modules()
        if solver not in ("direct", "iterative"):
            raise InputError(f"backend 'petsc': expected solver 'direct' or 'iterative', found {solver!r}")
        if rtol is not None and solver == "direct":
            raise InputError("backend 'petsc': rtol applies to solver='iterative' only; the direct "
                             "MUMPS solve has no tolerance")
        self.solver = solver
        self.rtol = 1e-10 if rtol is None else float(rtol)
        if not 0 < self.rtol < 1:
            raise InputError(f"backend 'petsc': expected 0 < rtol < 1, found {self.rtol}")
        self.options = parse_options(options)
        self.eig_tol = float(eig_tol)
        self.comm = self.PETSc.COMM_WORLD
        self._read = set()        # names of options= that a solver has read
        self._cache = {}          # sparsity pattern -> _Factorisation
        self._dead = []           # retired cache entries, destroyed by _reap
        self._serial = 0          # creation count of cache entries (the same on every rank)

    # ------------------------------------------------------------------ matrices
    def ownership(self, n: int) -> tuple[int, int]:
        """Rows [lo, hi) of an n x n matrix owned by this rank (PETSc's default split)."""
        P, r = self.comm.size, self.comm.rank
        base, extra = divmod(n, P)
        lo = r * base + min(r, extra)
        return lo, lo + base + (1 if r < extra else 0)

    def _mat(self, A, *, cache: bool = True):
        """(PETSc Mat, key) of A: a DistributedMatrix's Mat, or this rank's rows of a
        replicated scipy matrix. With ``cache`` a new A of an earlier pattern only updates
        that Mat's values, so that MUMPS keeps its symbolic analysis."""
        if isinstance(A, (DistributedMatrix, ShiftedMatrix)):
            return self._dist_mat(A, cache=cache)
        if not sp.issparse(A):
            A = np.asarray(A, dtype=float)
        A = sp.csr_matrix(A, dtype=float)
        A.sum_duplicates()
        A.sort_indices()
        n = A.shape[0]
        if A.shape != (n, n):
            raise InputError(f"petsc: expected a square matrix, found shape {A.shape}")
        lo, hi = self.ownership(n)
        Al = A[lo:hi]
        ip = Al.indptr.astype(self.PETSc.IntType)
        ix = Al.indices.astype(self.PETSc.IntType)
        key = None
        if cache:
            digest = hashlib.sha1(ip.tobytes() + ix.tobytes()).hexdigest()
            if self.comm.size > 1:      # every rank must take the same branch (collective calls)
                digest = "".join(self.comm.tompi4py().allgather(digest))
            key = ("csr", n, digest)
        entry = self._cache.get(key)
        if entry is None:
            M = self.PETSc.Mat().createAIJ(size=((hi - lo, n), (hi - lo, n)), csr=(ip, ix, Al.data),
                                           comm=self.comm)
        else:
            M = entry.mat
            M.setValuesCSR(ip, ix, Al.data)
            entry.generation += 1      # earlier solves of this Mat are stale now
        M.assemble()
        return M, key

    def _dist_mat(self, A, *, cache: bool):
        """(PETSc Mat, key) of a DistributedMatrix or ShiftedMatrix: with ``cache`` the
        values are copied into this backend's own Mat of that pattern (one factorisation
        and one MUMPS analysis per pattern, whichever assembled matrix of the pattern or
        shift of it comes; a later update of A leaves the factors of this one intact), the
        shift added to its diagonal."""
        base = A.base if isinstance(A, ShiftedMatrix) else A
        if not cache and base is A:
            return A.mat, None
        key = ("dist", id(A.pattern))
        entry = self._cache.get(key)
        if entry is None:
            # the factorisation lives as long as the pattern (the model's assembler): the id
            # of a dead pattern may come back, its Mat must not
            weakref.finalize(A.pattern, self._drop, key).atexit = False
            M = base.mat.duplicate(copy=True)
        else:
            M = entry.mat
            base.mat.copy(M, structure=self.PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            entry.generation += 1      # earlier solves of this Mat are stale now
        if base is not A:
            d = M.createVecLeft()
            lo, hi = M.getOwnershipRange()
            d.setArray(A.d[lo:hi])
            M.setDiagonal(d, addv=self.PETSc.InsertMode.ADD_VALUES)
            d.destroy()         # petsc4py 3.18 frees a PETSc object on destroy() only
        return M, key

    def adopt(self, pattern, mat, ksp, symmetric: bool, owner=None) -> None:
        """Make ``mat`` and ``ksp`` (a KSP of this backend's configuration that has
        factorised a matrix of the sparsity ``pattern`` of DistributedMatrix objects: the
        one of the statics' SNES ``owner``, kept alive with it) the cache entry of that
        pattern, so that later solves and the eigen solve reuse MUMPS' analysis
        (:meth:`_analyzed`). Collective."""
        key = ("dist", id(pattern))
        old = self._cache.pop(key, None)
        if old is None:
            weakref.finalize(pattern, self._drop, key).atexit = False
        else:
            self._dead.append(old)
        self._serial += 1
        self._cache[key] = _Factorisation(mat, ksp, 0, symmetric, self._serial, owner=owner)

    def _drop(self, key) -> None:
        """Retire the cached Mat and KSP (MUMPS factors) of ``key`` (its pattern is gone).

        A finalizer: it runs wherever the pattern dies, which need not be the same point on
        every rank (an exception unwinding on one rank, the cyclic garbage collector), and
        destroying MUMPS factors is collective. So the entry leaves the cache at once and
        is destroyed later by :meth:`_reap`, at a call every rank makes."""
        entry = self._cache.pop(key, None)
        if entry is not None:
            self._dead.append(entry)

    def _reap(self) -> None:
        """Destroy the retired entries that every rank has retired, in the order they were
        created (collective: called where every rank enters, at each factorisation and
        eigen solve)."""
        serials = sorted(e.serial for e in self._dead)
        if self.comm.size > 1:
            common = set(serials)
            for other in self.comm.tompi4py().allgather(serials):
                common &= set(other)
            serials = sorted(common)
        for serial in serials:
            entry = next(e for e in self._dead if e.serial == serial)
            self._dead.remove(entry)
            self._destroy(entry)

    @staticmethod
    def _destroy(entry) -> None:
        """Free the Mat and KSP of a cache entry (collective); its solves are stale."""
        entry.generation = -1
        entry.ksp.destroy()
        entry.mat.destroy()
        if entry.owner is not None:
            entry.owner.destroy()

    def _symmetric(self, A, M) -> bool:
        """Whether A (scipy, the same on every rank) or its PETSc Mat M equals its transpose
        to 1e-12 of its largest entry; the same answer on every rank (petsc4py 3.18's
        ``isSymmetric`` of an MPIAIJ matrix answers per rank)."""
        if sp.issparse(A):
            A = sp.csr_matrix(A)
            big = abs(A).max() if A.nnz else 0.0
            D = A - A.T
            return bool((abs(D).max() if D.nnz else 0.0) <= 1e-12 * big)
        if isinstance(A, np.ndarray):
            return bool(np.abs(A - A.T).max(initial=0.0) <= 1e-12 * np.abs(A).max(initial=0.0))
        # distributed: compare M x with M^T x for a random x (collective norms; a transpose
        # of the matrix would double its memory)
        x, y = M.createVecs()
        z = y.duplicate()
        lo, hi = M.getOwnershipRange()
        x.setArray(np.random.default_rng(7).standard_normal(M.getSize()[0])[lo:hi])
        M.mult(x, y)
        M.multTranspose(x, z)
        scale = y.norm()
        z.axpy(-1.0, y)
        symmetric = bool(z.norm() <= 1e-12 * max(scale, 1e-300))
        for v in (x, y, z):
            v.destroy()
        return symmetric

    def _configure(self, ksp, symmetric: bool) -> None:
        """Defaults of the module docstring, then the options database (PETSC_OPTIONS and
        ``options=``, which wins)."""
        PETSc = self.PETSc
        pc = ksp.getPC()
        if self.solver == "direct":
            ksp.setType("preonly")
            pc.setType("cholesky" if symmetric else "lu")
            pc.setFactorSolverType("mumps")
        else:
            ksp.setType("cg" if symmetric else "gmres")
            pc.setType("gamg")
            ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
            ksp.setTolerances(rtol=self.rtol, atol=0.0, max_it=10000)
        with self._database(self.options):
            set_from_options(ksp, "linear solver (petsc)")

    @contextmanager
    def _database(self, entries: dict):
        """PETSc's options database with ``entries`` ({name: value}) set inside the block,
        the earlier values restored after it (options do not leak into the next object)."""
        opts = self.PETSc.Options()
        saved = {}
        for name, v in entries.items():
            saved[name] = opts.getString(name, None) if opts.hasName(name) else None
            opts.setValue(name, v)
        try:
            yield
        finally:
            self._read.update(name for name in saved
                              if name in self.options and option_used(self.PETSc, name))
            for name, old in saved.items():
                if old is None:
                    opts.delValue(name)
                else:
                    opts.setValue(name, old)

    def unused_options(self) -> list[str]:
        """The entries of ``options=`` (as ``-name``) that none of this backend's solvers
        has read so far: misspelt, or for a solver not yet run (an ``-eps_*`` option before
        the first eigen solve)."""
        return [f"-{name}" for name in self.options if name not in self._read]

    # ------------------------------------------------------------------ linear solves
    def factorize(self, A):
        """``solve(b)`` of the square matrix A (module docstring); :class:`SingularMatrix`
        when the factorisation fails (zero pivot) or a solution is not finite.

        The returned ``solve`` accepts b of shape (n,) or (n, m) (full arrays on every
        rank) and returns x of the same shape on every rank. Factorising another matrix of
        the same sparsity pattern reuses the PETSc objects (and MUMPS' analysis): an older
        ``solve`` of that pattern then raises instead of silently using the new factors.
        """
        PETSc = self.PETSc
        self._reap()
        M, key = self._mat(A)
        n = M.getSize()[0]
        sym = self._symmetric(A, M)
        entry = self._cache.get(key)
        if entry is None or entry.symmetric != sym:
            ksp = PETSc.KSP().create(comm=self.comm)
            M.setOption(PETSc.Mat.Option.SYMMETRIC, sym)
            ksp.setOperators(M)
            self._configure(ksp, sym)
            if entry is not None:          # the same pattern (and Mat M), the other symmetry
                old = self._cache.pop(key)
                old.generation = -1        # its solves are stale
                old.ksp.destroy()
            self._serial += 1
            entry = _Factorisation(M, ksp, 0, sym, self._serial)
            if len(self._cache) >= 4:
                self._destroy(self._cache.pop(next(iter(self._cache))))
            self._cache[key] = entry
        else:
            ksp = entry.ksp
            ksp.setOperators(M)
        entry.generation += 1
        generation = entry.generation
        where = f"linear solve (petsc {ksp.getType()}/{ksp.getPC().getType()})"
        try:
            # MUMPS reads its options (-mat_mumps_icntl_*) when the factor is created, here
            with self._database({k: v for k, v in self.options.items()
                                 if not k.startswith(("eps_", "st_"))}):
                ksp.setUp()
        except PETSc.Error as exc:
            if (refused := option_error(exc, where)) is not None:
                raise refused from None
            raise _factorisation_failure(ksp, f"expected a non-singular {n}x{n} matrix, found the "
                                         f"factorisation failing (PETSc error {exc.ierr})", where) from None
        if mumps_failure(ksp) is not None:
            raise _factorisation_failure(ksp, f"expected a non-singular {n}x{n} matrix, found a "
                                         "singular one", where)
        lo, hi = M.getOwnershipRange()
        x_vec, b_vec = M.createVecs()

        def solve(b, *, rtol: float | None = None):
            if entry.generation != generation:
                raise InputError("petsc: this solve belongs to an earlier factorisation of a matrix "
                                 "of the same pattern, which has since been refactorised")
            b = np.asarray(b, dtype=float)
            if b.shape[0] != n:
                raise InputError(f"petsc solve: expected a right-hand side of {n} rows, found {b.shape}")
            if rtol is not None:
                if self.solver == "direct":
                    raise InputError("petsc solve: rtol applies to solver='iterative' only")
                ksp.setTolerances(rtol=float(rtol))
            cols = b.reshape(n, -1)
            if cols.shape[1] > 1 and self.solver == "direct":
                out = self._mat_solve(ksp, cols)
                if not np.all(np.isfinite(out)):
                    raise SingularMatrix(f"linear solve (petsc): expected a non-singular {n}x{n} "
                                         "matrix, found a numerically singular one (non-finite "
                                         "solution)")
                return out.reshape(b.shape)
            out = np.empty_like(cols)
            for j in range(cols.shape[1]):
                b_vec.setArray(cols[lo:hi, j])
                ksp.solve(b_vec, x_vec)
                if self.solver == "iterative":
                    self._refine(ksp, M, b_vec, x_vec)
                reason = ksp.getConvergedReason()
                if reason < 0:
                    what = _KSP_REASONS.get(reason, str(reason))
                    if self.solver == "direct" or reason in (-11,):
                        raise SingularMatrix(f"linear solve (petsc): expected a non-singular {n}x{n} "
                                             f"matrix, found a singular one (KSP {what})")
                    raise ConvergenceError(f"linear solve (petsc {ksp.getType()}/{ksp.getPC().getType()}): "
                                           f"expected ||b - A x|| <= {ksp.getTolerances()[0]:.1e} ||b|| "
                                           f"within {ksp.getTolerances()[3]} iterations, found KSP {what} "
                                           f"after {ksp.getIterationNumber()} iterations "
                                           f"(residual {ksp.getResidualNorm():.3e})")
                out[:, j] = self.gather(x_vec)
            if not np.all(np.isfinite(out)):
                raise SingularMatrix(f"linear solve (petsc): expected a non-singular {n}x{n} matrix, "
                                     "found a numerically singular one (non-finite solution; a "
                                     "mechanism or an unloaded cable/membrane direction?)")
            return out.reshape(b.shape)
        return solve

    @staticmethod
    def _refine(ksp, A, b, x, restarts: int = 3) -> None:
        """Restart a converged Krylov solve from x while the true residual ||b - A x||
        exceeds the tolerance (the method's recursively updated residual, which it stops
        on, drifts from the true one by round-off near rtol = 1e-10)."""
        rtol = ksp.getTolerances()[0]
        r = b.duplicate()
        bn = b.norm()
        try:
            for _ in range(restarts):
                A.mult(x, r)
                r.aypx(-1.0, b)                  # r = b - A x
                if ksp.getConvergedReason() < 0 or r.norm() <= rtol * bn:
                    return
                ksp.setInitialGuessNonzero(True)
                ksp.solve(b, x)
        finally:
            ksp.setInitialGuessNonzero(False)
            r.destroy()

    def _mat_solve(self, ksp, B: np.ndarray) -> np.ndarray:
        """X = A^-1 B for the m columns of B (n, m) at once (MUMPS' multiple right-hand
        sides, MatMatSolve: 5-7x less time per column than m single solves at m = 12-28)."""
        PETSc = self.PETSc
        n, m = B.shape
        F = ksp.getPC().getFactorMatrix()
        lo, hi = F.getOwnershipRange()
        Bm = PETSc.Mat().createDense(((hi - lo, n), (None, m)), comm=self.comm)
        Bm.setUp()
        Bm.getDenseArray()[:] = B[lo:hi]
        Bm.assemble()
        Xm = Bm.duplicate()
        F.matSolve(Bm, Xm)
        local = np.array(Xm.getDenseArray())
        Bm.destroy()
        Xm.destroy()
        return gather_rows(local, self.comm.tompi4py())

    def gather(self, vec) -> np.ndarray:
        """Full numpy copy (n,) of a distributed PETSc Vec on every rank."""
        return gather(vec)

    # ------------------------------------------------------------------ nonlinear statics
    def solve_equilibrium(self, residual, energy, u0, **kwargs):
        """The equilibrium r(u) = 0 of the energy W from u0 by PETSc's SNES with
        pseudo-transient continuation (:func:`tmfem.solvers.petsc_snes.snes_equilibrium`:
        the arguments of :func:`tmfem.solvers.trust_region.trust_region_newton` with every
        dof free, a distributed tangent and the residual as this rank's rows of it, the
        fields of its result as a dict)."""
        from tmfem.solvers.petsc_snes import snes_equilibrium
        self.release_retired()
        return snes_equilibrium(self, residual, energy, u0, **kwargs)

    def factor_memory_mb(self) -> dict:
        """MUMPS' memory on this rank [MB] for the factorisations this backend holds, summed
        (MUMPS users' guide: INFO(22), effectively used in the factorisation; INFO(16),
        allocated for it): ``{"used": ..., "allocated": ...}``, zeros when it holds none."""
        used = allocated = 0
        for entry in self._cache.values():
            F = mumps_factor(entry.ksp)
            if F is not None:
                used += int(F.getMumpsInfo(22))
                allocated += int(F.getMumpsInfo(16))
        return {"used": float(used), "allocated": float(allocated)}

    def release_retired(self) -> None:
        """Free the factorisations (MUMPS factors, SNES) of patterns that are gone, also of
        models that went in a reference cycle (a coarse level of a mesh sequencing), before
        a new model's matrices take their memory. Collective (every rank calls it)."""
        gc.collect()
        self._reap()

    # ------------------------------------------------------------------ eigenproblems
    def eigsh(self, K, M, k, sigma):
        """The k eigenpairs of K v = w M v nearest to ``sigma`` (eq. 5.32), ascending, by
        SLEPc's Krylov-Schur shift-and-invert (module docstring); V (n, k) M-orthonormal."""
        self._reap()
        Kp, _ = self._mat(K, cache=False)
        Mp, _ = self._mat(M, cache=False)
        n = Kp.getSize()[0]
        k = int(k)
        if not 1 <= k < n:
            raise InputError(f"eigen (petsc): expected 1 <= k < {n} (matrix size), found k={k}")
        sym = self._symmetric(K, Kp) and self._symmetric(M, Mp)
        reuse = self._analyzed(K, M) if sym else None
        w, local = self._slepc_eigsh(Kp, Mp, k, float(sigma), sym, reuse)
        # Rayleigh-Ritz in span(V) from each rank's rows of V: exactly M-orthonormal, also
        # inside clusters of equal eigenvalues; ascending (eigh); the full V gathered once
        comm = self.comm.tompi4py()
        Kr, Mr = rows_gram(Kp, local, comm), rows_gram(Mp, local, comm)
        w, Y = la.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T))
        return w, gather_rows(local @ Y, comm)

    def _analyzed(self, K, M):
        """The cache entry (Mat, KSP: MUMPS' analysis done) of the tangent K's pattern when
        the eigen solve can factorise K - sigma M in it, else None.

        The static solve has factorised tangents of K's pattern in that entry (a Cholesky
        KSP whose symbolic analysis every later numeric factorisation of the pattern
        reuses); when the mass M has no entry outside K's pattern (the MTC mass: the
        membrane's and the trusses' node blocks), K - sigma M has K's pattern and needs
        only a numeric factorisation there (one MUMPS analysis less per eigen solve:
        PETSc's PCSetUp redoes the symbolic factorisation only when the nonzero pattern
        changes). Not with ``st_`` options (they configure the eigen solve's own KSP), an
        iterative solver or a matrix of another kind. Collective (the subset check)."""
        if not (self.solver == "direct" and type(K) is DistributedMatrix
                and type(M) is DistributedMatrix):
            return None
        entry = self._cache.get(("dist", id(K.pattern)))
        if entry is None or not entry.symmetric or any(key.startswith("st_") for key in self.options) \
                or any(key.startswith("st_") for key in self.PETSc.Options().getAll()):
            return None
        subset = entry.mass_within.get(M.pattern)
        if subset is None:
            subset = entry.mass_within[M.pattern] = self._subset(M, K)
        return entry if subset else None

    def _subset(self, B, A, *, chunk: int = 1 << 17) -> bool:
        """Whether the nonzero pattern of the DistributedMatrix B lies within that of A
        (the same row layout); the same answer on every rank. Read from the assemblers'
        patterns (PETSc's CSR only where a pattern does not carry them), ``chunk`` entries
        of B's rows at a time: no copy of the matrices' values or of their full keys (the
        blocks of ~1 MB are reused from the heap, which keeps what larger blocks would
        leave resident there after the check)."""
        ia, ja = A.pattern.indptr, A.pattern.indices
        if ia is None:
            ia, ja, _ = A.mat.getValuesCSR()
        ib, jb = B.pattern.indptr, B.pattern.indices
        if ib is None:
            ib, jb, _ = B.mat.getValuesCSR()
        n = A.shape[1]
        rows, r0, mine = ib.size - 1, 0, True
        while mine and r0 < rows:
            r1 = int(np.searchsorted(ib, ib[r0] + chunk, side="right")) - 1
            r1 = min(rows, max(r0 + 1, r1))
            r = np.arange(r0, r1, dtype=np.int64)
            ka = np.repeat(r, np.diff(ia[r0:r1 + 1])) * n + ja[ia[r0]:ia[r1]]
            kb = np.repeat(r, np.diff(ib[r0:r1 + 1])) * n + jb[ib[r0]:ib[r1]]
            if not bool(np.all(ka[1:] >= ka[:-1])):   # AIJ rows come column-sorted
                ka.sort()
            pos = np.minimum(np.searchsorted(ka, kb), max(ka.size - 1, 0))
            mine = bool(kb.size == 0 or (ka.size > 0 and np.array_equal(ka[pos], kb)))
            r0 = r1
        if self.comm.size == 1:
            return mine
        return all(self.comm.tompi4py().allgather(mine))

    def _slepc_eigsh(self, Kp, Mp, k: int, sigma: float, sym: bool, reuse=None):
        """(w, V) of K v = w M v: the k converged eigenvalues nearest to sigma and this
        rank's rows of their vectors, by SLEPc (module docstring). With
        ``reuse`` (:meth:`_analysed`) K - sigma M is formed in place in that entry's Mat
        and factorised by its KSP (SLEPc's ``ST`` mat mode ``inplace``, subset pattern):
        MUMPS' analysis of the static solve is reused."""
        PETSc, SLEPc = self.PETSc, self.SLEPc
        n = Kp.getSize()[0]
        E = SLEPc.EPS().create(comm=self.comm)
        if reuse is not None:
            reuse.generation += 1              # its Mat becomes K - sigma M: solves are stale
            Kp.copy(reuse.mat, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            Kp = reuse.mat
        try:
            E.setOperators(Kp, Mp)
            E.setProblemType(SLEPc.EPS.ProblemType.GHEP if sym else SLEPc.EPS.ProblemType.GNHEP)
            E.setType(SLEPc.EPS.Type.KRYLOVSCHUR)
            E.setDimensions(nev=k, ncv=min(n, max(2 * k + 1, k + 16)))
            E.setTarget(float(sigma))
            E.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
            E.setTolerances(tol=self.eig_tol, max_it=1000)
            # purification (one more solve per vector) removes components in the null space
            # of a singular B; the mass is positive definite on the free dofs (lowest_modes
            # checks its diagonal): off, 12 % of the eigen time at 78k DOF, the same
            # frequencies to 4e-11 (``-eps_purify`` turns it back on)
            E.setPurify(False)
            st = E.getST()
            st.setType(SLEPc.ST.Type.SINVERT)
            st.setShift(float(sigma))
            ksp = st.getKSP()
            ksp.setType("preonly")
            ksp.getPC().setType("cholesky" if sym else "lu")
            ksp.getPC().setFactorSolverType("mumps")
            # the options stay in the database through the solve, which reads the viewers
            # (-eps_view, -eps_error_relative ::ascii_info_detail) at its end
            with self._database({key: v for key, v in self.options.items()
                                 if key.startswith(("eps_", "st_"))}):
                set_from_options(E, "eigen (petsc)")
                if reuse is not None:
                    st.setMatMode(SLEPc.ST.MatMode.INPLACE)
                    st.setMatStructure(PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
                    st.setKSP(reuse.ksp)
                try:
                    E.solve()
                except PETSc.Error as exc:
                    if (refused := option_error(exc, "eigen (petsc)")) is not None:
                        raise refused from None
                    raise _factorisation_failure(
                        st.getKSP(), f"expected K - sigma M non-singular for sigma={sigma:g}, found "
                        f"the shift-invert factorisation failing (PETSc error {exc.ierr})",
                        "eigen (petsc)") from None
            nconv = E.getConverged()
            if nconv < k:
                raise ConvergenceError(f"eigen (petsc): SLEPc converged {nconv} of k={k} modes near "
                                       f"sigma={sigma:g} in {E.getIterationNumber()} restarts")
            # the k converged pairs nearest to sigma, this rank's rows of their vectors
            w = np.array([E.getEigenvalue(i).real for i in range(nconv)])
            order = np.argsort(np.abs(w - sigma), kind="stable")[:k]
            vr = Kp.createVecRight()
            lo, hi = vr.getOwnershipRange()
            local = np.empty((hi - lo, k))
            for c, i in enumerate(order):
                E.getEigenvector(int(i), vr)
                local[:, c] = vr.getArray(readonly=True)
            vr.destroy()
        finally:
            E.destroy()
        return w[order], local
