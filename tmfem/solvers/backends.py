"""Linear-algebra backends of the solvers: linear solves and generalised eigenproblems.

Solvers (Newton, arc length, eigen) talk to a backend only, so a scale-out backend can be
added beside the embedded scipy default without touching elements or models. A backend
provides

``factorize(A) -> solve``     solve(b) for a square sparse matrix A (b may be (n,) or (n, m));
``eigsh(K, M, k, sigma) -> (w, V)``   the k eigenpairs of K v = w M v nearest to ``sigma``.

``get_backend("scipy")`` is always available (SuperLU + ARPACK shift-invert). The name
``"petsc"`` is reserved for a PETSc/SLEPc backend (KSP/EPS through petsc4py/slepc4py); while
that is not implemented or not installed, asking for it raises :class:`BackendUnavailable`
naming the install command.
"""
from __future__ import annotations

from typing import Callable, Protocol

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from tmfem.errors import BackendUnavailable, ConvergenceError, InputError

PETSC_INSTALL = ("PETSC_CONFIGURE_OPTIONS=\"--with-fc=0 --with-cuda=0 --with-x=0 --with-debugging=0\" "
                 ".venv/bin/pip install petsc petsc4py slepc slepc4py   "
                 "(needs apt-get install libopenblas-dev libopenmpi-dev; builds PETSc, tens of minutes)")


class Backend(Protocol):
    name: str

    def factorize(self, A) -> Callable[[np.ndarray], np.ndarray]: ...

    def eigsh(self, K, M, k: int, sigma: float) -> tuple[np.ndarray, np.ndarray]: ...


class SingularMatrix(ConvergenceError):
    """A tangent matrix that cannot be factorised (a mechanism, a slack structure)."""


class ScipyBackend:
    """Embedded default: SuperLU direct solves, ARPACK shift-invert Lanczos."""

    name = "scipy"

    def factorize(self, A):
        if not sp.issparse(A):
            A = sp.csc_matrix(np.asarray(A, dtype=float))
        n = A.shape[0]
        A = sp.csc_matrix(A)
        try:
            # FE tangents are structurally symmetric: symmetric ordering with diagonal pivots
            # is 3-6x faster than the default COLAMD + partial pivoting
            lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options=dict(SymmetricMode=True))
            d = lu.U.diagonal()
            if not np.all(np.isfinite(d)) or not np.all(d != 0):
                raise RuntimeError("zero pivot in symmetric mode")
        except RuntimeError:
            try:
                lu = spla.splu(A)
            except RuntimeError as exc:   # "Factor is exactly singular"
                raise SingularMatrix(f"linear solve: expected a non-singular {n}x{n} matrix, "
                                     f"found a singular one ({exc})") from None
        d = lu.U.diagonal()
        if not np.all(np.isfinite(d)) or (d.size and np.min(np.abs(d)) <= 1e-14 * np.max(np.abs(d))):
            raise SingularMatrix(f"linear solve: expected a non-singular {n}x{n} matrix, found "
                                 f"pivot ratio {np.min(np.abs(d)) / max(np.max(np.abs(d)), 1e-300):.2e} "
                                 "(a mechanism or an unloaded cable/membrane direction?)")
        return lu.solve

    def eigsh(self, K, M, k, sigma):
        n = K.shape[0]
        if n <= 600 or k >= n - 1:
            import scipy.linalg as la
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
                              OPinv=op, tol=1e-12)
        except spla.ArpackNoConvergence as exc:
            raise ConvergenceError(f"eigen: ARPACK did not converge for k={k} modes near sigma={sigma:g} "
                                   f"({len(exc.eigenvalues)} converged)") from None
        return w, V


class PetscBackend:   # pragma: no cover - exercised only where petsc4py is installed
    """Placeholder of the scale-out backend; raises until petsc4py/slepc4py are present."""

    name = "petsc"

    def __init__(self):
        try:
            import petsc4py  # noqa: F401
            import slepc4py  # noqa: F401
        except ImportError:
            raise BackendUnavailable(f"backend 'petsc': expected petsc4py and slepc4py importable, "
                                     f"found them missing; install with: {PETSC_INSTALL}") from None
        raise BackendUnavailable("backend 'petsc': petsc4py/slepc4py are installed but the PETSc "
                                 "backend is not implemented yet in this tmfem version; use 'scipy'")


_BACKENDS = {"scipy": ScipyBackend, "petsc": PetscBackend}


def get_backend(name: str | Backend | None = None) -> Backend:
    """Return a backend by name ('scipy' default, 'petsc'), or pass an object through."""
    if name is None:
        return ScipyBackend()
    if not isinstance(name, str):
        return name
    cls = _BACKENDS.get(name)
    if cls is None:
        raise InputError(f"backend: expected one of {sorted(_BACKENDS)}, found {name!r}")
    return cls()
