"""Supports that compose: constraint rows on the dofs of each node.

Every support, symmetry plane, prescribed displacement and local-frame condition of a
:class:`tmfem.fem.structure.Structure` is stored as a row ``c . u_f = g lam`` on one field f
of one node: the translations (c in global x, y, z), the rotations of a 6-dof node (c in
global x, y, z: the solvers' rotation increments are spatial) or the two rotations of a
5-dof shell node (c in the coordinates of its reference V_1, V_2: a spatial direction d gives
c = (d . V_1, d . V_2); the rotation about the director is not a dof). g is the value reached
at load factor 1 (0 for a support). A node's rows are never replaced, only added: a node on
two symmetry planes carries the rows of both.

When a row is added it is checked against the node's rows so far:

- independent of them: kept;
- a combination of them, and they and it are all supports (g = 0): nothing new, ignored
  (two planes through a node constrain a rotation twice);
- a combination of them where a prescribed value is involved: refused, as *conflicting*
  when the implied value differs and as *redundant* when it agrees, with the node and the
  dofs named.

A pinned connection makes a node's translations follow a master node's; rows on the
translations of a pinned node, a pin of a node that has translation rows, a second pin of
the same node and chains of pins are refused.

:meth:`Supports.build` turns the rows into a :class:`tmfem.fem.constraints.ConstraintMap`:
for each (node, field) with k rows D (k, m) an orthonormal basis Q (m, m) whose first k
columns span the rows (QR of D^T); its first k local components are fixed at
(D Q_k)^-1 g lam, the others are free.
"""
from __future__ import annotations

import copy
import logging
from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError
from tmfem.fem.constraints import ConstraintMap
from tmfem.fem.dofmap import DofMap

log = logging.getLogger(__name__)

_TOL = 1e-9


@dataclass
class Row:
    """One constraint row ``c . u_field = value lam`` of a node (module docstring)."""

    node: int
    field: str            # "u" translations, "r" rotations
    c: np.ndarray         # unit coefficients on the field's dofs (3,) or (2,)
    value: float          # reached at load factor 1
    prescribed: bool      # a prescribed displacement (False: a support, value 0)
    label: str            # the call that made it, for messages


def describe(row_field: str, c: np.ndarray, n_dofs: int) -> str:
    """The dof a row acts on, by name when it is a coordinate axis ("uz", "r1", "rx"), else as
    a direction."""
    names = {("u", 3): ("ux", "uy", "uz"), ("r", 2): ("r1", "r2"), ("r", 3): ("rx", "ry", "rz")}[(row_field, n_dofs)]
    k = int(np.argmax(np.abs(c)))
    if abs(abs(c[k]) - 1.0) < 1e-12:
        return ("-" if c[k] < 0 else "") + names[k]
    comp = ", ".join(f"{v:.3g}" for v in c)
    return f"{'u' if row_field == 'u' else 'rotation'} along ({comp})" + (" of (V1, V2)" if n_dofs == 2 else "")


class Supports:
    """The constraint rows and pins of a structure (module docstring)."""

    def __init__(self, dofmap: DofMap):
        self.dofmap = dofmap
        self.rows: dict[tuple[int, str], list[Row]] = {}
        self.pins: dict[int, tuple[np.ndarray, np.ndarray, str]] = {}

    def copy(self) -> "Supports":
        return copy.deepcopy(self)

    def n_field(self, node: int, field: str) -> int:
        return 3 if field == "u" else int(self.dofmap.counts[node]) - 3

    def add(self, node: int, field: str, c, *, value: float = 0.0, prescribed: bool = False,
            label: str) -> None:
        """Add the row ``c . u_field = value lam`` at ``node`` (checks: module docstring)."""
        node = int(node)
        c = np.asarray(c, dtype=float)
        m = self.n_field(node, field)
        if field == "r" and m == 0:
            raise InputError(f"{label}: node {node} has no rotations; expected a node with 5 or 6 dofs")
        norm = float(np.linalg.norm(c))
        if c.shape != (m,) or norm < 1e-8:
            raise InputError(f"{label}: node {node}: expected a direction with a component on its "
                             f"{m} {'translation' if field == 'u' else 'rotation'} dofs, found {c.tolist()}"
                             + (" (the rotation about a shell director is not a dof)" if m == 2 else ""))
        c, value = c / norm, float(value) / norm
        name = describe(field, c, m)
        if field == "u" and node in self.pins:
            raise InputError(f"{label}: node {node}: its translations follow node(s) "
                             f"{self.pins[node][0].tolist()} ({self.pins[node][2]}); expected the "
                             f"support on the master, found one on {name} of the pinned node")
        rows = self.rows.setdefault((node, field), [])
        if rows:
            D = np.array([r.c for r in rows])
            a, *_ = np.linalg.lstsq(D.T, c, rcond=None)
            if np.linalg.norm(D.T @ a - c) <= _TOL:
                used = [r for r, ai in zip(rows, a) if abs(ai) > _TOL]
                implied = float(sum(ai * r.value for r, ai in zip(rows, a)))
                if not prescribed and not any(r.prescribed for r in used):
                    log.debug("%s: node %d: %s is constrained already", label, node, name)
                    return
                others = ", ".join(f"{describe(field, r.c, m)} ({r.label}, {r.value:g})" for r in used)
                kind = ("conflicting" if abs(implied - value) > 1e-12 * max(1.0, abs(value), abs(implied))
                        else "redundant")
                raise InputError(f"{label}: node {node}: expected a constraint on a free dof, found a "
                                 f"{kind} one: {name} = {value:g} against {others} (release() first)")
        rows.append(Row(node=node, field=field, c=c, value=value, prescribed=prescribed, label=label))

    def pin(self, node: int, masters, weights, *, label: str) -> None:
        """Translations of ``node`` = sum weights[i] translations of masters[i]."""
        node = int(node)
        masters = np.atleast_1d(np.asarray(masters, dtype=np.int64))
        weights = np.atleast_1d(np.asarray(weights, dtype=float))
        if node in self.pins:
            raise InputError(f"{label}: node {node} is pinned already to {self.pins[node][0].tolist()} "
                             f"({self.pins[node][2]}); expected one pin per node (release() first)")
        if node in masters:
            raise InputError(f"{label}: expected a master other than node {node} itself")
        chained = [int(k) for k in masters if int(k) in self.pins]
        if chained or any(node in p[0] for p in self.pins.values()):
            raise InputError(f"{label}: node {node}: expected no chain of pins, found "
                             + (f"master(s) {chained} pinned themselves" if chained
                                else f"node {node} is a master of a pinned node"))
        if self.rows.get((node, "u")):
            names = [describe("u", r.c, 3) for r in self.rows[(node, "u")]]
            raise InputError(f"{label}: node {node} has supports on {names} ({self.rows[(node, 'u')][0].label}); "
                             f"expected a pinned node without translation supports (support the master)")
        self.pins[node] = (masters, weights, label)

    def release(self, node: int, field: str | None = None, c=None) -> int:
        """Remove the rows of ``node`` (of ``field`` along ``c`` when given) and its pin (when
        ``field`` is None); the number removed."""
        node = int(node)
        removed = 0
        if field is None:
            removed += int(self.pins.pop(node, None) is not None)
            for f in ("u", "r"):
                removed += len(self.rows.pop((node, f), []))
            return removed
        rows = self.rows.get((node, field), [])
        c = np.asarray(c, dtype=float) / np.linalg.norm(c)
        keep = [r for r in rows if abs(abs(r.c @ c) - 1.0) > 1e-9]
        self.rows[(node, field)] = keep
        return len(rows) - len(keep)

    def freeze(self) -> None:
        """Prescribed values reached so far become permanent: every value is set to 0 (the
        state carries the displacement; the rows stay prescribed for the checks)."""
        for rows in self.rows.values():
            for r in rows:
                r.value = 0.0

    def build(self) -> tuple[ConstraintMap, np.ndarray]:
        """The constraint map and the full prescribed displacement at load factor 1 (ndof,)."""
        dm = self.dofmap
        bases, fixed, local = [], [], []
        for (node, field), rows in self.rows.items():
            if not rows:
                continue
            m = self.n_field(node, field)
            D = np.array([r.c for r in rows])
            k = D.shape[0]
            Q, _ = np.linalg.qr(D.T, mode="complete")
            dofs = dm.offset[node] + (np.arange(3) if field == "u" else 3 + np.arange(m))
            bases.append((dofs, Q))
            fixed.append(dofs[:k])
            g = np.array([r.value for r in rows])
            local.append((dofs[:k], np.linalg.solve(D @ Q[:, :k], g)))
        dependent = [(n, ms, w) for n, (ms, w, _) in self.pins.items()]
        cm = ConstraintMap.build(dm, dependent=dependent, bases=bases,
                                 fixed_dofs=np.concatenate(fixed) if fixed else np.zeros(0, np.int64))
        ur = np.zeros(cm.n_reduced)
        for dofs, v in local:
            ur[cm.reduced_of[dofs]] = v
        return cm, cm.full(ur)
