"""Element sets assembled rank by rank into one distributed tangent (``mpiexec -n P``, PETSc).

The finite-element side of :mod:`tmfem.solvers.distributed`: a model's element sets (the
interface of :mod:`tmfem.fem.element`) on the unknowns u = (T u_r)[free] of its constraint
map, with

* the internal force r = (T^T f)[free] (eqs. 4.4-4.6) on every rank, summed over the ranks'
  contributions;
* the tangent (T^T K T)[free][:, free] as one parallel PETSc matrix, preallocated once from
  the union of the ranks' patterns (:class:`~tmfem.solvers.distributed.DistributedAssembler`);
* the strain energy summed over the ranks, and the mass matrix.

How an element set is shared out over the ranks:

* sets that provide the *share protocol* -- ``element_dofs`` (ne, nd) and
  ``element_arrays(state, tangent=, elements=slice)``, ``energy(state, elements=slice)``
  and, optionally, ``element_mass(state, elements=slice)`` (the membrane, the MITC4 shells,
  the trusses) -- evaluate only the contiguous block of elements of this rank
  (:func:`~tmfem.solvers.distributed.element_share`): the kernel work, the element arrays
  and the matrix entries are split P ways;
* any other set (the beams: a few hundred elements) is evaluated whole on every rank, and
  each rank contributes its block of the entries of its assembled tangent (the set's CSR
  pattern is fixed) and, on rank 0, its force and energy.

Every rank holds the full state (vectors are replicated, O(n) per rank). A tangent that a
caller still references is never refilled (:meth:`DistributedElements.residual` reuses an
unreferenced one, else assembles a new one): a solver that holds the tangent of its iterate
while it evaluates trial points has two; the SNES statics let go of each tangent before the
next evaluation (:mod:`tmfem.solvers.petsc_snes`), so one serves the whole solve.
"""
from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.solvers.distributed import DistributedAssembler, comm_world, element_share
from tmfem.solvers.eigen import lowest_modes


def for_backend(backend, elements, state0, T, free):
    """The :class:`DistributedElements` of a model's element sets when ``backend``
    assembles distributed matrices (``backend.distributed_assembly``: PETSc, on one rank
    or under ``mpiexec``), else None (the model assembles scipy matrices)."""
    if not getattr(backend, "distributed_assembly", False):
        return None
    release = getattr(backend, "release_retired", None)
    if release is not None:
        release()                   # the factors of a model gone (a coarse level) go first
    return DistributedElements(elements, state0, T, free)


def _shares(e) -> bool:
    """Whether element set ``e`` provides the share protocol (module docstring)."""
    return hasattr(e, "element_dofs") and hasattr(e, "element_arrays")


class DistributedElements:
    """Residual, tangent, energy and mass of element sets on the free dofs, rank by rank.

    Parameters
    ----------
    elements : list of element sets on one dof map (n full dofs)
    state0 : State
        A state at which the pattern of the tangent of every set is the one of all states
        (any state: the kernels keep their patterns).
    T : sparse (n, n_r)
        Constraint map u = T u_r.
    free : bool mask (n_r,)
        The unknowns.
    comm : mpi4py communicator, optional (COMM_WORLD)
    """

    def __init__(self, elements, state0, T, free, *, comm=None):
        self.comm = comm_world() if comm is None else comm
        self.elements = list(elements)
        self.n = self.elements[0].dofmap.ndof
        self.T, self.free = sp.csr_matrix(T), np.asarray(free, bool)
        self.root = self.comm.rank == 0
        groups, self._shares, self._entries, self._dofs = [], [], [], []
        for e in self.elements:
            if _shares(e):
                dofs = np.asarray(e.element_dofs)
                share = element_share(dofs.shape[0], self.comm)
                mine = dofs[share].copy()          # this rank's elements only are kept
                del dofs
                groups.append((mine, "element"))
                self._shares.append(share)
                self._entries.append(None)
                self._dofs.append(mine)
            else:
                K0 = _structure(e.internal(state0, tangent=True)[1])
                share = element_share(K0.nnz, self.comm)
                rows = np.repeat(np.arange(self.n), np.diff(K0.indptr))
                groups.append((np.stack([rows[share], K0.indices[share]], axis=1), "entry"))
                self._shares.append(share)
                self._entries.append((K0.indptr.copy(), K0.indices.copy()))
                self._dofs.append(None)
        self.assembler = DistributedAssembler(groups, self.n, T=self.T, keep=self.free,
                                              comm=self.comm)
        self._K = []
        self._M = None

    @property
    def N(self) -> int:
        """Number of unknowns (free dofs)."""
        return self.assembler.N

    def residual(self, state, *, tangent: bool = True, symmetric: bool = False):
        """``(r, K)``: this rank's rows (those of its matrix rows) of the internal force on
        the free dofs, and the tangent (a
        :class:`~tmfem.solvers.distributed.DistributedMatrix`, refilled in a later call only
        once the caller has dropped it), eqs. 4.4-4.6. ``symmetric``: the
        symmetric part (K + K^T) / 2 of the tangent instead (assembled from the symmetric
        parts of the element matrices: T^T K T commutes with the transposition), for the
        modes about a state of a tangent that is symmetric only at equilibrium (finite
        rotations)."""
        f = np.zeros(self.n)
        values = []
        for e, share, entries, dofs in zip(self.elements, self._shares, self._entries, self._dofs):
            if entries is None:
                fe, Ke = e.element_arrays(state, tangent=tangent, elements=share)
                f += np.bincount(dofs.ravel(), weights=fe.ravel(), minlength=self.n)
                if tangent and symmetric:
                    Ke = 0.5 * (Ke + np.swapaxes(Ke, 1, 2))
                values.append(Ke)
            else:
                fs, Ks = e.internal(state, tangent=tangent)
                if self.root:
                    f += fs
                if tangent:
                    Ks = sp.csr_matrix(Ks)
                    if symmetric:
                        Ks = sp.csr_matrix(0.5 * (Ks + Ks.T))
                    Ks.sort_indices()
                    if not (np.array_equal(Ks.indptr, entries[0])
                            and np.array_equal(Ks.indices, entries[1])):
                        Ks = _on_pattern(Ks, *entries)
                    values.append(Ks.data[share])
        r = self.assembler.vector(f)
        if not tangent:
            return r, None
        # a tangent the caller still holds (the iterate's, while it evaluates trial points)
        # is never overwritten: refill one that nobody references, else assemble a new one
        free = self._unreferenced_tangents()
        if free:
            return r, self.assembler.matrix(*values, out=self._K[free[0]])
        K = self.assembler.matrix(*values)
        self._K.append(K)
        return r, K

    def _unreferenced_tangents(self) -> list[int]:
        """Indices of the kept tangents that nothing references on any rank. Collective:
        whether a rank still references one (a frame or traceback kept alive, an object in
        a reference cycle the garbage collector has not reached yet) differs between ranks,
        and refilling a tangent on one rank while another assembles a new one are different
        collective calls."""
        free = [sys.getrefcount(K) <= 3 for K in self._K]   # the list's, the loop's, the argument's
        if self.comm.size > 1:
            free = [all(column) for column in zip(*self.comm.allgather(free))]
        return [i for i, f in enumerate(free) if f]

    def release(self) -> None:
        """Free the PETSc matrices (tangents, mass) and work vectors assembled here
        (petsc4py 3.18 frees a PETSc object on ``destroy()`` only, not when it is garbage
        collected): for a model that is done, such as a coarse level of a mesh sequencing.
        Collective (every rank calls it at the same point); the matrices are unusable after."""
        for D in self._K + ([self._M] if self._M is not None else []):
            D.destroy()
        self._K, self._M = [], None

    def energy(self, state) -> float:
        """Strain energy [J] of all sets, summed over the ranks (the same on every rank)."""
        local = 0.0
        for e, share, entries in zip(self.elements, self._shares, self._entries):
            if entries is None:
                local += e.energy(state, elements=share)
            elif self.root:
                local += e.energy(state)
        return float(self.comm.allreduce(local))

    def mass(self, state=None):
        """Mass matrix (T^T M T)[free][:, free] (a DistributedMatrix) at ``state``: the
        rotary inertia of shells and beams turns with their triads (the sets' ``mass(state)``
        of :mod:`tmfem.fem.element`). The reference mass (``state`` None) is assembled once
        and kept (freed by :meth:`release`); a mass at a state is a new matrix each call, which
        the caller destroys (``destroy()``: petsc4py frees a matrix on it only).

        Sets that provide ``element_mass(state, elements=slice)`` (element mass matrices
        (ne, nd, nd) of a block, like ``element_arrays``: the membrane, the shells, the
        trusses) contribute each rank's element masses (no full mass matrix on any rank),
        their entries where any element of the share has one (the membrane's node blocks
        are diagonal: 48 of 144); the other sets (the beams, evaluated whole on every rank
        as in :meth:`residual`) this rank's share of the entries of their assembled mass."""
        if state is None and self._M is not None:
            return self._M
        groups, values = [], []
        for e, entries, dofs, share in zip(self.elements, self._entries, self._dofs, self._shares):
            if entries is None and hasattr(e, "element_mass"):
                Me = np.asarray(e.element_mass(state, elements=share))
                I, J = np.nonzero(np.any(Me != 0.0, axis=0))
                groups.append((np.stack([dofs[:, I].ravel(), dofs[:, J].ravel()], axis=1), "entry"))
                values.append(Me[:, I, J].ravel())
            else:
                rows, cols, data = self._entry_share(e.mass(state))
                groups.append((np.stack([rows, cols], axis=1), "entry"))
                values.append(data)
        Md = DistributedAssembler(groups, self.n, T=self.T, keep=self.free,
                                  comm=self.comm).matrix(*values)
        if state is None:
            self._M = Md
        return Md

    def _entry_share(self, M):
        """(rows, cols, values) of this rank's share of the entries of a full matrix (n, n)."""
        M = sp.csr_matrix(M)
        M.sort_indices()
        rows = np.repeat(np.arange(self.n), np.diff(M.indptr))
        share = element_share(M.nnz, self.comm)
        return rows[share], M.indices[share], M.data[share]

    def modes(self, K, M, *, k: int, sigma: float, backend):
        """The k lowest modes of (M omega^2 - K) phi = 0 (eq. 5.32) of a distributed tangent
        K and mass M on the free dofs (:func:`tmfem.solvers.eigen.lowest_modes`), the
        shapes on all reduced dofs (n_r, k), zero at the fixed ones."""
        modes = lowest_modes(K, M, k=k, sigma=sigma, backend=backend)
        shapes = np.zeros((self.free.size, modes.shapes.shape[1]))
        shapes[self.free] = modes.shapes
        return replace(modes, shapes=shapes)


def _structure(K) -> sp.csr_matrix:
    """A CSR matrix on the union of the patterns of K and K^T (sorted; the values do not
    matter): the fixed pattern of a set's tangent and of its symmetric part."""
    K = sp.csr_matrix(K)
    B = sp.csr_matrix((np.ones(K.nnz), K.indices, K.indptr), shape=K.shape)
    S = sp.csr_matrix(B + B.T)
    S.sort_indices()
    return S


def _on_pattern(K: sp.csr_matrix, indptr, indices) -> sp.csr_matrix:
    """K on the sparsity pattern (indptr, indices) (the set's pattern at the state the
    assembler was built at; zeros where K has no entry); an entry of K outside it is refused."""
    n = K.shape[1]
    keys = np.repeat(np.arange(K.shape[0]), np.diff(indptr)) * n + indices
    kk = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr)) * n + K.indices
    pos = np.minimum(np.searchsorted(keys, kk), max(keys.size - 1, 0))
    if kk.size and (keys.size == 0 or np.any(keys[pos] != kk)):
        raise InputError(f"distributed assembly: expected the tangent of an element set on its "
                         f"pattern of {indices.size} entries, found entries outside it")
    data = np.zeros(indices.size)
    np.add.at(data, pos, K.data)
    return sp.csr_matrix((data, indices, indptr), shape=K.shape)
