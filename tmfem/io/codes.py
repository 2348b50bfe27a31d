"""Integer codes that identify members and nodes in the VTK files (VTU files hold numbers,
not strings).

Codes written as integer data (VTU files hold numbers, not strings):

* cell data ``kind``: 0 bar, 1 tendon, 2 membrane (see :data:`KIND_CODES`);
* cell data ``family``: index into :data:`FAMILY_CODES` (``S V D C P R SL SU``), -1 for
  bars and membrane cells; ``stage`` and ``j`` give the indices i, j of the member label;
* point data ``node_kind``: 0 for A_ij, 1 for B_ij, 2 for H_1j, -1 for membrane mesh
  nodes; ``node_stage`` and ``node_j`` give i, j of the label, ``node_id`` its index in
  ``System.node_labels``.

Floating-point data not defined on a cell or point (a bar's rest length, a membrane
stress on a tendon) is NaN, which ParaView shows as "no value".
"""
from __future__ import annotations

import re

import numpy as np

from tmfem.errors import InputError
from tmfem.models.members import FAMILY_CODES  # noqa: F401  (re-exported: the family codes of the files)
from tmfem.system.topology import label

KIND_CODES = {"bar": 0, "tendon": 1, "membrane": 2}
NODE_KIND_CODES = {"A": 0, "B": 1, "H": 2}

_LABEL = re.compile(r"^([A-Z]+)_(\d)(\d)$|^([A-Z]+)_(\d+),(\d+)$")


def split_label(name: str) -> tuple[str, int, int]:
    """``A_12`` -> ("A", 1, 2); ``A_1,12`` -> ("A", 1, 12)."""
    m = _LABEL.match(name)
    if m is None:
        raise InputError(f"unexpected node label {name!r}")
    if m.group(1):
        return m.group(1), int(m.group(2)), int(m.group(3))
    return m.group(4), int(m.group(5)), int(m.group(6))


def node_codes(system) -> dict:
    """Integer point data identifying the labelled nodes of ``system``."""
    parts = [split_label(s) for s in system.node_labels]
    return {"node_id": np.arange(len(parts), dtype=np.int64),
            "node_kind": np.array([NODE_KIND_CODES[p[0]] for p in parts], dtype=np.int64),
            "node_stage": np.array([p[1] for p in parts], dtype=np.int64),
            "node_j": np.array([p[2] for p in parts], dtype=np.int64)}


def configuration_cells(system) -> list:
    """Cells of the labelled nodes of ``system``: bars, tendons and the membrane polygon."""
    return [("line", system.bar_connectivity), ("line", system.tendon_connectivity),
            ("polygon", membrane_corner_nodes(system)[:, None])]


def membrane_corner_nodes(system) -> np.ndarray:
    """Indices of the membrane corners B_M1..B_MN in ``system.node_labels``."""
    return np.array([system.node_index(label("B", system.M, j)) for j in range(1, system.N + 1)])


def kind_cell_data(cells) -> dict:
    """Cell data ``kind`` (:data:`KIND_CODES`: 0 bar, 1 tendon, 2 membrane) for the three cell
    blocks of an MTC mesh (bars, tendon elements, membrane quads; ``model_cells``), so that
    ParaView can separate them in a modes file (Threshold on ``kind``)."""
    codes = (KIND_CODES["bar"], KIND_CODES["tendon"], KIND_CODES["membrane"])
    if len(cells) != 3:
        raise InputError(f"cells: expected the 3 blocks bars, tendons, membrane, found {len(cells)}")
    return {"kind": [np.full(np.asarray(c).shape[1], k, dtype=np.int64)
                     for (_, c), k in zip(cells, codes)]}

