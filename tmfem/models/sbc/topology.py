"""Node numbering of the shell-beam-cable model (dissertation 4.3, 6.2).

The SBC model numbers its nodes as the MTC model does (:mod:`tmfem.models.fe.topology`) and
appends the interior nodes of the bars:

* ``0 .. nm-1``           membrane nodes, 5 dofs each (MITC4 shell: 3 translations, 2
                          rotations about V_1, V_2);
* ``nm .. nm+ns-1``       the labelled system nodes A_ij, B_ij (bar ends), 6 dofs each (beam);
* then                    the tendon internal nodes, 3 dofs each;
* then                    the bar interior nodes, ``3 e - 1`` per bar for ``e`` four-node
                          beam elements per bar, 6 dofs each.

A 1-N(D) system's point H_1j on bar j (at k_H of its length) is a node of the bar: the bar is
two segments A_1j-H_1j and H_1j-B_1j of ``e`` elements each (``2 e`` per bar, ``2 (3 e - 1)``
interior nodes), so the tendon forces at H_1j and the kink of the bending moment there are
represented exactly.

Only the numbering lives here; the constraints (pinned bases, bar tops pinned to the membrane
corners, the bars' spin) are built by :class:`tmfem.models.sbc.model.SBCModel`, which needs the
beam element for the spin constraint.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError
from tmfem.fem.dofmap import DofMap


@dataclass(frozen=True)
class SBCNumbering:
    """Dof counts and bar chains of an SBC model.

    Attributes
    ----------
    dofmap : DofMap
    bar_chain : ndarray (n_bars, 3 e + 1)
        Nodes of each bar from A_ij to B_ij (``system.bar_connectivity`` order).
    beam_conn : ndarray (4, n_bars e)
        Four-node beam elements, bar-major.
    n_mtc_nodes : int
        Nodes shared with the MTC numbering (membrane, system labels, tendon internals).
    bar_elements : int
        Four-node beam elements per bar (``2 e`` when the bars carry points H_1j).
    chain_s : ndarray (3 bar_elements + 1,)
        Fraction of the bar length from A_ij of every chain node (straight bar, equally
        spaced nodes within each segment).
    """

    dofmap: DofMap
    bar_chain: np.ndarray
    beam_conn: np.ndarray
    n_mtc_nodes: int
    bar_elements: int
    chain_s: np.ndarray


def number_sbc(mtc_topology, bar_connectivity: np.ndarray, *, bar_elements: int,
               bar_points: np.ndarray | None = None, k_point: float | None = None) -> SBCNumbering:
    """Append the bar interior nodes to the MTC numbering ``mtc_topology`` (module docstring).

    Parameters
    ----------
    mtc_topology : MTCTopology
    bar_connectivity : ndarray (2, n_bars)
        Global nodes (A, B) of each bar in the MTC numbering (``mtc_topology.bar_conn``).
    bar_elements : int
        Four-node beam elements per bar, or per bar segment with ``bar_points`` (6.2: 1).
    bar_points : ndarray (n_bars,), optional
        Global node of the point H_1j of each bar (1-N(D) systems), at the fraction
        ``k_point`` (k_H) of the bar length from A.
    """
    if not (isinstance(bar_elements, (int, np.integer)) and bar_elements >= 1):
        raise InputError(f"bar_elements: expected an integer >= 1, found {bar_elements!r}")
    e = int(bar_elements)
    n0 = mtc_topology.n_nodes
    nb = bar_connectivity.shape[1]
    A, B = bar_connectivity[0][:, None], bar_connectivity[1][:, None]
    if bar_points is None:
        interior = n0 + np.arange(nb * (3 * e - 1)).reshape(nb, 3 * e - 1)
        chain = np.concatenate([A, interior, B], axis=1)
        s = np.linspace(0.0, 1.0, 3 * e + 1)
    else:
        if not (k_point is not None and 0.0 < k_point < 1.0):
            raise InputError(f"bar points: expected 0 < k_H < 1, found {k_point!r}")
        interior = n0 + np.arange(nb * 2 * (3 * e - 1)).reshape(nb, 2, 3 * e - 1)
        chain = np.concatenate([A, interior[:, 0], np.asarray(bar_points)[:, None], interior[:, 1], B],
                               axis=1)
        s = np.concatenate([np.linspace(0.0, k_point, 3 * e + 1),
                            np.linspace(k_point, 1.0, 3 * e + 1)[1:]])
        e = 2 * e
    starts = 3 * np.arange(e)
    beam_conn = chain[:, starts[:, None] + np.arange(4)[None, :]].reshape(nb * e, 4).T   # (4, nb e)
    counts = np.full(n0 + interior.size, 6, dtype=np.int64)
    counts[:mtc_topology.n_mesh] = 5
    internal = np.asarray(mtc_topology.tendon_internal).ravel()
    counts[internal] = 3
    return SBCNumbering(dofmap=DofMap(counts), bar_chain=chain, beam_conn=beam_conn,
                        n_mtc_nodes=n0, bar_elements=e, chain_s=s)
