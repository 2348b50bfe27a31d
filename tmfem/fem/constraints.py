"""Linear multi-point constraints on a dof map: dependent translations and fixed dofs.

The independent (reduced) unknowns u_r map to all dofs by ``u = T u_r``. A *dependent* node
has translations that are a fixed weighted average of other nodes' translations (a point
attachment: one master of weight 1; a distributed one: the weights of an RBE3-type patch;
a pinned connection between a shell corner and a bar top: the bar top's translations
follow the corner, its rotations stay its own). Forces map back by ``T^T f`` and tangents by
``T^T K T`` (the constraint adds no stiffness). Fixed dofs are removed by the ``free`` mask
on the reduced dofs.

A block of independent dofs may be expressed in a local (skew) basis: ``u_block = Q u~``
with Q orthonormal, so that ``T = T_0 L`` with L block-diagonal, and a fixed dof of such a
block fixes its local component (a support along a skew direction, a symmetry plane).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.dofmap import DofMap


class ConstraintMap:
    """``u = T u_r`` with dependent translations; fixed dofs in ``free`` (module docstring).

    Build with :meth:`build`. Attributes: ``T`` (csr, ndof x n_red), ``free`` (bool, n_red),
    ``reduced_of`` (int, ndof: the reduced dof of each independent dof, -1 at dependent ones).
    """

    def __init__(self, T: sp.csr_matrix, free: np.ndarray, reduced_of: np.ndarray,
                 L: sp.csr_matrix | None = None):
        self.T = T.tocsr()
        self.free = np.asarray(free, dtype=bool)
        self.reduced_of = reduced_of
        self.L = L

    @classmethod
    def build(cls, dofmap: DofMap, *, dependent: Sequence[tuple[int, np.ndarray, np.ndarray]] = (),
              fixed_nodes=(), fixed_dofs=(),
              dependent_dofs: Sequence[tuple[int, np.ndarray, np.ndarray]] = (),
              bases: Sequence[tuple[np.ndarray, np.ndarray]] = ()) -> "ConstraintMap":
        """Constraint map of ``dofmap``.

        Parameters
        ----------
        dependent : sequence of (node, masters, weights)
            The translations of ``node`` are ``sum_i weights[i] x[masters[i]]``; weights
            should sum to 1 for the map to carry positions as well as increments.
        fixed_nodes : array_like of int
            Nodes whose translations are fixed (pinned).
        fixed_dofs : array_like of int
            Further fixed dofs (full numbering).
        dependent_dofs : sequence of (dof, master_dofs, weights)
            Single dofs (full numbering, any field) that are ``sum_i weights[i] u[master_dofs[i]]``
            of independent dofs: a linear multi-point constraint (e.g. the spin constraint
            of a pinned bar, :func:`tmfem.fem.beam.spin_constraint`).
        bases : sequence of (dofs, Q)
            Independent dofs (k,) (full numbering) expressed in a local orthonormal basis Q
            (k, k): ``u[dofs] = Q u~``. A fixed dof ``dofs[j]`` then fixes the local component
            ``u~_j``.
        """
        n = dofmap.ndof
        dep_nodes = np.array([d[0] for d in dependent], dtype=np.int64)
        if np.unique(dep_nodes).size != dep_nodes.size:
            raise InputError("constraints: expected each dependent node once, found repeats")
        dep_dofs = dofmap.translation_dofs(dep_nodes).ravel() if dep_nodes.size else np.zeros(0, np.int64)
        extra = np.array([int(d[0]) for d in dependent_dofs], dtype=np.int64)
        if extra.size and (np.unique(extra).size != extra.size or np.isin(extra, dep_dofs).any()
                           or extra.min() < 0 or extra.max() >= n):
            raise InputError(f"constraints: expected distinct dependent dofs in [0, {n}) outside the "
                             f"dependent nodes, found {extra.tolist()}")
        independent = np.ones(n, dtype=bool)
        independent[dep_dofs] = False
        independent[extra] = False
        reduced_of = np.full(n, -1, dtype=np.int64)
        reduced_of[independent] = np.arange(int(independent.sum()))
        rows = [np.flatnonzero(independent)]
        cols = [reduced_of[independent]]
        vals = [np.ones(int(independent.sum()))]
        for node, masters, w in dependent:
            masters = np.asarray(masters, dtype=np.int64)
            w = np.asarray(w, dtype=float)
            if masters.shape != w.shape or masters.size == 0:
                raise InputError(f"constraints: node {node}: expected as many weights as masters "
                                 f"(>= 1), found {masters.size} masters and {w.size} weights")
            if np.isin(masters, dep_nodes).any():
                raise InputError(f"constraints: node {node}: a master is itself dependent")
            md = dofmap.translation_dofs(masters)                    # (m, 3)
            nd = dofmap.translation_dofs([node])[0]                  # (3,)
            rows.append(np.repeat(nd[None, :], masters.size, axis=0).ravel())
            cols.append(reduced_of[md].ravel())
            vals.append(np.repeat(w, 3))
        for dof, masters, w in dependent_dofs:
            masters = np.asarray(masters, dtype=np.int64)
            w = np.asarray(w, dtype=float)
            if masters.shape != w.shape or masters.size == 0 or not independent[masters].all():
                raise InputError(f"constraints: dof {dof}: expected as many weights as independent "
                                 f"master dofs (>= 1), found {masters.size} masters "
                                 f"({int(np.sum(~independent[masters]))} dependent) and {w.size} weights")
            rows.append(np.full(masters.size, int(dof)))
            cols.append(reduced_of[masters])
            vals.append(w)
        nr = int(independent.sum())
        T = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n, nr))
        L = None
        if len(bases):
            L = _local_bases(bases, reduced_of, nr)
            T = (T @ L).tocsr()
        fixed = list(np.asarray(fixed_dofs, dtype=np.int64).ravel())
        fn = np.asarray(fixed_nodes, dtype=np.int64).ravel()
        if fn.size:
            fixed += list(dofmap.translation_dofs(fn).ravel())
        fixed = np.asarray(fixed, dtype=np.int64)
        if fixed.size and np.any(reduced_of[fixed] < 0):
            raise InputError("constraints: a fixed dof belongs to a dependent node (fix its masters)")
        free = np.ones(T.shape[1], dtype=bool)
        free[reduced_of[fixed]] = False
        return cls(T, free, reduced_of, L)

    @property
    def n_reduced(self) -> int:
        return int(self.T.shape[1])

    def full(self, u_r: np.ndarray) -> np.ndarray:
        """All dofs (ndof,) from the reduced ones."""
        return self.T @ u_r

    def reduce(self, u: np.ndarray) -> np.ndarray:
        """Reduced dofs of a full vector that satisfies the constraints (its independent entries)."""
        keep = self.reduced_of >= 0
        out = np.empty(self.n_reduced)
        out[self.reduced_of[keep]] = np.asarray(u)[keep]
        return out if self.L is None else self.L.T @ out

    def independent(self, v_r: np.ndarray) -> np.ndarray:
        """A full vector (ndof,) that holds the reduced vector ``v_r`` at the independent dofs
        (rotated back from the local bases) and zero at the dependent ones: the reduced
        residual at the fixed dofs becomes the nodal reactions of the supports."""
        v = np.asarray(v_r, dtype=float) if self.L is None else self.L @ v_r
        out = np.zeros(self.reduced_of.size)
        keep = self.reduced_of >= 0
        out[keep] = v[self.reduced_of[keep]]
        return out

    def residual(self, f: np.ndarray) -> np.ndarray:
        """Reduced force T^T f."""
        return self.T.T @ f

    def tangent(self, K: sp.spmatrix) -> sp.csr_matrix:
        """Reduced tangent T^T K T."""
        return (self.T.T @ K @ self.T).tocsr()


def _local_bases(bases, reduced_of: np.ndarray, nr: int) -> sp.csr_matrix:
    """Block-diagonal L (nr, nr): identity, with the blocks Q of ``bases`` (module docstring)."""
    rows, cols, vals = [], [], []
    inside = np.zeros(nr, dtype=bool)
    for dofs, Q in bases:
        dofs = np.asarray(dofs, dtype=np.int64)
        Q = np.asarray(Q, dtype=float)
        r = reduced_of[dofs]
        if Q.shape != (dofs.size, dofs.size) or np.any(r < 0) or inside[r].any():
            raise InputError(f"constraints: expected a local basis ({dofs.size} x {dofs.size}) on "
                             f"independent dofs given once, found shape {Q.shape} on dofs {dofs.tolist()}")
        if not np.allclose(Q.T @ Q, np.eye(dofs.size), atol=1e-10):
            raise InputError(f"constraints: expected an orthonormal local basis on dofs {dofs.tolist()}")
        inside[r] = True
        rows.append(np.repeat(r, r.size))
        cols.append(np.tile(r, r.size))
        vals.append(Q.ravel())
    rest = np.flatnonzero(~inside)
    rows.append(rest)
    cols.append(rest)
    vals.append(np.ones(rest.size))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(nr, nr))
