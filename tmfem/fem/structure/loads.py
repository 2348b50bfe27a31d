"""Loads of a structure: load cases, their combination, and line loads.

Every load belongs to a named load case ("default" unless given). The live load is the
combination F_live = sum_c w_c F_c (:meth:`LoadCases.combine`, all w_c = 1 by default),
scaled by the load factor lam of the solvers; the base load (:meth:`LoadCases.freeze`) is not
scaled. A case holds a dead nodal vector (point forces, dead line, surface and body loads:
consistent nodal forces computed once), point moments (turned into generalized forces when
solving, with the triads of the shell nodes) and state-dependent loads (pressures, follower
line loads) with a ``load(state, tangent=)`` method returning the force and its load stiffness
dF/du.

Line loads (:class:`LineLoad`) act on 2-node edges (linear interpolation: shell element
edges, bars, chains of nodes) or on the 4-node beam elements (their cubic interpolation),
as consistent nodal forces f_k = int h_k q ds:

- dead: q [N/m] (3,) or q(x, y, z) -> (3, m) per unit reference length, integrated by Gauss
  (2 points on an edge, 4 on a beam element: exact for loads linear along the line);
- follower (shell edges): q [N/m] per unit current length along the current director
  interpolated along the edge, d(s) = h_a d_a + h_b d_b: f_a = q L (d_a/3 + d_b/6),
  f_b = q L (d_a/6 + d_b/3) with L the current edge length; its load stiffness (exact,
  non-symmetric): df_a/dx_b = -df_a/dx_a = q (d_a/3 + d_b/6) e^T (e the unit chord) and, with
  the rotation increments about the current V_1, V_2 (d' = -V_2 dalpha + V_1 dbeta),
  df_a/dalpha_a = -q L V_2,a / 3, df_a/dbeta_a = q L V_1,a / 3, df_a/dalpha_b = -q L V_2,b / 6, ...;
- follower (beam elements): q [N/m] (3,) per unit current length, given in the reference
  configuration and turned with the sections (:class:`BeamFollowerLoad`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.assembly import Assembler
from tmfem.fem.beam import shape_functions
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import skew


@dataclass
class Case:
    """One load case: dead nodal vector, point moments (node, m) and state-dependent loads."""

    force: np.ndarray
    moments: list = field(default_factory=list)
    loads: list = field(default_factory=list)


class LoadCases:
    """Named load cases, their combination factors and the base load (module docstring)."""

    def __init__(self, ndof: int):
        self.ndof = ndof
        self.cases: dict[str, Case] = {}
        self.factors: dict[str, float] | None = None
        self.base_force = np.zeros(ndof)
        self.base_loads: list = []                      # (weight, load)

    def case(self, name: str) -> Case:
        if not isinstance(name, str) or not name:
            raise InputError(f"load case: expected a non-empty name, found {name!r}")
        return self.cases.setdefault(name, Case(force=np.zeros(self.ndof)))

    def combine(self, factors: dict) -> None:
        """Live load = sum_c factors[c] F_c (cases not named: 0); an empty dict: every case 1."""
        unknown = sorted(set(factors) - set(self.cases))
        if unknown:
            raise InputError(f"combine: expected load cases from {sorted(self.cases)}, found {unknown}")
        bad = {k: v for k, v in factors.items() if not (isinstance(v, (int, float, np.number)) and np.isfinite(v))}
        if bad:
            raise InputError(f"combine: expected finite factors, found {bad}")
        self.factors = {k: float(v) for k, v in factors.items()} or None

    def weight(self, name: str) -> float:
        return 1.0 if self.factors is None else self.factors.get(name, 0.0)

    def live(self, state, moment_vector, *, tangent: bool = True):
        """Combined live load at load factor 1 and its load stiffness at ``state``;
        ``moment_vector(moments) -> (ndof,)`` turns a case's point moments into forces."""
        f, K = np.zeros(self.ndof), None
        for name, c in self.cases.items():
            w = self.weight(name)
            if w == 0.0:
                continue
            f = f + w * (c.force + moment_vector(c.moments))
            for ld in c.loads:
                fl, Kl = ld.load(state, tangent=tangent)
                f = f + w * fl
                if Kl is not None:
                    K = w * Kl if K is None else K + w * Kl
        return f, K

    def base(self, state, *, tangent: bool = True):
        """Base load (not scaled by the load factor) and its load stiffness."""
        f, K = self.base_force.copy(), None
        for w, ld in self.base_loads:
            fl, Kl = ld.load(state, tangent=tangent)
            f = f + w * fl
            if Kl is not None:
                K = w * Kl if K is None else K + w * Kl
        return f, K

    def freeze(self, moment_vector) -> None:
        """The combined live load becomes part of the base load; the cases are emptied."""
        for name, c in self.cases.items():
            w = self.weight(name)
            self.base_force = self.base_force + w * (c.force + moment_vector(c.moments))
            self.base_loads += [(w, ld) for ld in c.loads]
        self.cases = {}
        self.factors = None


def _gauss(n: int):
    r, w = np.polynomial.legendre.leggauss(n)
    return r, w


def line_shape(k: int, r: np.ndarray) -> np.ndarray:
    """Lagrange shape functions (k, nq) of k equally spaced nodes on [-1, 1] (k = 2: linear
    edges; k = 4: the cubic beam element, nodes at -1, -1/3, 1/3, 1)."""
    xi = np.linspace(-1.0, 1.0, k)
    h = np.ones((k, r.size))
    for a in range(k):
        for b in range(k):
            if b != a:
                h[a] *= (r - xi[b]) / (xi[a] - xi[b])
    return h


def _line_derivative(k: int, r: np.ndarray, eps: float = 1e-6) -> np.ndarray:
    return (line_shape(k, r + eps) - line_shape(k, r - eps)) / (2 * eps)


class LineLoad:
    """Consistent line load on 2-node edges or 4-node beam elements (module docstring).

    Parameters
    ----------
    X : (3, n_nodes) reference positions; lines : (k, ne) nodes of each line element (k = 2
    or 4, in order along it); dofmap : DofMap; q : (3,) or callable (x, y, z) -> (3, m) [N/m]
    for a dead load, a number [N/m] for a follower load; follower : bool; frames : (n, 3, 3)
    reference triads (follower loads on 5-dof nodes).
    """

    def __init__(self, *, X, lines, dofmap: DofMap, q, follower: bool = False, frames=None):
        self.X = np.asarray(X, dtype=float)
        self.lines = np.asarray(lines, dtype=np.int64)
        self.dofmap = dofmap
        self.follower = bool(follower)
        k = self.lines.shape[0]
        if self.lines.ndim != 2 or k not in (2, 4) or self.lines.shape[1] == 0:
            raise InputError(f"line load: expected line elements of shape (2 or 4, ne >= 1), found {self.lines.shape}")
        if self.follower:
            if k != 2 or np.any(dofmap.counts[self.lines] != 5):
                raise InputError("line load: expected a follower line load on edges of shell (5-dof) nodes, "
                                 "found other nodes or beam elements")
            if not (np.ndim(q) == 0 and np.isfinite(q)):
                raise InputError(f"line load: expected a follower load as one number [N/m] along the "
                                 f"director, found {q!r}")
            self.q = float(q)
            self.frames = np.asarray(frames, dtype=float)
            self._asm = Assembler(dofmap.element_dofs(self.lines, rotations=True), dofmap.ndof)
            self._f = None
            return
        r, w = _gauss(2 if k == 2 else 4)
        h, dh = line_shape(k, r), _line_derivative(k, r)
        Xe = self.X[:, self.lines]                                          # (3, k, ne)
        xq = np.einsum("kq,ike->iqe", h, Xe)                                # (3, nq, ne)
        J = np.linalg.norm(np.einsum("kq,ike->iqe", dh, Xe), axis=0)        # (nq, ne)
        if callable(q):
            qq = np.asarray(q(*xq.reshape(3, -1)), dtype=float)
            qq = np.broadcast_to(qq.reshape(3, -1) if qq.ndim == 2 else qq.reshape(3, 1),
                                 (3, xq[0].size)).reshape(3, *xq.shape[1:])
        else:
            qv = np.asarray(q, dtype=float)
            if qv.shape != (3,):
                raise InputError(f"line load: expected q of 3 components [N/m] or a callable, found shape {qv.shape}")
            qq = np.broadcast_to(qv[:, None, None], xq.shape)
        if not np.all(np.isfinite(qq)):
            raise InputError("line load: expected finite values of q, found non-finite ones")
        fe = np.einsum("q,kq,qe,iqe->eki", w, h, J, qq)                     # (ne, k, 3)
        f = np.zeros(dofmap.ndof)
        np.add.at(f, dofmap.translation_dofs(self.lines.T.ravel()), fe.reshape(-1, 3))
        self._f = f

    def load(self, state, *, tangent: bool = True):
        """Nodal force (ndof,) and its load stiffness (csr; None for a dead load)."""
        if not self.follower:
            return self._f, None
        a, b = self.lines
        V = np.einsum("nij,njk->nik", state.R, self.frames)                 # current triads (n, 3, 3)
        da, db = V[a, :, 2], V[b, :, 2]
        ch = (state.x[:, b] - state.x[:, a]).T                              # (ne, 3)
        L = np.linalg.norm(ch, axis=1)
        e = ch / L[:, None]
        ga, gb = da / 3 + db / 6, da / 6 + db / 3
        fe = self.q * np.stack([L[:, None] * ga, L[:, None] * gb], axis=1)  # (ne, 2, 3)
        fe5 = np.zeros((L.size, 2, 5))
        fe5[:, :, :3] = fe
        f = self._asm.vector(fe5.reshape(-1, 10))
        if not tangent:
            return f, None
        ne = L.size
        Ke = np.zeros((ne, 2, 5, 2, 5))
        for i, g in enumerate((ga, gb)):
            dx = self.q * np.einsum("ei,ej->eij", g, e)
            Ke[:, i, :3, 0, :3] = -dx
            Ke[:, i, :3, 1, :3] = dx
            for j, node in enumerate((a, b)):
                c = self.q * L * (1 / 3 if i == j else 1 / 6)
                Ke[:, i, :3, j, 3] = -c[:, None] * V[node, :, 1]
                Ke[:, i, :3, j, 4] = c[:, None] * V[node, :, 0]
        return f, self._asm.matrix(Ke.reshape(ne, 10, 10))

    def internal(self, state, *, tangent: bool = True):
        """The load as an element set: internal force -F and tangent -dF/du."""
        f, K = self.load(state, tangent=tangent)
        if tangent and K is None:
            K = sp.csr_matrix((self.dofmap.ndof,) * 2)
        return -f, (-K if tangent else None)


class BeamFollowerLoad:
    """Follower line load on 4-node beam elements (module docstring): q [N/m] (3,) per unit
    current length of the axis, given in global axes in the reference configuration and
    turned with the sections: at a point r of an element the load is
    q(r) = sum_k h_k(r) R_k q (R_k the rotation of node k), so a load normal to the axis stays
    normal to it. Consistent nodal forces (4-point Gauss along the axis)

        f_a = int h_a |x'| q(r) dr,

    and the exact load stiffness (translations x_b, spatial rotation increments theta_k of the
    nodes, d(R_k q) = theta_k x R_k q):

        df_a/dx_b = int h_a h_b' q(r) e^T dr,   df_a/dtheta_k = -int h_a h_k |x'| dr skew(R_k q),

    with e = x' / |x'| the unit tangent of the current axis.

    Parameters
    ----------
    lines : (4, ne) beam element nodes; dofmap : DofMap (six dofs at every node of ``lines``);
    q : (3,) [N/m].
    """

    def __init__(self, *, lines, dofmap: DofMap, q):
        self.lines = np.asarray(lines, dtype=np.int64)
        if self.lines.ndim != 2 or self.lines.shape[0] != 4 or self.lines.shape[1] == 0:
            raise InputError(f"beam follower load: expected beam elements of shape (4, ne >= 1), "
                             f"found {self.lines.shape}")
        dofmap.check_element_nodes(self.lines, 6, element="beam follower load", dofs="six dofs")
        q = np.asarray(q, dtype=float)
        if q.shape != (3,) or not np.all(np.isfinite(q)):
            raise InputError(f"beam follower load: expected a finite q of 3 components [N/m], found {q!r}")
        self.q = q
        self.dofmap = dofmap
        r, self.w = _gauss(4)
        self.h, self.dh = shape_functions(r)                                # (4, ng)
        self._asm = Assembler(dofmap.element_dofs(self.lines, rotations=True), dofmap.ndof)

    def load(self, state, *, tangent: bool = True):
        """Nodal force (ndof,) and its load stiffness (csr)."""
        h, dh, w = self.h, self.dh, self.w
        xp = np.einsum("kg,ike->egi", dh, state.x[:, self.lines])          # (ne, ng, 3)
        L = np.linalg.norm(xp, axis=-1)                                     # (ne, ng)
        Rq = np.einsum("keij,j->eki", state.R[self.lines], self.q)          # (ne, 4, 3)
        d = np.einsum("kg,eki->egi", h, Rq)                                 # (ne, ng, 3)
        ne = L.shape[0]
        fe = np.zeros((ne, 4, 6))
        fe[..., :3] = np.einsum("g,ag,eg,egi->eai", w, h, L, d)
        f = self._asm.vector(fe.reshape(ne, 24))
        if not tangent:
            return f, None
        Ke = np.zeros((ne, 4, 6, 4, 6))
        e = xp / L[..., None]
        Ke[:, :, :3, :, :3] = np.einsum("g,ag,bg,egi,egj->eaibj", w, h, dh, d, e)
        c = np.einsum("g,ag,kg,eg->eak", w, h, h, L)                        # (ne, 4, 4)
        Ke[:, :, :3, :, 3:] = -np.einsum("eak,ekij->eaikj", c, skew(Rq))
        return f, self._asm.matrix(Ke.reshape(ne, 24, 24))
