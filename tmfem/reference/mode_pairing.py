"""Pairing the modes of two models by their shapes, not by their order: the modal assurance
criterion (MAC) on a displacement vector both models share, and a one-to-one assignment.

For real shape vectors a (of one model) and b (of the other) on the same entries,

    MAC(a, b) = (a^T b)^2 / ((a^T a) (b^T b)),

1 for proportional vectors, 0 for orthogonal ones (plain MAC: no mass weighting, the shared
entries are displacements of one kind, in metres).

Repeated frequencies. The modes of a repeated (degenerate) frequency of a symmetric system are
any basis of their span, and two models pick different bases, so the MAC of one vector against
one of them means nothing. The other model's modes are grouped into *clusters*: runs of
ascending frequencies whose neighbours differ by at most :data:`CLUSTER_TOLERANCE` (relative).
A reference mode a is compared with the span of the cluster C holding the other model's mode b,

    MAC*(a, b) = a^T Q (Q^T a) / (a^T a),   Q an orthonormal basis of the span of C,

the MAC of a with its projection on that span: the plain MAC when C has one mode, the same
for every basis of C, and 1 for any vector of a degenerate pair's plane against the other
model's plane of that pair (so the reference model's own choice of basis in a pair does not
matter either, as long as the two planes agree). The pairs are the one-to-one assignment
(Hungarian algorithm, ``scipy.optimize.linear_sum_assignment``) that maximises the sum of
MAC*; ties (modes of one cluster) are broken by the plain MAC, which tells apart distinct
modes that happen to lie within the tolerance, and the reference modes of one cluster that go
to one cluster of the other model take its modes in order (within a degenerate pair the plain
MAC is arbitrary). A pair whose MAC* is below
:data:`MAC_THRESHOLD` is no pair: that mode has no counterpart among the other model's computed
modes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError

#: smallest MAC* of a pair: below it the shapes have less than half of their squared norm in
#: common (the best match is no better than a mixture of two different modes)
MAC_THRESHOLD = 0.5
#: largest relative difference of neighbouring frequencies of one cluster: the degenerate
#: pairs of a symmetric system agree to round-off in the FE models, while the COM's truncated
#: membrane basis splits some by up to 0.2 % (the 1-3 test system's modes 8-9 with K = 7);
#: distinct modes closer than this are compared as one span and told apart by their plain MAC
CLUSTER_TOLERANCE = 0.003


def mac_matrix(A, B) -> np.ndarray:
    """MAC(a_i, b_j) (module docstring) of the columns of A (n, k_a) and B (n, k_b)."""
    A, B = np.asarray(A, dtype=float), np.asarray(B, dtype=float)
    if A.shape[0] != B.shape[0]:
        raise InputError(f"mac_matrix: expected shapes on the same entries, found {A.shape[0]} and "
                         f"{B.shape[0]} rows")
    return (A.T @ B) ** 2 / np.outer(np.einsum("ij,ij->j", A, A), np.einsum("ij,ij->j", B, B))


def frequency_clusters(freq_hz, *, tolerance: float = CLUSTER_TOLERANCE) -> list[np.ndarray]:
    """The clusters (module docstring) of ascending frequencies: index arrays, in order."""
    f = np.asarray(freq_hz, dtype=float)
    if f.size == 0:
        return []
    gap = np.abs(np.diff(f)) > tolerance * np.maximum(np.abs(f[:-1]), np.abs(f[1:]))
    return np.split(np.arange(f.size), np.flatnonzero(gap) + 1)


def cluster_mac(A, B, *, clusters) -> np.ndarray:
    """MAC*(a_i, b_j) (module docstring): each column of A against the span of the cluster of
    ``clusters`` (of B's columns) that holds b_j; (k_a, k_b)."""
    A, B = np.asarray(A, dtype=float), np.asarray(B, dtype=float)
    out = np.empty((A.shape[1], B.shape[1]))
    norm = np.einsum("ij,ij->j", A, A)
    for c in clusters:
        Q, _ = np.linalg.qr(B[:, c])                                   # orthonormal basis of the span
        out[:, c] = (np.sum((Q.T @ A) ** 2, axis=0) / norm)[:, None]
    return out


@dataclass
class ModePairs:
    """The modes of another model paired with each mode of a reference model.

    Attributes
    ----------
    partner : list of int or None
        0-based mode of the other model paired with each reference mode; None: no counterpart.
    mac : list of float
        MAC* of each reference mode with its assignment (also when below the threshold).
    unpaired_other : list of int
        0-based modes of the other model paired with none.
    cluster_of : list of int
        The cluster (index) of each of the other model's modes.
    """

    partner: list
    mac: list
    unpaired_other: list
    cluster_of: list

    @property
    def is_identity(self) -> bool:
        """Every reference mode i paired with the other model's mode i or a mode of its cluster
        (the same frequency within the tolerance): the comparison by order is the paired one."""
        c = self.cluster_of
        return all(p is not None and i < len(c) and c[p] == c[i] for i, p in enumerate(self.partner))

    @property
    def unpaired(self) -> list:
        """0-based reference modes without a counterpart."""
        return [i for i, p in enumerate(self.partner) if p is None]


def pair_modes(reference, other, *, reference_hz, other_hz, threshold: float = MAC_THRESHOLD,
               cluster_tolerance: float = CLUSTER_TOLERANCE) -> ModePairs:
    """Pair the modes (columns of ``reference`` and ``other`` on the same entries) by shape:
    the assignment maximising the sum of MAC* of the module docstring (the other model's
    clusters of close frequencies compared through their spans), pairs below ``threshold``
    dropped."""
    from scipy.optimize import linear_sum_assignment
    reference_hz, other_hz = np.asarray(reference_hz, dtype=float), np.asarray(other_hz, dtype=float)
    clusters = frequency_clusters(other_hz, tolerance=cluster_tolerance)
    score = np.clip(cluster_mac(reference, other, clusters=clusters), 0.0, 1.0)
    ka, kb = score.shape
    order = (np.arange(ka)[:, None] - np.arange(kb)[None, :]) ** 2 / (ka * kb) ** 2
    tie = 1e-6 * mac_matrix(reference, other) - 1e-9 * order          # ties: plain MAC, then order
    rows, cols = linear_sum_assignment(1.0 - score - tie)
    cluster_of = np.empty(kb, dtype=int)
    for n, c in enumerate(clusters):
        cluster_of[c] = n
    cols = _in_order_within_clusters(rows, cols, cluster_of,
                                     frequency_clusters(reference_hz, tolerance=cluster_tolerance))
    partner, mac = [None] * ka, [0.0] * ka
    for i, j in zip(rows, cols):
        mac[i] = float(score[i, j])
        if score[i, j] >= threshold:
            partner[i] = int(j)
    used = {p for p in partner if p is not None}
    return ModePairs(partner=partner, mac=mac, unpaired_other=[j for j in range(kb) if j not in used],
                     cluster_of=cluster_of.tolist())


def _in_order_within_clusters(rows, cols, cluster_of, reference_clusters) -> np.ndarray:
    """The partners ``cols`` of ``rows`` with the modes of one reference cluster that went to
    one cluster of the other model given its partners in ascending order (their MAC* are the
    same; only the plain MAC, arbitrary within degenerate pairs, chose among them)."""
    cols = np.array(cols)
    where = {int(i): n for n, i in enumerate(rows)}
    for rc in reference_clusters:
        mine = [where[int(i)] for i in rc if int(i) in where]
        for c in {cluster_of[cols[n]] for n in mine}:
            slots = [n for n in mine if cluster_of[cols[n]] == c]
            cols[slots] = np.sort(cols[slots])
    return cols
