"""The element interface: what every finite element of tmfem provides, and the nodal state.

An element set (a :class:`Element`) acts on the global dofs of a :class:`~tmfem.fem.dofmap.DofMap`
and returns, for a :class:`State`,

``internal(state, tangent=True) -> (f, K)``   internal force (ndof,) and tangent (csr) of
                                              eqs. 4.4-4.6 in the global numbering;
``energy(state) -> float``                    strain energy [J] (the potential of eq. 4.9);
``mass(state=None) -> csr``                    mass matrix (ndof, ndof) at ``state`` (the
                                              rotary inertia of shells and beams turns with
                                              their triads; the reference by default; the
                                              same at every state for translations only).

The truss (:class:`tmfem.fem.truss.TrussElement`) and the membrane
(:class:`tmfem.fem.membrane.MembraneElement`) implement it; the MITC4 shell and the beam
element do too. A model sums its element sets with :func:`assemble`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, Sequence

import numpy as np
import scipy.sparse as sp
from scipy.spatial.transform import Rotation

from tmfem.errors import InputError
from tmfem.fem.dofmap import DofMap


@dataclass
class State:
    """Current configuration of the nodes of a :class:`DofMap`.

    Attributes
    ----------
    x : ndarray (3, n_nodes)
        Current positions.
    R : ndarray (n_nodes, 3, 3) or None
        Rotation of each node's triad from its reference orientation (identity where a node
        has no rotations). None for a model of translational nodes only.

    Rotations are not additive: :meth:`advanced` applies a rotational increment theta of a
    node as ``R <- exp(skew(theta)) R`` (the exponential map, a finite rotation; eq. 4.16's
    directors are the columns of R times the reference directors). For a 5-dof (shell)
    node the two rotation dofs are the components along the current V1, V2 axes, i.e. the
    first two columns of ``R @ V0`` with V0 the reference triad (:attr:`frames`).
    """

    x: np.ndarray
    R: np.ndarray | None = None
    frames: np.ndarray | None = None

    @classmethod
    def reference(cls, X: np.ndarray, dofmap: DofMap, *, frames: np.ndarray | None = None) -> "State":
        """The undeformed state at positions X (3, n_nodes): identity rotations at rotational
        nodes. ``frames`` (n_nodes, 3, 3): reference triads [V1 V2 Vn] as columns (needed by
        5-dof nodes, whose two rotations are about V1 and V2)."""
        X = np.asarray(X, dtype=float)
        if X.shape != (3, dofmap.n_nodes):
            raise InputError(f"state: expected positions of shape (3, {dofmap.n_nodes}), found {X.shape}")
        if dofmap.translational_only:
            return cls(x=X.copy())
        R = np.broadcast_to(np.eye(3), (dofmap.n_nodes, 3, 3)).copy()
        if np.any(dofmap.counts == 5) and frames is None:
            raise InputError("state: 5-dof (shell) nodes need reference frames [V1 V2 Vn]")
        return cls(x=X.copy(), R=R, frames=None if frames is None else np.asarray(frames, float))

    def advanced(self, du: np.ndarray, dofmap: DofMap) -> "State":
        """The state after the increment du (ndof,): translations added, rotations composed
        by the exponential map (Rodrigues' formula, via ``scipy.spatial.transform``)."""
        du = np.asarray(du, dtype=float)
        if du.shape != (dofmap.ndof,):
            raise InputError(f"state: expected an increment of {dofmap.ndof} dofs, found {du.shape}")
        x = self.x + du[dofmap.translation_dofs(np.arange(dofmap.n_nodes))].T
        if self.R is None:
            return State(x=x)
        R = self.R.copy()
        for n_rot in (2, 3):
            nodes = np.flatnonzero(dofmap.counts == 3 + n_rot)
            if nodes.size == 0:
                continue
            a = du[dofmap.rotation_dofs(nodes)]                      # (n, n_rot)
            if n_rot == 3:
                theta = a
            else:                                                    # about the current V1, V2
                V = np.einsum("nij,njk->nik", R[nodes], self.frames[nodes])
                theta = a[:, 0, None] * V[:, :, 0] + a[:, 1, None] * V[:, :, 1]
            R[nodes] = np.einsum("nij,njk->nik", Rotation.from_rotvec(theta).as_matrix(), R[nodes])
        return State(x=x, R=R, frames=self.frames)


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrices: ``skew(v) @ w = v x w`` for v (..., 3) -> (..., 3, 3) (the
    spin of a rotation increment, eqs. 4.16 and 4.22)."""
    v = np.asarray(v, dtype=float)
    S = np.zeros(v.shape + (3,))
    S[..., 0, 1], S[..., 0, 2] = -v[..., 2], v[..., 1]
    S[..., 1, 0], S[..., 1, 2] = v[..., 2], -v[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -v[..., 1], v[..., 0]
    return S


def smallest_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotations (n, 3, 3) turning the directions a (3, n) onto b (3, n) about a x b by the
    angle between them (identity for parallel directions): e.g. a shell director onto the
    normal of a deformed surface."""
    a = np.asarray(a, dtype=float) / np.linalg.norm(a, axis=0)
    b = np.asarray(b, dtype=float) / np.linalg.norm(b, axis=0)
    axis = np.cross(a, b, axis=0)
    sn = np.linalg.norm(axis, axis=0)
    ang = np.arctan2(sn, np.einsum("in,in->n", a, b))
    rv = np.where(sn > 0, axis / np.where(sn > 0, sn, 1.0) * ang, 0.0)
    return Rotation.from_rotvec(rv.T).as_matrix()


class Element(Protocol):
    """A set of elements of one kind on the global dofs of a :class:`DofMap` (module docstring)."""

    dofmap: DofMap

    def internal(self, state: State, *, tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix | None]: ...

    def energy(self, state: State) -> float: ...

    def mass(self, state: State | None = None) -> sp.csr_matrix: ...


def assemble(elements: Sequence[Element], state: State, *, tangent: bool = True):
    """Sum of the internal forces (ndof,) and tangents (csr or None) of element sets that
    share one dof map (eq. 4.4 summed over the element kinds)."""
    if not elements:
        raise InputError("assemble: expected at least one element set, found none")
    n = elements[0].dofmap.ndof
    f = np.zeros(n)
    K = None
    for e in elements:
        if e.dofmap.ndof != n:
            raise InputError(f"assemble: expected element sets on one dof map of {n} dofs, found "
                             f"one with {e.dofmap.ndof}")
        fe, Ke = e.internal(state, tangent=tangent)
        f += fe
        if tangent:
            K = Ke if K is None else K + Ke
    return f, K
