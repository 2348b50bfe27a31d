"""Nodal reactions of the supports and their resultants.

At an equilibrium the reduced residual r = T^T (f_int - f_ext) vanishes on the free dofs; on
the constrained dofs it is the force the supports exert on the structure, R = f_int - f_ext,
in the local constraint basis of each node (:mod:`tmfem.fem.structure.supports`). Rotated
back (:meth:`tmfem.fem.constraints.ConstraintMap.independent`) it is a generalized nodal
force: global translations, global moments at 6-dof nodes and the moments (M_1, M_2) about
the current V_1, V_2 of a shell node, whose moment vector is M_1 V_1 + M_2 V_2 (a shell node
has no moment about its director). Free-body check: sum R + sum F = 0 and
sum (x - a) x R + M_R + (x - a) x F + M_F = 0 about any point a, with x the current
positions.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import State


def nodal_vectors(g: np.ndarray, state: State, dofmap: DofMap) -> tuple[np.ndarray, np.ndarray]:
    """Forces (3, n) and moment vectors (3, n) of a generalized nodal force g (ndof,): the
    translation components, the rotation components of 6-dof nodes, and M_1 V_1 + M_2 V_2 with
    the current triad of 5-dof nodes."""
    n = dofmap.n_nodes
    force = g[dofmap.translation_dofs(np.arange(n))].T.copy()
    moment = np.zeros((3, n))
    six = np.flatnonzero(dofmap.counts == 6)
    if six.size:
        moment[:, six] = g[dofmap.rotation_dofs(six)].T
    five = np.flatnonzero(dofmap.counts == 5)
    if five.size:
        V = np.einsum("nij,njk->nik", state.R[five], state.frames[five])
        m = g[dofmap.rotation_dofs(five)]
        moment[:, five] = (m[:, 0, None] * V[:, :, 0] + m[:, 1, None] * V[:, :, 1]).T
    return force, moment


@dataclass
class Reactions:
    """Reactions of the supports: force [N] and moment [N m] per node (3, n_nodes; zero at
    nodes without supports), in global axes or, with ``frame="local"``, in each node's local
    axes; ``x`` (3, n_nodes) the positions where they act."""

    force: np.ndarray
    moment: np.ndarray
    x: np.ndarray
    frame: str = "global"

    def resultant(self, nodes=None, *, about=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
        """Resultant force (3,) and moment (3,) about the point ``about`` of the reactions at
        ``nodes`` (default all): sum R and sum (x - a) x R + M_R (global axes only)."""
        from tmfem.errors import InputError
        if self.frame != "global":
            raise InputError("reactions: expected global components for a resultant, found local ones")
        sel = slice(None) if nodes is None else np.asarray(nodes)
        a = np.asarray(about, dtype=float).reshape(3, 1)
        F = self.force[:, sel]
        return F.sum(axis=1), (np.cross((self.x[:, sel] - a).T, F.T).sum(axis=0) + self.moment[:, sel].sum(axis=1))
