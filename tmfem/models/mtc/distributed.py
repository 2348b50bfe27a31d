"""The MTC model on the distributed assembly of the PETSc backend (``mpiexec -n P``).

Every rank builds the same :class:`~tmfem.models.mtc.model.MTCModel` (meshing is
deterministic) and assembles its share (:func:`tmfem.solvers.distributed.element_share`) of
the membrane elements and of the truss entries into one parallel PETSc matrix through the
model's constraint map (T^T K T on the free dofs); residuals are summed over the ranks.
The unknowns are the free independent positions ``u = xr[free]``, so that
:func:`tmfem.solvers.newton` (with ``free=None``) and the backend's ``eigsh`` work on them
unchanged.

Limitation: the membrane kernel still evaluates all elements on every rank before the
rank keeps its share (the kernel has no element-subset argument yet); assembly, matrix
storage and factorisation are distributed.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from tmfem.fem.element import State
from tmfem.solvers.distributed import DistributedAssembler, element_share


class DistributedMTC:
    """Residual, tangent and mass of ``model`` on the free dofs, assembled rank by rank.

    Parameters
    ----------
    model : MTCModel
    comm : mpi4py communicator, optional (COMM_WORLD)
    """

    def __init__(self, model, *, comm=None):
        from tmfem.solvers.distributed import comm_world
        self.model = model
        self.comm = comm_world() if comm is None else comm
        topo = model.topology
        n = topo.dofmap.ndof
        self.n_full = n
        T, free = topo.constraints.T, model.free
        mem = model.membrane_element
        self._mshare = element_share(mem.element_dofs.shape[0], self.comm)
        self.membrane = DistributedAssembler(mem.element_dofs[self._mshare], n, T=T, keep=free,
                                             comm=self.comm)
        # trusses (bars, tendons: a few hundred elements): the entries of their assembled
        # tangents (a fixed CSR pattern per set) are shared out as (row, column) pairs
        self._truss_sets = (model.bar_element, model.tendon_element)
        x0 = model.initial_positions("design")
        self.trusses, self._tshares = [], []
        for e in self._truss_sets:
            K0 = e.internal(State(x=x0), tangent=True)[1]
            rows = np.repeat(np.arange(n), np.diff(K0.indptr))
            share = element_share(K0.nnz, self.comm)
            pairs = np.stack([rows, K0.indices], axis=1)[share]
            self.trusses.append(DistributedAssembler(pairs, n, T=T, keep=free, comm=self.comm))
            self._tshares.append(share)
        self._vshare = element_share(n, self.comm)
        self.vectors = DistributedAssembler(np.arange(n)[self._vshare, None], n, T=T, keep=free,
                                            comm=self.comm)
        self.xr0 = None
        self._parts, self._sum = [], None

    @property
    def N(self) -> int:
        """Number of unknowns (free dofs)."""
        return self.membrane.N

    def unknowns(self, xr: np.ndarray) -> np.ndarray:
        """Free dofs u of independent positions xr (and xr kept for the fixed dofs)."""
        self.xr0 = np.array(xr, dtype=float)
        return self.xr0[self.model.free].copy()

    def positions(self, u: np.ndarray) -> np.ndarray:
        """Independent positions xr of the unknowns u."""
        xr = self.xr0.copy()
        xr[self.model.free] = u
        return xr

    def residual(self, u: np.ndarray):
        """``(r, K)``: reduced internal force on the free dofs (N,) on every rank and the
        tangent (a DistributedMatrix), eqs. 4.4-4.6."""
        model = self.model
        x = model.full(self.positions(u))
        fm, Km = model.membrane.element_arrays(x[:, model.membrane_element.nodes], tangent=True)
        r = self.membrane.vector(fm[self._mshare])
        parts = [self.membrane.matrix(Km[self._mshare], out=self._parts[0] if self._parts else None)]
        for i, (e, asm, share) in enumerate(zip(self._truss_sets, self.trusses, self._tshares)):
            f, K = e.internal(State(x=x), tangent=True)
            r = r + self.vectors.vector(f[self._vshare, None])
            Ke = np.zeros((share.stop - share.start, 2, 2))
            Ke[:, 0, 1] = K.data[share]
            parts.append(asm.matrix(Ke, out=self._parts[i + 1] if self._parts else None))
        self._parts = parts
        # the parts have different patterns: sum them in PETSc (the union pattern is fixed at
        # the first call, later sums reuse it)
        from petsc4py import PETSc
        from tmfem.solvers.distributed import DistributedMatrix
        S = PETSc.Mat.Structure
        if self._sum is None:
            mat = parts[0].mat.duplicate(copy=True)
            for p in parts[1:]:
                mat.axpy(1.0, p.mat, structure=S.DIFFERENT_NONZERO_PATTERN)
            self._sum = DistributedMatrix(mat, object(), parts[0].shape)
        else:
            self._sum.mat.zeroEntries()
            for p in parts:
                self._sum.mat.axpy(1.0, p.mat, structure=S.SUBSET_NONZERO_PATTERN)
            self._sum.version += 1
        return r, self._sum

    def mass(self):
        """Mass matrix on the free dofs (a DistributedMatrix), from the model's element masses."""
        M = sp.csr_matrix(sum(e.mass() for e in self.model.elements))
        M.sort_indices()
        rows = np.repeat(np.arange(self.n_full), np.diff(M.indptr))
        share = element_share(M.nnz, self.comm)
        asm = DistributedAssembler(np.stack([rows, M.indices], axis=1)[share], self.n_full,
                                   T=self.model.topology.T, keep=self.model.free, comm=self.comm)
        Me = np.zeros((share.stop - share.start, 2, 2))
        Me[:, 0, 1] = M.data[share]
        return asm.matrix(Me)
