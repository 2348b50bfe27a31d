"""Degrees of freedom with per-node fields: translations everywhere, rotations where needed.

Every node carries three translational dofs; a node of a shell carries two more (the
rotations about its director's V1, V2 axes, eq. 4.16), a node of a beam three more (eq.
4.19). The numbering is node-interleaved: the dofs of node ``n`` are
``offset[n] .. offset[n + 1] - 1``, its translations first, so a model of 3-dof nodes only
numbers dof = 3 node + component as every tmfem kernel did before rotations existed.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError

#: the dof counts a node may have: translations only, shell (2 rotations), beam (3 rotations)
NODE_DOFS = (3, 5, 6)


class DofMap:
    """Global dof numbering of ``n_nodes`` nodes with ``counts[n]`` dofs each.

    Parameters
    ----------
    counts : array_like of int (n_nodes,)
        Dofs of each node, each one of :data:`NODE_DOFS`: 3 (translations), 5 (translations
        and two director rotations), 6 (translations and three rotations).

    Attributes
    ----------
    offset : ndarray (n_nodes + 1,)
        First global dof of each node; ``offset[-1]`` is the number of dofs.
    """

    def __init__(self, counts):
        counts = np.asarray(counts, dtype=np.int64)
        if counts.ndim != 1:
            raise InputError(f"dof map: expected one dof count per node, found shape {counts.shape}")
        bad = ~np.isin(counts, NODE_DOFS)
        if bad.any():
            raise InputError(f"dof map: expected node dof counts in {NODE_DOFS}, found "
                             f"{counts[bad][:5].tolist()} at nodes {np.flatnonzero(bad)[:5].tolist()}")
        self.counts = counts
        self.offset = np.concatenate([[0], np.cumsum(counts)])

    @classmethod
    def translations(cls, n_nodes: int) -> "DofMap":
        """``n_nodes`` nodes with three translational dofs each."""
        return cls(np.full(int(n_nodes), 3))

    @property
    def n_nodes(self) -> int:
        return int(self.counts.size)

    @property
    def ndof(self) -> int:
        return int(self.offset[-1])

    @property
    def translational_only(self) -> bool:
        """True when no node carries rotations (dof = 3 node + component)."""
        return bool(np.all(self.counts == 3))

    def translation_dofs(self, nodes) -> np.ndarray:
        """Global dofs (len(nodes), 3) of the translations of ``nodes``."""
        nodes = self._nodes(nodes)
        return self.offset[nodes][:, None] + np.arange(3)[None, :]

    def rotation_dofs(self, nodes) -> np.ndarray:
        """Global dofs (len(nodes), n_rot) of the rotations of ``nodes`` (all with the same
        number n_rot of rotations)."""
        nodes = self._nodes(nodes)
        n_rot = np.unique(self.counts[nodes] - 3)
        if n_rot.size != 1 or n_rot[0] == 0:
            raise InputError(f"dof map: expected nodes with one common number of rotations, found "
                             f"rotation counts {n_rot.tolist()}")
        return self.offset[nodes][:, None] + 3 + np.arange(int(n_rot[0]))[None, :]

    def node_dofs(self, nodes) -> np.ndarray:
        """Global dofs (len(nodes), count) of all fields of ``nodes`` (one common count)."""
        nodes = self._nodes(nodes)
        c = np.unique(self.counts[nodes])
        if c.size != 1:
            raise InputError(f"dof map: expected nodes with one common dof count, found {c.tolist()}")
        return self.offset[nodes][:, None] + np.arange(int(c[0]))[None, :]

    def element_dofs(self, conn, *, rotations: bool = False) -> np.ndarray:
        """Global dofs (ne, nen * ncomp) of elements with node connectivity ``conn`` (nen, ne),
        node by node: the translations (``rotations=False``; the truss and membrane kernels) or
        all dofs of each node (``rotations=True``; shells and beams)."""
        conn = np.asarray(conn, dtype=np.int64)
        if conn.ndim != 2:
            raise InputError(f"dof map: expected connectivity of shape (nen, ne), found {conn.shape}")
        pick = self.node_dofs if rotations else self.translation_dofs
        d = pick(conn.T.ravel())
        return d.reshape(conn.shape[1], -1)

    def check_element_nodes(self, conn, count: int, *, element: str, dofs: str) -> None:
        """Refuse an element connectivity ``conn`` whose nodes are out of range or do not carry
        ``count`` dofs each (``dofs`` names them in the message, e.g. "six dofs")."""
        conn = np.asarray(conn)
        if conn.size and (conn.min() < 0 or conn.max() >= self.n_nodes):
            raise InputError(f"{element}: expected node indices in [0, {self.n_nodes}), found "
                             f"[{conn.min()}, {conn.max()}]")
        nodes = np.unique(conn)
        bad = nodes[self.counts[nodes] != count]
        if bad.size:
            raise InputError(f"{element}: expected {dofs} at every {element} node, found "
                             f"{self.counts[bad[:5]].tolist()} at nodes {bad[:5].tolist()}")

    def translation_mask(self) -> np.ndarray:
        """Boolean (ndof,): True at translational dofs."""
        m = np.zeros(self.ndof, dtype=bool)
        m[self.translation_dofs(np.arange(self.n_nodes)).ravel()] = True
        return m

    def _nodes(self, nodes) -> np.ndarray:
        nodes = np.asarray(nodes, dtype=np.int64).ravel()
        if nodes.size and (nodes.min() < 0 or nodes.max() >= self.n_nodes):
            raise InputError(f"dof map: expected node indices in [0, {self.n_nodes}), found "
                             f"[{nodes.min()}, {nodes.max()}]")
        return nodes

    def __repr__(self) -> str:
        kinds = {c: int(np.sum(self.counts == c)) for c in NODE_DOFS if np.any(self.counts == c)}
        return f"DofMap({self.n_nodes} nodes, {self.ndof} dofs, nodes by dof count {kinds})"
