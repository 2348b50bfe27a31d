"""Node labels and tendon connectivity of M-N and 1-N(D) systems (dissertation 2.2).

Nodes are ordered ``A_11..A_1N, A_21..A_MN, B_11..B_MN`` and, for 1-N(D) systems,
``H_11..H_1N``. Tendon families (Fig. 2.3, 2.4):

* ``S_ij``: A_ij - B_i,j-1          * ``V_ij``: A_ij - B_i-1,j+1
* ``D_ij``: A_ij - B_i-1,j-1        * ``C_ij``: A_ij - A_i-1,j-1
* ``P_ij``: B_ij - B_i-1,j          * ``R_ij``: B_ij - B_i-1,j-1
* ``SL_j``: A_1j - H_1,j-1          * ``SU_j``: B_1j - H_1,j-1

Stage 1 of an M-N system has only S tendons; stages i >= 2 have all six families.
Bar indices are cyclic: j-1 of j=1 is N, j+1 of j=N is 1.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

FAMILIES_MN = ("S", "V", "D", "C", "P", "R")
FAMILIES_D = ("SL", "SU")


def label(kind: str, i: int, j: int) -> str:
    """Label of a node or member, ``kind_ij`` (``kind_i,j`` when an index exceeds 9)."""
    return f"{kind}_{i}{j}" if i < 10 and j < 10 else f"{kind}_{i},{j}"


@dataclass(frozen=True)
class Tendon:
    """One tendon: its name (``S_12``), family, stage i, index j and its two end nodes.

    ``group`` is the family-stage key (``S1``, ``V2``, ``SL``) under which symmetric
    designs share a rest length and a cross section.
    """

    name: str
    family: str
    stage: int
    j: int
    ends: tuple[str, str]

    @property
    def group(self) -> str:
        return self.family if self.family in FAMILIES_D else f"{self.family}{self.stage}"


def node_labels(M: int, N: int, deployable: bool) -> list[str]:
    """Node labels in global order: A nodes by stage, B nodes by stage, then H nodes."""
    labels = [label("A", i, j) for i in range(1, M + 1) for j in range(1, N + 1)]
    labels += [label("B", i, j) for i in range(1, M + 1) for j in range(1, N + 1)]
    if deployable:
        labels += [label("H", 1, j) for j in range(1, N + 1)]
    return labels


def tendon_topology(M: int, N: int, deployable: bool) -> list[Tendon]:
    """All tendons of an M-N system, or of a 1-N(D) system when ``deployable`` (a new list of
    the tendons made once per topology, so that systems of one topology share them)."""
    return list(_tendon_topology(int(M), int(N), bool(deployable)))


@lru_cache(maxsize=None)
def _tendon_topology(M: int, N: int, deployable: bool) -> tuple[Tendon, ...]:
    def cyc(j: int) -> int:
        return (j - 1) % N + 1

    if deployable:
        if M != 1:
            raise ValueError(f"1-N(D) systems have one stage; found M={M}")
        out = [Tendon(f"SL_{j}", "SL", 1, j, (label("A", 1, j), label("H", 1, cyc(j - 1))))
               for j in range(1, N + 1)]
        out += [Tendon(f"SU_{j}", "SU", 1, j, (label("B", 1, j), label("H", 1, cyc(j - 1))))
                for j in range(1, N + 1)]
        return tuple(out)

    out = [Tendon(label("S", 1, j), "S", 1, j, (label("A", 1, j), label("B", 1, cyc(j - 1))))
           for j in range(1, N + 1)]
    for i in range(2, M + 1):
        for j in range(1, N + 1):
            ends = {
                "S": (label("A", i, j), label("B", i, cyc(j - 1))),
                "V": (label("A", i, j), label("B", i - 1, cyc(j + 1))),
                "D": (label("A", i, j), label("B", i - 1, cyc(j - 1))),
                "C": (label("A", i, j), label("A", i - 1, cyc(j - 1))),
                "P": (label("B", i, j), label("B", i - 1, j)),
                "R": (label("B", i, j), label("B", i - 1, cyc(j - 1))),
            }
            out += [Tendon(label(f, i, j), f, i, j, ends[f]) for f in FAMILIES_MN]
    return tuple(out)
