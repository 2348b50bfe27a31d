"""Vectorised sparse assembly with a cached CSR pattern.

Element kernels return element vectors ``fe`` (ne, nd) and matrices ``Ke`` (ne, nd, nd)
together with the global dofs ``dofs`` (ne, nd) of each element (node-interleaved
numbering, dof = 3*node + component). :class:`Assembler` computes the CSR pattern once
(``np.unique`` over the linear (row, col) keys) and then assembles any number of matrices
of that pattern with one ``np.bincount`` — no Python loop over elements, and no
coo -> csr sort at every Newton iteration.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def element_dofs(conn: np.ndarray, ncomp: int = 3) -> np.ndarray:
    """Global dofs (ne, nnodes_e * ncomp) of elements with node connectivity ``conn``
    (nnodes_e, ne), node-interleaved: dof = ncomp * node + component."""
    conn = np.asarray(conn, dtype=np.int64)
    return (ncomp * conn.T[:, :, None] + np.arange(ncomp)[None, None, :]).reshape(conn.shape[1], -1)


class Assembler:
    """Assemble element vectors/matrices with fixed global dofs into ``n``-sized arrays.

    Parameters
    ----------
    dofs : ndarray (ne, nd)
        Global dof of each local dof of each element.
    n : int
        Number of global dofs.
    """

    def __init__(self, dofs: np.ndarray, n: int):
        dofs = np.asarray(dofs, dtype=np.int64)
        if dofs.ndim != 2:
            raise ValueError(f"dofs: expected shape (ne, nd), found {dofs.shape}")
        if dofs.size and (dofs.min() < 0 or dofs.max() >= n):
            raise ValueError(f"dofs: expected values in [0, {n}), found [{dofs.min()}, {dofs.max()}]")
        self.dofs = dofs
        self.n = int(n)
        ne, nd = dofs.shape
        rows = np.broadcast_to(dofs[:, :, None], (ne, nd, nd)).ravel()
        cols = np.broadcast_to(dofs[:, None, :], (ne, nd, nd)).ravel()
        keys = rows * self.n + cols
        ukeys, inverse = np.unique(keys, return_inverse=True)
        self._inverse = inverse.astype(np.int32) if ukeys.size < 2**31 else inverse
        del inverse, keys
        self._indices = (ukeys % self.n).astype(np.int32 if self.n < 2**31 else np.int64)
        urows = ukeys // self.n
        self._indptr = np.zeros(self.n + 1, dtype=self._indices.dtype)
        np.cumsum(np.bincount(urows, minlength=self.n), out=self._indptr[1:])
        self.nnz = ukeys.size

    def vector(self, fe: np.ndarray) -> np.ndarray:
        """Sum element vectors ``fe`` (ne, nd) into a global vector (n,)."""
        return np.bincount(self.dofs.ravel(), weights=np.asarray(fe).ravel(), minlength=self.n)

    def matrix(self, Ke: np.ndarray) -> sp.csr_matrix:
        """Sum element matrices ``Ke`` (ne, nd, nd) into a global CSR matrix (n, n)."""
        data = np.bincount(self._inverse, weights=np.asarray(Ke).ravel(), minlength=self.nnz)
        return sp.csr_matrix((data, self._indices.copy(), self._indptr.copy()), shape=(self.n, self.n))
