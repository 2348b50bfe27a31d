"""Total-Lagrangian MITC4 shell element (dissertation 4.2 and 4.3.1, eqs. 4.7-4.18).

Geometry (eq. 4.12). A material point of an element at reference coordinates
(xi_1, xi_2) in the unit square of scikit-fem's ``ElementQuad1`` and r_3 in [-1, 1] across
the thickness a is

    x(xi, r_3) = sum_k h_k(xi) x_k + r_3 sum_k h_k(xi) d_k,     d_k = (a / 2) V_n^k,

with the bilinear functions h_k of eq. 4.13 (scikit-fem's counter-clockwise node order; the
dissertation numbers the same nodes starting at (1, 1)) and one unit director V_n^k per node.
The covariant base vectors of eq. 4.8 are

    g_alpha = sum_k h_k,alpha (x_k + r_3 d_k),   g_3 = sum_k h_k d_k,

and the Green-Lagrange strain of eq. 4.7 is eps_ij = (g_i . g_j - G_i . G_j) / 2 (G: the
reference configuration). It is evaluated from the displacements u_alpha = g_alpha - G_alpha
(``2 eps_ab = u_a.G_b + G_a.u_b + u_a.u_b``) so that small strains carry no cancellation.

Transverse shear by mixed interpolation (eqs. 4.17-4.18): eps_13 is tied at A (xi = (1/2, 1))
and C (1/2, 0), eps_23 at D (1, 1/2) and B (0, 1/2), all at r_3 = 0, and interpolated
linearly in xi_2 and xi_1 respectively; it is constant through the thickness. eps_33 is not
used (plane stress).

Material (eqs. 4.9-4.11). St.Venant-Kirchhoff in the lamina: at every integration point the
covariant strain components c = [eps_11, eps_22, 2 eps_12, 2 eps_13, 2 eps_23] are
transformed to the local Cartesian frame e_i of eq. 4.11 (e_3 along G_3, e_1 along
G_2 x e_3) and the plane-stress law with transverse shear modulus k G (k = 5/6) applies:
S = C~ c with C~ = Q^T D Q (eq. 4.10). C~ is a property of the reference configuration and
is computed once.

Tension-field lamina (``law="tension-field"``, beyond the dissertation; docs/guides/wrinkling.md).
The in-plane part of the lamina law is replaced by the relaxed membrane law of
:mod:`tmfem.fem.tension_field` evaluated on the local in-plane Green-Lagrange strain
E_loc = [[e_11, e_12], [e_12, e_22]] (eps_loc = Q c) at every lamina integration point:
s_loc = [S_11, S_22, S_12](E_loc), transverse shear k G [2 e_13, 2 e_23] as before, and the
contravariant stress and tangent are S = Q^T s_loc and C = Q^T D_loc(E_loc) Q, with D_loc the
law's consistent tangent (state dependent: taut, wrinkled, slack) bordered by k G. The
energy density is W(E_loc) + k G ((2 e_13)^2 + (2 e_23)^2) / 2. With ``law="svk"``
(default) the constant C~ above is used unchanged.

Integration: 2 x 2 Gauss points in the plane (scikit-fem's ``get_quadrature(RefQuad, 3)``)
times 2 Gauss points through the thickness (exact for the linear-in-r_3 part of the strain,
the classical choice for the MITC4; the r_3^2 terms are integrated approximately). All
kernels are vectorised over elements and integration points.

Rotations (eq. 4.16 and the finite-rotation update). Each node has two rotational dofs
(alpha_k, beta_k), rotations about the node's current V_1, V_2, which is how
:meth:`tmfem.fem.element.State.advanced` applies them: R <- exp(alpha V_1 + beta V_2) R, the
director V_n = R V_n^0 (a finite rotation, no small-angle approximation). The variation of a
director is delta V_n = -V_2 alpha + V_1 beta (the linear part of the dissertation's
V_n = -V_2 alpha + V_1 beta) and its second variation along increments (alpha', beta') is
-(alpha alpha' + beta beta') V_n; together they give the exact derivative of the residual
(the tangent is symmetric: rotations about V_1, V_2 leave no skew part).
The reference triads follow eq. 4.16: V_1 = e_y x V_n / |e_y x V_n| (V_1 = e_z when V_n is
parallel to e_y), V_2 = V_n x V_1. The State rotates V_1, V_2 with the node (rather than
re-deriving them from V_n by eq. 4.16 at every step); both span the plane normal to V_n, so
only the meaning of the two dofs differs, not the strains.

Consistent mass with rotary inertia: M = int rho N^T N dV with the interpolation above,
mapped to the rotational dofs by d(d_k)/d(alpha, beta) = (a/2) [-V_2, V_1].
"""
from __future__ import annotations

import copy


import numpy as np
import scipy.sparse as sp

from tmfem.cache import MemoryMemo
from tmfem.errors import InputError
from tmfem.fem.assembly import Assembler
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import skew
from tmfem.fem.plane_stress import von_mises
from tmfem.fem.shell_section import ShellSection
from tmfem.fem.tension_field import element_wrinkling, membrane_law

#: in-plane result points of a shell whose reference quantities are kept
RESULT_POINTS_KEPT = 32


def director_frames(normals: np.ndarray) -> np.ndarray:
    """Nodal triads [V_1 V_2 V_n] (n, 3, 3), columns, from unit directors (3, n) (eq. 4.16):
    V_1 = e_y x V_n / |e_y x V_n|, or e_z when V_n is parallel to e_y; V_2 = V_n x V_1."""
    Vn = np.asarray(normals, dtype=float)
    if Vn.ndim != 2 or Vn.shape[0] != 3:
        raise InputError(f"director frames: expected normals of shape (3, n), found {Vn.shape}")
    nrm = np.linalg.norm(Vn, axis=0)
    if np.any(~np.isfinite(nrm)) or np.any(nrm < 1e-12):
        raise InputError(f"director frames: expected non-zero directors, found {int(np.sum(~(nrm >= 1e-12)))} "
                         f"of zero length")
    Vn = Vn / nrm
    ey = np.array([0.0, 1.0, 0.0])
    V1 = np.cross(ey[:, None], Vn, axis=0)
    s = np.linalg.norm(V1, axis=0)
    par = s < 1e-8
    V1[:, par] = np.array([0.0, 0.0, 1.0])[:, None]
    V1[:, ~par] /= s[~par]
    # V_1 = e_z is normal to V_n = +-e_y exactly; re-orthogonalise for nearly parallel input
    V1 -= np.einsum("in,in->n", V1, Vn) * Vn
    V1 /= np.linalg.norm(V1, axis=0)
    V2 = np.cross(Vn, V1, axis=0)
    return np.stack([V1.T, V2.T, Vn.T], axis=2)


def quad_shape(xi: np.ndarray):
    """Bilinear shape functions h (4, m) and derivatives dh (4, 2, m) at reference points
    xi (2, m) of the unit square (scikit-fem ``ElementQuad1``, eq. 4.13)."""
    from skfem import ElementQuad1
    e = ElementQuad1()
    h = np.stack([e.lbasis(xi, k)[0] for k in range(4)])
    dh = np.stack([e.lbasis(xi, k)[1] for k in range(4)])
    return h, dh


def nodal_normals(X: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Unit normals (3, n_nodes) at the nodes of a quadrilateral surface mesh: the average of
    the normals g_1 x g_2 of the elements at each node, evaluated at that node's corner
    (zero columns at nodes of no element). Raises InputError for inconsistently oriented
    elements (a corner normal opposite to the average)."""
    X = np.asarray(X, dtype=float)
    conn = np.asarray(conn, dtype=np.int64)
    corners = np.array([[0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0]])
    _, dh = quad_shape(corners)                          # (4 nodes, 2, 4 corners)
    xe = X[:, conn]                                       # (3, 4, ne)
    g = np.einsum("kac,ike->eaci", dh, xe)                # (ne, 2, corner, 3)
    n = np.cross(g[:, 0], g[:, 1])                        # (ne, corner, 3)
    area = np.linalg.norm(n, axis=-1)
    if np.any(area <= 1e-14 * max(1.0, float(np.max(area, initial=0.0)))):
        e = int(np.argwhere(area <= 1e-14 * max(1.0, float(np.max(area, initial=0.0))))[0, 0])
        raise InputError(f"shell mesh: expected elements with non-degenerate corners, found element "
                         f"{e} with a zero corner area (nodes {conn[:, e].tolist()})")
    n = n / area[..., None]
    acc = np.zeros((3, X.shape[1]))
    for i in range(3):
        acc[i] = np.bincount(conn.ravel(), weights=n[..., i].T.ravel(), minlength=X.shape[1])
    nrm = np.linalg.norm(acc, axis=0)
    count = np.bincount(conn.ravel(), minlength=X.shape[1])
    used = count > 0
    coherence = np.where(used, nrm / np.maximum(count, 1), 1.0)
    if np.any(coherence < 0.5):
        k = int(np.argmin(coherence))
        raise InputError(f"shell mesh: expected consistently oriented elements (corner normals at a node "
                         f"within 60 deg), found node {k} where |sum of {count[k]} unit normals| / {count[k]} "
                         f"= {coherence[k]:.3f}; reorder element nodes or pass normals")
    acc[:, used] /= nrm[used]
    dots = np.einsum("eci,ice->ce", n, acc[:, conn])
    if np.any(dots <= 0.0):
        c, e = np.argwhere(dots <= 0.0)[0]
        raise InputError(f"shell mesh: expected consistently oriented elements, found element {e} "
                         f"whose normal at node {conn[c, e]} opposes the nodal average "
                         f"(cosine {dots[c, e]:.3f}); reorder its nodes")
    return acc


def _in_plane(eps: np.ndarray) -> np.ndarray:
    """Local in-plane Green-Lagrange strain tensor E_loc (2, 2, ...) from the local
    engineering strains eps (..., 5) = [e_11, e_22, 2 e_12, 2 e_13, 2 e_23]."""
    E12 = 0.5 * eps[..., 2]
    return np.stack([np.stack([eps[..., 0], E12]), np.stack([E12, eps[..., 1]])])


class _Points:
    """Reference quantities of the MITC4 element set at a tensor grid of points: in-plane
    points xi (2, nq) with weights wq, thickness coordinates r3 (nz,) with weights wz."""

    def __init__(self, shell, xi, wq, r3, wz, *, output_frame: bool = False):
        self.xi, self.r3 = np.asarray(xi, float), np.asarray(r3, float)
        self.h, self.dh = quad_shape(self.xi)                       # (4, nq), (4, 2, nq)
        self.wt13, self.wt23 = shell._tie_weights(self.xi)           # (nt, nq) each
        Xe, De = shell._Xe, shell._De                                # (ne, 4, 3)
        Ga = np.einsum("kaq,eki->eqai", self.dh, Xe)                 # (ne, nq, 2, 3)
        Gb = np.einsum("kaq,eki->eqai", self.dh, De)
        G3 = np.einsum("kq,eki->eqi", self.h, De)                    # (ne, nq, 3)
        G = Ga[:, :, None] + self.r3[None, None, :, None, None] * Gb[:, :, None]   # (ne,nq,nz,2,3)
        G3z = np.broadcast_to(G3[:, :, None, :], G.shape[:3] + (3,))
        J = np.concatenate([G, G3z[:, :, :, None, :]], axis=3)       # rows G_1, G_2, G_3
        detJ = np.linalg.det(J)
        if np.any(detJ <= 0):
            e = int(np.argwhere(detJ <= 0)[0, 0])
            raise InputError(f"MITC4: expected a positive volume Jacobian, found {detJ.min():.3e} in "
                             f"element {e} (nodes {shell.conn[:, e].tolist()}): distorted element, "
                             f"or directors against the element orientation")
        self.detJ = detJ
        self.dV = detJ * np.asarray(wq)[None, :, None] * np.asarray(wz)[None, None, :]
        self.Ga, self.Gb, self.G3 = Ga, Gb, G3
        # local Cartesian frame (eq. 4.11) and the strain transformation Q (eq. 4.10)
        e3 = G3z / np.linalg.norm(G3z, axis=-1, keepdims=True)
        if output_frame:
            # results frame: eq. 4.16 at the point (e_1 = e_y x e_3 normalised, e_z if parallel)
            e1 = np.cross(np.array([0.0, 1.0, 0.0]), e3)
            par = np.linalg.norm(e1, axis=-1) < 1e-8
            e1[par] = np.array([0.0, 0.0, 1.0])
            e1 -= np.einsum("...i,...i->...", e1, e3)[..., None] * e3
        else:
            e1 = np.cross(G[:, :, :, 1], e3)
        e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
        e2 = np.cross(e3, e1)
        Ev = np.stack([e1, e2, e3], axis=-2)                         # rows e_m
        self.frame = Ev
        Ginv = np.linalg.inv(J)                                      # columns G^i
        T = np.einsum("...mj,...ji->...mi", Ev, Ginv)                # T_mi = e_m . G^i
        basis = np.zeros((5, 3, 3))
        basis[0, 0, 0] = basis[1, 1, 1] = 1.0
        basis[2, 0, 1] = basis[2, 1, 0] = 0.5
        basis[3, 0, 2] = basis[3, 2, 0] = 0.5
        basis[4, 1, 2] = basis[4, 2, 1] = 0.5
        el = np.einsum("...mi,pij,...nj->...pmn", T, basis, T)        # (..., 5, 3, 3)
        self.Q = np.stack([el[..., 0, 0], el[..., 1, 1], 2 * el[..., 0, 1],
                           2 * el[..., 0, 2], 2 * el[..., 1, 2]], axis=-1)   # (..., p, out)
        self.Q = np.swapaxes(self.Q, -1, -2)                          # (..., out, p)
        D = shell.section.lamina_matrix()
        self.C = np.einsum("...ba,bc,...cd->...ad", self.Q, D, self.Q)   # C~ = Q^T D Q

    #: the per-element arrays (leading axis: elements)
    _PER_ELEMENT = ("Ga", "Gb", "G3", "detJ", "dV", "Q", "C")

    def take(self, elements: slice) -> "_Points":
        """The same points on the ``elements`` (a slice) only (views of the arrays)."""
        out = copy.copy(self)
        for name in self._PER_ELEMENT:
            setattr(out, name, getattr(self, name)[elements])
        return out


class MITC4Shell:
    """A set of MITC4 shell elements on the 5-dof nodes of a :class:`DofMap` (module docstring).

    Parameters
    ----------
    X : ndarray (3, n_nodes)
        Reference positions of all nodes of ``dofmap`` (only the shell's nodes are read).
    conn : ndarray (4, ne)
        Global nodes of each element, counter-clockwise seen from the side the directors
        point to (scikit-fem ``MeshQuad.t`` order).
    section : ShellSection
    dofmap : DofMap
        The shell's nodes must have 5 dofs (translations, rotations about V_1 and V_2).
    normals : ndarray (3, n_nodes), optional
        Reference directors V_n^0 (default: :func:`nodal_normals` of the mesh). Pass the exact
        surface normals of a curved shell where known; each is turned to the side of the
        element normals g_1 x g_2 (the mesh orientation decides the side).
    shear : {"mitc", "direct"}
        Mixed-interpolated (eqs. 4.17-4.18) or displacement-based transverse shear.
    law : {"svk", "tension-field"} or MembraneLaw
        In-plane lamina law (module docstring): St.Venant-Kirchhoff (eq. 4.9, default) or the
        tension-field law of :mod:`tmfem.fem.tension_field` (a law object must be built on
        ``section``, e.g. ``TensionFieldLaw(section, eta=...)``).

    Attributes
    ----------
    frames : ndarray (n_nodes, 3, 3)
        Reference triads [V_1 V_2 V_n] of eq. 4.16 (identity at nodes outside the shell): the
        ``frames`` of :meth:`tmfem.fem.element.State.reference`.
    """

    def __init__(self, *, X, conn, section: ShellSection, dofmap: DofMap, normals=None,
                 shear: str = "mitc", law="svk"):
        X = np.asarray(X, dtype=float)
        conn = np.asarray(conn, dtype=np.int64)
        if X.shape != (3, dofmap.n_nodes):
            raise InputError(f"MITC4: expected reference positions of shape (3, {dofmap.n_nodes}), "
                             f"found {X.shape}")
        if conn.ndim != 2 or conn.shape[0] != 4 or conn.shape[1] == 0:
            raise InputError(f"MITC4: expected connectivity of shape (4, ne) with ne >= 1, found {conn.shape}")
        dofmap.check_element_nodes(conn, 5, element="MITC4",
                                   dofs="5 dofs (3 translations, 2 rotations)")
        self.X, self.conn, self.section, self.dofmap = X, conn, section, dofmap
        self.law = membrane_law(law, section)
        nodes = self.nodes = np.unique(conn)
        if normals is None:
            Vn = nodal_normals(X, conn)
        else:
            Vn = np.asarray(normals, dtype=float)
            if Vn.shape != (3, dofmap.n_nodes):
                raise InputError(f"MITC4: expected normals of shape (3, {dofmap.n_nodes}), found {Vn.shape}")
            # orient the given directors to the side of the element normals g_1 x g_2
            side = np.einsum("in,in->n", Vn, nodal_normals(X, conn))
            Vn = Vn * np.where(side < 0, -1.0, 1.0)
        frames = np.broadcast_to(np.eye(3), (dofmap.n_nodes, 3, 3)).copy()
        frames[nodes] = director_frames(Vn[:, nodes])
        self.frames = frames
        self.ne = conn.shape[1]
        self.half = 0.5 * section.thickness
        self._Xe = np.transpose(X[:, conn], (2, 1, 0))                        # (ne, 4, 3)
        self._De = self.half * np.transpose(frames[conn][..., 2], (1, 0, 2))  # (ne, 4, 3)
        from skfem.quadrature import get_quadrature
        from skfem.refdom import RefQuad
        xq, wq = get_quadrature(RefQuad, 3)
        if shear not in ("mitc", "direct"):
            raise InputError(f"MITC4: expected shear 'mitc' or 'direct', found {shear!r}")
        self.shear = shear
        if shear == "mitc":
            # tying points (eqs. 4.17-4.18): A, C for eps_13; D, B for eps_23
            self._tie_xi = np.array([[0.5, 0.5, 1.0, 0.0], [1.0, 0.0, 0.5, 0.5]])
        else:
            # displacement-based shear at the 2 x 2 Gauss points (locks in the thin limit)
            self._tie_xi = np.concatenate([xq, xq], axis=1)
        self._gxi = xq
        nt = self._tie_xi.shape[1] // 2
        self._nt = nt
        self._tie_h, self._tie_dh = quad_shape(self._tie_xi)
        Gt = np.einsum("kat,eki->etai", self._tie_dh, self._Xe)              # (ne, 2 nt, 2, 3)
        self._tie_G = np.stack([Gt[:, :nt, 0], Gt[:, nt:, 1]], axis=1)      # (ne, 2 comp, nt, 3)
        self._tie_G3 = np.einsum("kt,eki->eti", self._tie_h, self._De).reshape(self.ne, 2, nt, 3)
        rz, wz = np.polynomial.legendre.leggauss(2)
        self._gauss = _Points(self, xq, wq, rz, wz)
        self._asm = Assembler(dofmap.element_dofs(conn, rotations=True), dofmap.ndof)
        self._M = None
        self._part_cache = None
        self._result_points = MemoryMemo(RESULT_POINTS_KEPT)

    # ------------------------------------------------------------------ kinematics
    def _tie_weights(self, xi):
        """Weights (nt, m) of the tying-point values at points xi (2, m): eq. 4.17,
        eps_13 = xi_2 A + (1 - xi_2) C, eps_23 = xi_1 D + (1 - xi_1) B (``shear="mitc"``), or the
        bilinear interpolation of the Gauss-point values (``shear="direct"``)."""
        x1, x2 = np.asarray(xi, float)
        if self.shear == "mitc":
            return np.stack([x2, 1.0 - x2]), np.stack([x1, 1.0 - x1])
        g = self._gxi
        lo, hi = g.min(axis=1), g.max(axis=1)
        t1, t2 = (x1[None] - lo[0]) / (hi[0] - lo[0]), (x2[None] - lo[1]) / (hi[1] - lo[1])
        a1 = np.where(np.isclose(g[0], lo[0])[:, None], 1 - t1, t1)
        a2 = np.where(np.isclose(g[1], lo[1])[:, None], 1 - t2, t2)
        return a1 * a2, a1 * a2

    def _nodal(self, state):
        """Element nodal displacements u (ne, 4, 3), directors d = (a/2) V_n (ne, 4, 3),
        director changes w = d - D and the rotating triads (ne, 4, 3, 3) at ``state``."""
        if state.R is None or state.frames is None:
            raise InputError("MITC4: expected a state with nodal rotations and frames "
                             "(State.reference(X, dofmap, frames=shell.frames))")
        x = np.asarray(state.x)
        u = np.transpose(x[:, self.conn] - self.X[:, self.conn], (2, 1, 0))
        Rn = state.R[self.conn]                                              # (4, ne, 3, 3)
        V = np.transpose(np.matmul(Rn, state.frames[self.conn]), (1, 0, 2, 3))  # (ne, 4, 3, 3): V1 V2 Vn
        d = self.half * V[..., 2]
        # w = (a/2)(R - I) V_n^0, computed without cancellation from the rotation matrices
        RmI = np.transpose(Rn, (1, 0, 2, 3)) - np.eye(3)
        w = np.einsum("ekij,ekj->eki", RmI, self._De)
        return u, d, w, V

    def _strains(self, pts: _Points, u, d, w):
        """Covariant strains c (ne, nq, nz, 5) and current base vectors at the points and at
        the tying points."""
        ua = np.einsum("kaq,eki->eqai", pts.dh, u)                           # (ne, nq, 2, 3)
        ub = np.einsum("kaq,eki->eqai", pts.dh, w)
        Ux = ua[:, :, None] + pts.r3[None, None, :, None, None] * ub[:, :, None]  # (ne,nq,nz,2,3)
        G = pts.Ga[:, :, None] + pts.r3[None, None, :, None, None] * pts.Gb[:, :, None]
        g = G + Ux
        dot = "...i,...i->..."
        e11 = 2 * np.einsum(dot, Ux[..., 0, :], G[..., 0, :]) + np.einsum(dot, Ux[..., 0, :], Ux[..., 0, :])
        e22 = 2 * np.einsum(dot, Ux[..., 1, :], G[..., 1, :]) + np.einsum(dot, Ux[..., 1, :], Ux[..., 1, :])
        g12 = (np.einsum("...i,...i->...", Ux[..., 0, :], G[..., 1, :])
               + np.einsum("...i,...i->...", G[..., 0, :], Ux[..., 1, :])
               + np.einsum("...i,...i->...", Ux[..., 0, :], Ux[..., 1, :]))
        # tying points at r3 = 0: gamma_a3 = u_a.G_3 + G_a.u_3 + u_a.u_3 (A, C for a = 1; D, B for a = 2)
        ut = np.einsum("kat,eki->etai", self._tie_dh, u)
        nt = self._nt
        ut = np.stack([ut[:, :nt, 0], ut[:, nt:, 1]], axis=1)                # (ne, 2, nt, 3)
        u3 = np.einsum("kt,eki->eti", self._tie_h, w).reshape(self.ne, 2, nt, 3)
        gam_t = (np.einsum("ecti,ecti->ect", ut, self._tie_G3) + np.einsum("ecti,ecti->ect", self._tie_G, u3)
                 + np.einsum("ecti,ecti->ect", ut, u3))                       # (ne, 2, 2)
        g13 = np.einsum("tq,et->eq", pts.wt13, gam_t[:, 0])
        g23 = np.einsum("tq,et->eq", pts.wt23, gam_t[:, 1])
        nz = pts.r3.size
        c = np.stack([0.5 * e11, 0.5 * e22, g12,
                      np.repeat(g13[:, :, None], nz, axis=2), np.repeat(g23[:, :, None], nz, axis=2)], axis=-1)
        gt = self._tie_G + ut                                                # current g_a at tying points
        g3t = self._tie_G3 + u3
        return c, g, gt, g3t

    # ------------------------------------------------------------------ share protocol
    @property
    def element_dofs(self) -> np.ndarray:
        """(ne, 20) global dofs of each element, node by node [u_x, u_y, u_z, alpha, beta]
        (the share protocol of :class:`tmfem.fem.distributed.DistributedElements`)."""
        return self._asm.dofs

    def _part(self, elements: slice) -> "MITC4Shell":
        """This element set restricted to the ``elements`` (a slice): a shallow copy with
        the per-element reference arrays sliced (kept for the next call with that slice:
        a rank of a distributed assembly asks for the same block every time)."""
        if elements == slice(None):
            return self
        key = elements.indices(self.ne)
        if self._part_cache is not None and self._part_cache[0] == key:
            return self._part_cache[1]
        part = copy.copy(self)
        part.conn = self.conn[:, elements]
        part.ne = part.conn.shape[1]
        for name in ("_Xe", "_De", "_tie_G", "_tie_G3"):
            setattr(part, name, getattr(self, name)[elements])
        part._gauss = self._gauss.take(elements)
        part._part_cache = None
        part._result_points = MemoryMemo(RESULT_POINTS_KEPT)
        self._part_cache = (key, part)
        return part

    # ------------------------------------------------------------------ element arrays
    def element_arrays(self, state, *, tangent: bool = True, elements: slice = slice(None)):
        """Element internal forces fe (ne, 20) and tangents Ke (ne, 20, 20) (or None) of the
        ``elements`` (a slice; default all), local dofs node by node [u_x, u_y, u_z, alpha,
        beta] (eqs. 4.4-4.6 with the MITC shear of eqs. 4.17-4.18)."""
        return self._part(elements)._element_arrays(state, tangent=tangent)

    def _element_arrays(self, state, *, tangent: bool = True):
        """:meth:`element_arrays` of all elements of this set."""
        u, d, w, V = self._nodal(state)
        pts = self._gauss
        c, g, gt, g3t = self._strains(pts, u, d, w)
        ne, nq, nz = c.shape[:3]
        S, C = self._lamina(pts, c, tangent=tangent)                         # contravariant 2nd PK
        Sw = S * pts.dV[..., None]
        dh, r3 = pts.dh, pts.r3
        # B of the in-plane rows in extended nodal dofs (x_k, d_k): (ne, nq, nz, 3, 4, 2, 3)
        Bm = np.empty((ne, nq, nz, 3, 4, 2, 3))
        h1 = np.transpose(dh[:, 0, :])[None, :, None, :, None]               # (1, nq, 1, 4, 1)
        h2 = np.transpose(dh[:, 1, :])[None, :, None, :, None]
        g1 = g[..., 0, :][:, :, :, None, :]                                  # (ne, nq, nz, 1, 3)
        g2 = g[..., 1, :][:, :, :, None, :]
        Bm[:, :, :, 0, :, 0] = h1 * g1
        Bm[:, :, :, 1, :, 0] = h2 * g2
        Bm[:, :, :, 2, :, 0] = h1 * g2 + h2 * g1
        Bm[:, :, :, :, :, 1] = r3[None, None, :, None, None, None] * Bm[:, :, :, :, :, 0]
        # shear rows at the tying points: d gamma_a3 / d x_k = h_k,a g_3, / d d_k = h_k g_a
        nt = self._nt
        Bt = np.empty((ne, 2, nt, 4, 2, 3))                                  # (ne, comp, pt, k, x/d, 3)
        tdh = self._tie_dh.reshape(4, 2, 2, nt)                              # (k, a, comp, pt)
        th = self._tie_h.reshape(4, 2, nt)                                   # (k, comp, pt)
        for comp in range(2):
            Bt[:, comp, :, :, 0] = np.transpose(tdh[:, comp, comp, :])[None, :, :, None] * g3t[:, comp, :, None, :]
            Bt[:, comp, :, :, 1] = np.transpose(th[:, comp, :])[None, :, :, None] * gt[:, comp, :, None, :]
        Bs = np.stack([np.einsum("tq,etkxi->eqkxi", pts.wt13, Bt[:, 0]),
                       np.einsum("tq,etkxi->eqkxi", pts.wt23, Bt[:, 1])], axis=2)   # (ne, nq, 2, 4, 2, 3)
        B = np.concatenate([Bm.reshape(ne, nq, nz, 3, 24),
                            np.broadcast_to(Bs.reshape(ne, nq, 1, 2, 24), (ne, nq, nz, 2, 24))], axis=3)
        f_ext = np.einsum("eqzs,eqzsj->ej", Sw, B)                           # (ne, 24)
        L = self._lam(V)                                                     # (ne, 4, 6, 5) per node
        fe = np.einsum("ekab,eka->ekb", L, f_ext.reshape(ne, 4, 6)).reshape(ne, 20)
        if not tangent:
            return fe, None
        Bf = B.reshape(ne, nq * nz * 5, 24)
        CB = np.einsum("eqzst,eqztj->eqzsj", C * pts.dV[..., None, None], B).reshape(ne, nq * nz * 5, 24)
        Kx = np.matmul(np.swapaxes(Bf, 1, 2), CB)                            # (ne, 24, 24)
        # initial-stress part: scalar couplings of (x_k, d_k) pairs, times I_3
        Smat = np.empty((ne, nq, nz, 2, 2))
        Smat[..., 0, 0], Smat[..., 1, 1] = Sw[..., 0], Sw[..., 1]
        Smat[..., 0, 1] = Smat[..., 1, 0] = Sw[..., 2]
        A = np.einsum("kaq,eqzab,lbq->eqzkl", dh, Smat, dh)
        H = np.zeros((ne, 4, 2, 4, 2))
        H[:, :, 0, :, 0] = A.sum(axis=(1, 2))
        H[:, :, 0, :, 1] = np.einsum("eqzkl,z->ekl", A, r3)
        H[:, :, 1, :, 0] = H[:, :, 0, :, 1]
        H[:, :, 1, :, 1] = np.einsum("eqzkl,z->ekl", A, r3**2)
        # transverse shear: S^a3 at the tying points, Delta delta gamma_a3 = h_k,a h_l (dx_k . Dd_l) + sym
        St13 = np.einsum("eqz,tq->et", Sw[..., 3], pts.wt13)
        St23 = np.einsum("eqz,tq->et", Sw[..., 4], pts.wt23)
        for comp, St in ((0, St13), (1, St23)):
            Cxd = np.einsum("et,kt,lt->ekl", St, tdh[:, comp, comp, :], th[:, comp, :])
            H[:, :, 0, :, 1] += Cxd
            H[:, :, 1, :, 0] += np.swapaxes(Cxd, 1, 2)
        Kx += np.einsum("ekxly,ij->ekxilyj", H, np.eye(3)).reshape(ne, 24, 24)
        Lb = self._lam_block(L)                                              # (ne, 24, 20)
        Ke = np.matmul(np.swapaxes(Lb, 1, 2), np.matmul(Kx, Lb))
        # second variation of the directors: -(alpha alpha' + beta beta') V_n . (dW/dV_n)
        m = self.half * np.einsum("eki,eki->ek", f_ext.reshape(ne, 4, 6)[:, :, 3:], V[..., 2])
        idx = 5 * np.arange(4)[:, None] + np.array([3, 4])[None, :]
        Ke[:, idx, idx] -= m[:, :, None]
        return fe, Ke

    def _local_law(self, eps, *, tangent: bool = True):
        """Tension-field lamina (module docstring): local stresses s_loc (..., 5) and tangent
        D_loc (..., 5, 5) (or None) from the local engineering strains eps (..., 5)."""
        Sl, Dl = self.law.stress(_in_plane(eps), tangent=tangent)
        kG = self.section.shear_factor * self.law.mu
        s = np.concatenate([np.stack([Sl[0, 0], Sl[1, 1], Sl[0, 1]], axis=-1), kG * eps[..., 3:]],
                           axis=-1)
        if not tangent:
            return s, None
        D = np.zeros(eps.shape + (5,))
        D[..., :3, :3] = np.moveaxis(Dl, (0, 1), (-2, -1))
        D[..., 3, 3] = D[..., 4, 4] = kG
        return s, D

    def _lamina(self, pts: _Points, c, *, tangent: bool = True):
        """Contravariant stress S (..., 5) and tangent C = dS/dc (..., 5, 5) (or None) at the
        points from the covariant strains c: C~ c and C~ for SVK (eq. 4.10), Q^T s_loc and
        Q^T D_loc Q for the tension-field lamina (module docstring)."""
        if self.law.name == "svk":
            return np.einsum("eqzab,eqzb->eqza", pts.C, c), pts.C
        s, D = self._local_law(np.einsum("...ap,...p->...a", pts.Q, c), tangent=tangent)
        S = np.einsum("...ap,...a->...p", pts.Q, s)
        if not tangent:
            return S, None
        return S, np.einsum("...ba,...bc,...cd->...ad", pts.Q, D, pts.Q)

    def _lam(self, V):
        """Per-node map (ne, 4, 6, 5) from [u, alpha, beta] to the extended [x, d] variations:
        delta x = delta u, delta d = (a/2)(-V_2 alpha + V_1 beta)."""
        ne = V.shape[0]
        L = np.zeros((ne, 4, 6, 5))
        L[:, :, :3, :3] = np.eye(3)
        L[:, :, 3:, 3] = -self.half * V[..., 1]
        L[:, :, 3:, 4] = self.half * V[..., 0]
        return L

    @staticmethod
    def _lam_block(L):
        ne = L.shape[0]
        Lb = np.zeros((ne, 4, 6, 4, 5))
        k = np.arange(4)
        Lb[:, k, :, k, :] = np.transpose(L, (1, 0, 2, 3))
        return Lb.reshape(ne, 24, 20)

    # ------------------------------------------------------------------ Element protocol
    def internal(self, state, *, tangent: bool = True):
        """Internal force (ndof,) and tangent (csr) in the global numbering (eqs. 4.4-4.6)."""
        fe, Ke = self.element_arrays(state, tangent=tangent)
        return self._asm.vector(fe), (self._asm.matrix(Ke) if tangent else None)

    def energy(self, state, *, elements: slice = slice(None)) -> float:
        """Strain energy [J] of the ``elements`` (a slice; default all): int c . C~ c / 2 dV
        (SVK, eq. 4.9), or int W(E_loc) + k G ((2 e_13)^2 + (2 e_23)^2) / 2 dV (tension-field
        lamina)."""
        return self._part(elements)._energy(state)

    def _energy(self, state) -> float:
        """:meth:`energy` of all elements of this set."""
        u, d, w, _ = self._nodal(state)
        pts = self._gauss
        c = self._strains(pts, u, d, w)[0]
        if self.law.name == "svk":
            return 0.5 * float(np.einsum("eqza,eqzab,eqzb,eqz->", c, pts.C, c, pts.dV))
        eps = np.einsum("...ap,...p->...a", pts.Q, c)
        W = self.law.energy_density(_in_plane(eps)) \
            + 0.5 * self.section.shear_factor * self.law.mu * (eps[..., 3]**2 + eps[..., 4]**2)
        return float(np.sum(W * pts.dV))

    def mass(self, state=None) -> sp.csr_matrix:
        """Consistent mass with rotary inertia int rho N^T N dV (ndof, ndof); the rotational
        dofs are mapped with the triads of ``state`` (default: the reference triads): the
        assembled :meth:`element_mass`."""
        if state is None and self._M is not None:
            return self._M
        M = self._asm.matrix(self.element_mass(state))
        if state is None:
            self._M = M
        return M

    def element_mass(self, state=None, *, elements: slice = slice(None)) -> np.ndarray:
        """Element mass matrices (ne, 20, 20) of the ``elements`` (a slice; default all) at
        the triads of ``state`` (default: the reference triads), local dofs as in
        :meth:`element_arrays` (the share protocol of
        :class:`tmfem.fem.distributed.DistributedElements`)."""
        return self._part(elements)._element_mass(state)

    def _element_mass(self, state) -> np.ndarray:
        """:meth:`element_mass` of all elements of this set."""
        pts = self._gauss
        rho = self.section.rho
        hh = np.einsum("kq,lq->qkl", pts.h, pts.h)
        M0 = rho * np.einsum("qkl,eqz->ekl", hh, pts.dV)
        M1 = rho * np.einsum("qkl,eqz,z->ekl", hh, pts.dV, pts.r3)
        M2 = rho * np.einsum("qkl,eqz,z->ekl", hh, pts.dV, pts.r3**2)
        H = np.stack([np.stack([M0, M1], axis=-1), np.stack([M1, M2], axis=-1)], axis=2)  # (ne, k, x/d, l, x/d)
        Mx = np.einsum("ekxly,ij->ekxilyj", H, np.eye(3)).reshape(self.ne, 24, 24)
        if state is None:
            V = np.transpose(self.frames[self.conn], (1, 0, 2, 3))
        else:
            V = self._nodal(state)[3]
        Lb = self._lam_block(self._lam(V))
        return np.matmul(np.swapaxes(Lb, 1, 2), np.matmul(Mx, Lb))

    # ------------------------------------------------------------------ results
    #: thickness points and weights of the results: the surfaces r_3 = -1, 0, 1 and the
    #: 2-point Gauss rule
    _THICKNESS = {"surf": (np.array([-1.0, 0.0, 1.0]), np.ones(3)),
                  "gauss": np.polynomial.legendre.leggauss(2)}

    def _results_at(self, xi, thickness: str) -> _Points:
        """The reference quantities (:class:`_Points`, results frame of eq. 4.16) at one
        in-plane point xi and the ``thickness`` points of :attr:`_THICKNESS`; they depend on
        the reference geometry only, so they are made once per point (the last :data:`RESULT_POINTS_KEPT` kept)."""
        xi = np.asarray(xi, dtype=float).reshape(2, 1)
        key = (float(xi[0, 0]), float(xi[1, 0]), thickness)
        return self._result_points.get(key, lambda: _Points(self, xi, np.ones(1), *self._THICKNESS[thickness],
                                                            output_frame=True))

    def stresses(self, state, *, xi=(0.5, 0.5)):
        """Local 2nd Piola-Kirchhoff stresses at one in-plane point of every element.

        The results frame is that of eq. 4.16 at the point (e_3 along G_3, e_1 = e_y x e_3
        normalised, e_z where e_3 is parallel to e_y; the same on every element of a flat
        mesh), the stresses D Q_out c of the isotropic lamina law in that frame (the tension-field
        lamina's s_loc(Q_out c), the law being isotropic).

        Returns ``dict`` with ``sigma`` (ne, 3, 5): [s11, s22, s12, s13, s23] in that frame
        at r_3 = -1, 0, 1 (bottom, mid, top), ``von_mises``
        (ne, 3) of those (with the transverse shear), ``N`` (ne, 3) membrane forces
        [N11, N22, N12] and ``M`` (ne, 3) bending moments [M11, M22, M12] per unit length
        (2-point Gauss through the thickness) and ``Qs`` (ne, 2) transverse shear forces.
        """
        u, d, w, _ = self._nodal(state)
        D = self.section.lamina_matrix()
        out = {}
        for key in ("surf", "gauss"):
            pts = self._results_at(xi, key)
            c = self._strains(pts, u, d, w)[0][:, 0]                          # (ne, nz, 5)
            if self.law.name == "svk":
                out[key] = np.einsum("ab,ezbc,ezc->eza", D, pts.Q[:, 0], c)
            else:
                out[key] = self._local_law(np.einsum("ezbc,ezc->ezb", pts.Q[:, 0], c), tangent=False)[0]
        sig = out["surf"]
        vm = von_mises(np.moveaxis(sig, -1, 0))
        zg = self._THICKNESS["gauss"][0] * self.half                          # physical z of the Gauss points
        sg = out["gauss"]
        N = self.half * sg[..., :3].sum(axis=1)
        M = self.half * np.einsum("eza,z->ea", sg[..., :3], zg)
        Qs = self.half * sg[..., 3:].sum(axis=1)
        return {"sigma": sig, "von_mises": vm, "N": N, "M": M, "Qs": Qs}


    def wrinkling(self, state, *, xi=(0.5, 0.5)) -> dict:
        """States of the lamina law at one in-plane point of every element, at the two
        thickness Gauss points: :func:`tmfem.fem.tension_field.element_wrinkling` of the local
        in-plane strains in the results frame of :meth:`stresses` (``direction``: the tension
        direction in that frame, [e_1, e_2, 0]). With the SVK law these are the states the
        lamina would take if it could wrinkle. ``direction_xyz`` (3, ne): the same tension
        direction in the global axes, d = n_1 e_1 + n_2 e_2 with the results frame of the
        reference geometry (one frame per element: e_1, e_2 do not vary through the
        thickness), a material direction of the reference surface as the Green-Lagrange
        strain it comes from."""
        u, d, w, _ = self._nodal(state)
        pts = self._results_at(xi, "gauss")
        c = self._strains(pts, u, d, w)[0]
        eps = np.einsum("...ap,...p->...a", pts.Q, c).reshape(self.ne, -1, 5)
        out = element_wrinkling(self.law, _in_plane(eps))
        out["direction_xyz"] = np.einsum("emi,me->ie", pts.frame[:, 0, 0, :2], out["direction"][:2])
        return out


class ShellPressure:
    """Pressure p [Pa] on the mid-surface of quadrilateral shell elements (a load, not a
    stiffness): f_k = int p h_k (g_1 x g_2) dxi on the current (``follower=True``) or the
    reference (dead) surface, along the side the element normal g_1 x g_2 points to.

    The follower load has the load stiffness dF/dx (non-symmetric in general):
    dF_k/dx_l = int p h_k (h_l,2 [g_1]x - h_l,1 [g_2]x) dxi.

    Parameters
    ----------
    X : (3, n_nodes) reference positions; conn : (4, ne) nodes; dofmap : DofMap;
    p : float or (ne,) pressure per element [Pa]; follower : bool.
    """

    def __init__(self, *, X, conn, dofmap: DofMap, p, follower: bool = True):
        X = np.asarray(X, dtype=float)
        conn = np.asarray(conn, dtype=np.int64)
        if conn.ndim != 2 or conn.shape[0] != 4:
            raise InputError(f"pressure: expected connectivity of shape (4, ne), found {conn.shape}")
        p = np.broadcast_to(np.asarray(p, dtype=float), (conn.shape[1],)).copy()
        if not np.all(np.isfinite(p)):
            raise InputError("pressure: expected finite pressures, found non-finite values")
        self.X, self.conn, self.dofmap, self.p, self.follower = X, conn, dofmap, p, bool(follower)
        from skfem.quadrature import get_quadrature
        from skfem.refdom import RefQuad
        xq, self._wq = get_quadrature(RefQuad, 3)
        self._h, self._dh = quad_shape(xq)
        self._asm = Assembler(dofmap.element_dofs(conn), dofmap.ndof)

    def load(self, state, *, tangent: bool = True):
        """External force (ndof,) and, for a follower load, its derivative dF/du (csr; None
        for a dead load or ``tangent=False``)."""
        x = self.X if not self.follower else np.asarray(state.x)
        xe = x[:, self.conn]                                                 # (3, 4, ne)
        g = np.einsum("kaq,ike->eqai", self._dh, xe)                         # (ne, nq, 2, 3)
        n = np.cross(g[:, :, 0], g[:, :, 1])                                 # (ne, nq, 3)
        pw = self.p[:, None] * self._wq[None, :]
        fe = np.einsum("eq,kq,eqi->eki", pw, self._h, n).reshape(-1, 12)
        f = self._asm.vector(fe)
        if not (tangent and self.follower):
            return f, None
        K = (np.einsum("eq,kq,lq,eqij->ekilj", pw, self._h, self._dh[:, 1], skew(g[:, :, 0]))
             - np.einsum("eq,kq,lq,eqij->ekilj", pw, self._h, self._dh[:, 0], skew(g[:, :, 1])))
        return f, self._asm.matrix(K.reshape(-1, 12, 12))

    def nodal_areas(self) -> np.ndarray:
        """Consistent nodal areas int h_k |G_1 x G_2| dxi (4, ne) of the reference surface."""
        g = np.einsum("kaq,ike->eqai", self._dh, self.X[:, self.conn])
        a = np.linalg.norm(np.cross(g[:, :, 0], g[:, :, 1]), axis=-1)
        return np.einsum("q,kq,eq->ke", self._wq, self._h, a)

    def internal(self, state, *, tangent: bool = True):
        """The load as an element set: internal force -F and tangent -dF/du."""
        f, K = self.load(state, tangent=tangent)
        if tangent and K is None:
            K = sp.csr_matrix((self.dofmap.ndof,) * 2)
        return -f, (-K if tangent else None)

    def energy(self, state) -> float:
        """Potential -F . u of a dead pressure; a follower pressure on an open surface has
        none (refused)."""
        if self.follower:
            raise InputError("pressure: a follower pressure has no potential energy on an open "
                             "surface; expected follower=False for energy()")
        f, _ = self.load(state, tangent=False)
        u = (np.asarray(state.x) - self.X).T
        tr = self.dofmap.translation_dofs(np.arange(self.dofmap.n_nodes))
        return -float(f[tr.ravel()] @ u.ravel())

    def mass(self, state=None):
        """A load carries no mass (at any ``state``)."""
        return sp.csr_matrix((self.dofmap.ndof,) * 2)
