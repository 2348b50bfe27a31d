"""Linear-algebra backends of the solvers: linear solves and generalised eigenproblems.

Solvers (Newton, arc length, eigen) talk to a backend only, so a scale-out backend can be
added beside the embedded scipy default without touching elements or models. A backend
provides

``factorize(A) -> solve``     solve(b) for a square sparse matrix A (b may be (n,) or (n, m));
``eigsh(K, M, k, sigma, v0=None) -> (w, V)``   the k eigenpairs of K v = w M v nearest to
                              ``sigma``; ``v0`` a start vector (Krylov methods) that makes
                              the basis of a repeated eigenvalue reproducible.

``get_backend("scipy")`` is always available (SuperLU + ARPACK shift-invert).
``get_backend("petsc")`` is the PETSc/SLEPc backend (:mod:`tmfem.solvers.petsc`: KSP with
MUMPS, SNES, SLEPc shift-invert, MPI); without petsc4py/slepc4py it raises
:class:`tmfem.errors.BackendUnavailable` naming the install command.
``get_backend("auto", n_dofs=N)`` chooses one of them for a model of N free dofs
(:func:`choose_backend`).
"""
from __future__ import annotations

import hashlib
import logging
from typing import Callable, Protocol

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from tmfem.errors import ConvergenceError, InputError
from tmfem.solvers.petsc import PetscBackend
from tmfem.solvers.petsc_loader import launched_ranks, petsc_available
from tmfem.solvers.singular import SingularMatrix

log = logging.getLogger(__name__)


class Backend(Protocol):
    """What a solver asks of a linear-algebra backend (module docstring)."""

    name: str

    def factorize(self, A) -> Callable[[np.ndarray], np.ndarray]: ...

    def eigsh(self, K, M, k: int, sigma: float, v0=None) -> tuple[np.ndarray, np.ndarray]: ...


class ScipyBackend:
    """Embedded default: SuperLU direct solves, ARPACK shift-invert Lanczos."""

    name = "scipy"

    #: systems at least this large are reordered by nested dissection before SuperLU
    nd_threshold = 4000

    #: nested-dissection orderings by sparsity pattern, shared by all instances (a model that
    #: asks ``get_backend()`` at every Newton iteration still orders its pattern only once)
    _orderings: dict = {}

    def factorize(self, A):
        """``solve(b)`` of the square matrix A (SuperLU, symmetric mode; nested dissection
        from ``nd_threshold`` dofs); :class:`SingularMatrix` when A cannot be factorised or a
        solution is not finite."""
        if not sp.issparse(A):
            A = np.asarray(A, dtype=float)
        A = sp.csc_matrix(A)
        A.sum_duplicates()
        n = A.shape[0]
        perm = None
        if n >= self.nd_threshold:
            perm, Ap = self._permuted(A)
        try:
            # FE tangents are structurally symmetric: a symmetric ordering (METIS nested
            # dissection, else SuperLU's MMD on A^T + A) with diagonal pivots is 3-6x faster
            # than the default COLAMD + partial pivoting
            if perm is not None:
                lu = spla.splu(Ap, permc_spec="NATURAL", diag_pivot_thresh=0.0,
                               options=dict(SymmetricMode=True))
            else:
                lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                               options=dict(SymmetricMode=True))
        except RuntimeError:
            perm = None
            try:
                lu = spla.splu(A)
            except RuntimeError as exc:   # "Factor is exactly singular"
                raise SingularMatrix(f"linear solve: expected a non-singular {n}x{n} matrix, "
                                     f"found a singular one ({exc})") from None

        def solve(b):
            b = np.asarray(b, dtype=float)
            if perm is None:
                x = lu.solve(b)
            else:
                x = np.empty_like(b)
                x[perm] = lu.solve(b[perm])
            if not np.all(np.isfinite(x)):
                raise SingularMatrix(f"linear solve: expected a non-singular {n}x{n} matrix, found a "
                                     "numerically singular one (non-finite solution; a mechanism or "
                                     "an unloaded cable/membrane direction?)")
            return x
        # smallest / largest |pivot| (SuperLU's U carries them): a caller that must not solve a
        # numerically singular matrix compares it with SINGULAR_PIVOT_RATIO
        u = np.abs(lu.U.diagonal())
        solve.pivot_ratio = float(u.min() / u.max()) if u.size and u.max() > 0 else 0.0
        return solve

    def _permuted(self, A):
        """Nested-dissection permutation of A (cached by sparsity pattern) and P A P^T (csc)."""
        key = hashlib.sha1(A.indptr.tobytes() + A.indices.tobytes()).hexdigest() + str(A.shape)
        entry = self._orderings.get(key)
        if entry is None:
            perm = nested_dissection(A)
            # where each entry of A lands in P A P^T: permute a matrix of entry numbers once
            tag = sp.csc_matrix((np.arange(1, A.nnz + 1, dtype=float), A.indices, A.indptr), shape=A.shape)
            tp = sp.csc_matrix(tag[perm][:, perm])
            tp.sort_indices()
            entry = (perm, tp.data.astype(np.int64) - 1, tp.indices.copy(), tp.indptr.copy())
            if len(self._orderings) >= 8:
                self._orderings.pop(next(iter(self._orderings)))
            self._orderings[key] = entry
        perm, where, indices, indptr = entry
        Ap = sp.csc_matrix((A.data[where], indices, indptr), shape=A.shape)
        return perm, Ap

    def eigsh(self, K, M, k, sigma, v0=None):
        """The k eigenpairs of K v = w M v nearest to ``sigma`` (eq. 5.32): dense ``eigh``
        up to 600 dofs (or k >= n - 1) unless a start vector ``v0`` is given, else ARPACK
        shift-invert with this backend's LU of K - sigma M (from ``v0`` when given), with a
        Krylov space of max(4k, 40) vectors: with ARPACK's default max(2k + 1, 20) the run
        returned, from some random start vectors, the next mode instead of the partner of a
        repeated pair (SBC 1-4, 4 x 6 x 6, k = 6: 1.9709 Hz in place of the second
        1.9500 Hz in 2 of 6 runs; 0 of 8 with the larger space)."""
        n = K.shape[0]
        if k >= n - 1 or (n <= 600 and v0 is None):
            Kd = K.toarray() if sp.issparse(K) else np.asarray(K)
            Md = M.toarray() if sp.issparse(M) else np.asarray(M)
            try:
                w, V = la.eigh(Kd, Md, subset_by_index=[0, min(k, n) - 1])
            except np.linalg.LinAlgError as exc:
                raise InputError(f"eigen: expected a positive definite mass matrix on the free dofs "
                                 f"({exc})") from None
            return w, V
        A = sp.csc_matrix(K - sigma * M)
        lu = self.factorize(A)
        op = spla.LinearOperator(A.shape, matvec=lu, dtype=float)
        try:
            w, V = spla.eigsh(sp.csr_matrix(K), k=k, M=sp.csr_matrix(M), sigma=sigma, which="LM",
                              OPinv=op, tol=1e-10, v0=v0, ncv=min(n, max(4 * k, 40)))
        except spla.ArpackNoConvergence as exc:
            raise ConvergenceError(f"eigen: ARPACK did not converge for k={k} modes near sigma={sigma:g} "
                                   f"({len(exc.eigenvalues)} converged)") from None
        return w, V


def nested_dissection(A) -> np.ndarray:
    """Fill-reducing permutation of a structurally symmetric sparse matrix by METIS's
    multilevel nested dissection (METIS_NodeND through pymetis), on the graph of
    supervariables: consecutive rows with identical patterns (the 3 dofs of a node) are
    ordered together, on a graph 3x smaller. Returns ``perm`` with A[perm][:, perm] the
    reordered matrix."""
    import pymetis

    G = sp.csr_matrix(A, copy=True)
    G.data = np.ones_like(G.data)
    G = (G + G.T).tocsr()
    G.sort_indices()
    n = G.shape[0]
    if n == 0:
        return np.arange(0)
    length = np.diff(G.indptr)
    rng = np.random.default_rng(12345)
    w1, w2 = rng.random(n), rng.random(n)
    nz = length > 0
    h1, h2 = np.zeros(n), np.zeros(n)
    if G.nnz:
        starts = G.indptr[:-1][nz]
        h1[nz] = np.add.reduceat(w1[G.indices], starts)
        h2[nz] = np.add.reduceat(w2[G.indices], starts)
    new = np.ones(n, bool)
    new[1:] = ~((length[1:] == length[:-1]) & (h1[1:] == h1[:-1]) & (h2[1:] == h2[:-1]))
    group = np.cumsum(new) - 1
    ngroup = int(group[-1]) + 1
    P = sp.csr_matrix((np.ones(n), (np.arange(n), group)), shape=(n, ngroup))
    Gs = (P.T @ G @ P).tocsr()
    Gs.setdiag(0)
    Gs.eliminate_zeros()
    order, _ = pymetis.nested_dissection(adjacency=pymetis.CSRAdjacency(
        adj_starts=Gs.indptr.astype(np.int32), adjacent=Gs.indices.astype(np.int32)))
    members = np.argsort(group, kind="stable")
    first = np.searchsorted(group[members], np.arange(ngroup))
    counts = np.bincount(group, minlength=ngroup)
    return np.concatenate([members[first[g]:first[g] + counts[g]] for g in np.asarray(order)])


_BACKENDS = {"scipy": ScipyBackend, "petsc": PetscBackend}

#: free dofs from which ``"auto"`` takes the PETSc backend. Below it the PETSc backend's fixed
#: start-up cost (0.3-0.4 s more than scipy in building the model, at every size) outweighs
#: its faster factorisations and eigen solves: a 1-4 MTC static solve from the undeformed
#: membrane with 12 modes was faster with scipy at 5,067 free dofs (4 x 20 x 20, by 12 %) and
#: faster with PETSc from 7,227 (4 x 24 x 24, by 5 %) on; the crossover lies near 6,500
#: (``benchmarks/bench_backend_crossover.py`` measures it).
AUTO_CROSSOVER_DOFS = 6500


def choose_backend(*, n_dofs: int, ranks: int | None = None) -> str:
    """The backend ``"auto"`` takes for a model of ``n_dofs`` free dofs: ``"petsc"`` under
    ``mpiexec`` with more than one rank (``ranks``, default :func:`launched_ranks`; the
    scipy backend would solve the whole problem on every rank) and, when PETSc is installed,
    from :data:`AUTO_CROSSOVER_DOFS` dofs on; ``"scipy"`` otherwise."""
    ranks = launched_ranks() if ranks is None else int(ranks)
    if ranks > 1:
        return "petsc"
    if int(n_dofs) < AUTO_CROSSOVER_DOFS:
        return "scipy"
    return "petsc" if petsc_available() else "scipy"


def backend_names() -> list[str]:
    """Names accepted by :func:`get_backend`."""
    return sorted(_BACKENDS) + ["auto"]


def get_backend(name: str | Backend | None = None, *, n_dofs: int | None = None,
                **options) -> Backend:
    """Return a backend by name ('scipy' default, 'petsc', or 'auto': :func:`choose_backend`
    for ``n_dofs`` free dofs) built with ``options`` (the PETSc backend's keyword arguments;
    the scipy backend and 'auto' take none), or pass an object through."""
    if name is None:
        name = "scipy"
    if not isinstance(name, str):
        if options:
            raise InputError(f"backend: options {sorted(options)} apply to a backend built by "
                             f"name, found a backend object {type(name).__name__}")
        return name
    if name == "auto":
        if n_dofs is None:
            raise InputError("backend 'auto': expected the model's number of free dofs (n_dofs=) "
                             "to choose between scipy and petsc, found none")
        if options:
            raise InputError(f"backend 'auto': option does not apply: {', '.join(sorted(options))} "
                             "(options of the PETSc backend: expected backend 'petsc')")
        name = choose_backend(n_dofs=n_dofs)
        log.debug("backend auto: %s for %d free dofs (crossover %d)", name, n_dofs,
                 AUTO_CROSSOVER_DOFS)
    cls = _BACKENDS.get(name)
    if cls is None:
        raise InputError(f"backend: expected one of {backend_names()}, found {name!r}")
    if options and name == "scipy":
        raise InputError(f"backend 'scipy': option does not apply: {', '.join(sorted(options))} "
                         "(options of the PETSc backend: expected backend 'petsc')")
    return cls(**options)
