"""Four-node total-Lagrangian membrane element (dissertation 4.4.1, eqs. 4.25-4.28).

The reference configuration is the flat, undeformed membrane polygon (the mesh in the
floating frame O_f, coordinates X = (x_f, y_f)). The current position x(X) of each
material point is three-dimensional and interpolated with the bilinear functions of
eq. 4.26, so the deformation gradient F = dx/dX is 3 x 2 and the covariant base vectors of
eq. 4.8 are its columns. The in-plane Green-Lagrange strain (eq. 4.7) is

    E = (F^T F - I) / 2                          (2 x 2),

a membrane law (:mod:`tmfem.fem.tension_field`) gives the second Piola-Kirchhoff stress S(E)
and its material tangent D = dS/dE: by default the plane-stress St.Venant-Kirchhoff law
(eq. 4.9 with the isotropic plane-stress constitutive tensor),

    S = lam tr(E) I + 2 mu E,   lam = E_mod nu / (1 - nu^2),   mu = E_mod / (2 (1 + nu)),

or, with ``law="tension-field"``, the relaxed (wrinkling) law of that module. The linearised
virtual work of eq. 4.4 gives the internal force and tangent

    f(v)      = h int  (F S) : grad v  dA,
    K(du, v)  = h int  sym(F^T grad du) : D : sym(F^T grad v)      (material, K_L)
              + h int  S : (grad du^T grad v)  dA                  (initial stress, K_NL).

There is no bending or transverse-shear stiffness (assumption a of 4.4). Both forms are
scikit-fem forms on ``ElementVector(ElementQuad1(), dim=3)`` over the 2-D mesh, where
``grad(u)`` has shape (3, 2, ne, nqp). Integration is 2 x 2 Gauss.

Two implementations of the same residual and tangent are kept: the scikit-fem forms
(:meth:`MembraneTL.internal_forms`, the readable reference) and an einsum B-matrix kernel
assembled with a cached CSR pattern (:meth:`MembraneTL.internal`, used by the solvers; about
ten times faster since scikit-fem evaluates a vector form once per pair of the 12 local
dofs). The test suite checks that they agree to round-off.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.assembly import Assembler, element_dofs
from tmfem.fem.plane_stress import principal_stresses, von_mises
from tmfem.fem.tension_field import element_wrinkling, membrane_law
from tmfem.mesh.polygon import MembraneMesh
from tmfem.system.materials import MembraneMaterial


def _forms():
    """The scikit-fem forms (built lazily so that importing this module stays cheap)."""
    from skfem import BilinearForm, LinearForm
    from skfem.helpers import grad

    @LinearForm
    def residual(v, w):
        # w['P'] = h F S (3, 2, ne, nqp): first Piola-Kirchhoff stress resultant
        return np.einsum("ia...,ia...->...", w["P"], grad(v))

    @BilinearForm
    def tangent(du, v, w):
        F, S, D, h = w["F"], w["S"], w["D"], w["h"]
        gu, gv = grad(du), grad(v)
        au = np.einsum("ia...,ib...->ab...", F, gu)
        av = np.einsum("ia...,ib...->ab...", F, gv)
        # Voigt strain variations [dE11, dE22, 2 dE12]
        eu = np.stack([au[0, 0], au[1, 1], au[0, 1] + au[1, 0]])
        ev = np.stack([av[0, 0], av[1, 1], av[0, 1] + av[1, 0]])
        material = np.einsum("v...,vw...,w...->...", ev, D, eu)
        geometric = np.einsum("ab...,ib...,ia...->...", S, gu, gv)
        return h * (material + geometric)

    return residual, tangent


def q1_gauss_arrays(p: np.ndarray, t: np.ndarray):
    """Shape functions N (4, ne, nqp), their reference-plane gradients dN (4, 2, ne, nqp) and
    the weights dx = |det J| w (ne, nqp) of four-node quadrilaterals (nodes p (2, nn),
    connectivity t (4, ne)) at scikit-fem's intorder-3 (2 x 2 Gauss) points: its reference
    element and quadrature (so the values equal those of ``Basis(mesh, ElementQuad1(),
    intorder=3)``), evaluated in closed form on the elements (the Basis object holds ~10 kB
    per element, 4 GB transient at 4 x 320 x 320): J_ia = sum_k X_i(node k) dphi_k/dxi_a,
    dN_k = J^-T dphi_k. N is the same on every element (a broadcast view, no copy)."""
    from skfem import ElementQuad1
    from skfem.quadrature import get_quadrature
    from skfem.refdom import RefQuad
    Xq, Wq = get_quadrature(RefQuad, 3)
    el = ElementQuad1()
    ref = [el.lbasis(Xq, k) for k in range(4)]
    phi = np.stack([r[0] for r in ref])                               # (4, nqp)
    dphi = np.stack([r[1] for r in ref])                              # (4, 2, nqp)
    J = np.einsum("ike,kaq->iaeq", p[:, t], dphi)                     # (2, 2, ne, nqp)
    det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
    Jinv = np.stack([np.stack([J[1, 1], -J[0, 1]]), np.stack([-J[1, 0], J[0, 0]])]) / det
    dN = np.einsum("kaq,aieq->kieq", dphi, Jinv)                      # Jinv[a, i] = dxi_a/dX_i
    N = np.broadcast_to(phi[:, None, :], (4, t.shape[1], Xq.shape[1]))
    return N, dN, np.abs(det) * Wq


@dataclass
class MembraneStresses:
    """Stresses of the membrane at the 2 x 2 Gauss points of each element.

    Attributes
    ----------
    S : (3, ne, nqp)
        Second Piola-Kirchhoff stress (S_11, S_22, S_12) in the reference (floating-frame) axes.
    cauchy : (3, ne, nqp)
        Cauchy stress (sigma_11, sigma_22, sigma_12) in the reference axes rotated with the
        material (R^T sigma R, F = R U): the in-plane stress "in the floating frame".
    principal : (3, ne, nqp)
        Principal Cauchy stresses sigma_p1 >= sigma_p2 >= sigma_p3; the normal stress of the
        membrane is zero and enters as one of the three (eqs. 5.29-5.30).
    von_mises : (ne, nqp)
        von Mises stress of eq. 5.30.
    points : (2, ne, nqp)
        Reference coordinates of the Gauss points.
    """

    S: np.ndarray
    cauchy: np.ndarray
    principal: np.ndarray
    von_mises: np.ndarray
    points: np.ndarray

    @property
    def principal_elem(self) -> np.ndarray:
        """Element averages (3, ne) of the principal stresses."""
        return self.principal.mean(axis=-1)

    @property
    def von_mises_elem(self) -> np.ndarray:
        """Element averages (ne,) of the von Mises stress."""
        return self.von_mises.mean(axis=-1)


def point_matrix(skmesh, points) -> sp.csr_matrix:
    """Interpolation matrix (n_points, n_nodes) of a nodal bilinear field on a quadrilateral
    mesh at reference points: the bilinear interpolation of eqs. 4.25-4.26 (scikit-fem probes
    of ``ElementQuad1``, whose dof k is node k).

    The elements that hold the points are found on the whole mesh (scikit-fem's element
    finder) and the probes made on a mesh of those elements alone, so that the cost does not
    grow with the mesh beyond the search.

    Parameters
    ----------
    skmesh : skfem.MeshQuad
    points : array_like (2, n_points)
        Reference coordinates (x_f, y_f) [m].
    """
    from skfem import Basis, ElementQuad1, MeshQuad
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if pts.shape[0] != 2:
        raise InputError(f"membrane points: expected shape (2, n) of (x_f, y_f), found {pts.shape}")
    try:
        cells = skmesh.element_finder()(*pts)
    except ValueError as exc:
        raise InputError(f"membrane points {pts.T.tolist()}: outside the undeformed membrane "
                         f"({exc})") from None
    t = skmesh.t[:, np.unique(cells)]
    nodes, local = np.unique(t.ravel(), return_inverse=True)
    near = MeshQuad(skmesh.p[:, nodes], local.reshape(t.shape))
    P = Basis(near, ElementQuad1(), intorder=1).probes(pts).tocoo()
    return sp.csr_matrix((P.data, (P.row, nodes[P.col])), shape=(pts.shape[1], skmesh.p.shape[1]))


#: elements per chunk of the membrane kernel (:meth:`MembraneTL.element_arrays`)
KERNEL_CHUNK = 4096


class MembraneTL:
    """Total-Lagrangian membrane on a flat reference mesh (eqs. 4.25-4.28).

    Parameters
    ----------
    mesh : MembraneMesh
        Flat reference mesh; ``mesh.p`` (2, nn) are the reference coordinates.
    material : MembraneMaterial
        E, nu, rho, h.
    law : {"svk", "tension-field"} or MembraneLaw
        Membrane law S(E), D = dS/dE (:mod:`tmfem.fem.tension_field`; default "svk", eq. 4.9).

    Attributes
    ----------
    X : ndarray (3, nn)
        Reference positions (x_f, y_f, 0).
    basis : skfem.Basis
        ``Basis(mesh, ElementVector(ElementQuad1(), dim=3), intorder=3)``; its dofs are
        node-interleaved (dof = 3 node + component), as everywhere in tmfem. Built on first
        use (the reference forms of :meth:`internal_forms`): it holds ~13 kB per element,
        5 GB at 4 x 320 x 320; the kernels use the shape functions and their gradients at
        the same 2 x 2 Gauss points only.
    """

    def __init__(self, *, mesh: MembraneMesh, material: MembraneMaterial, law="svk"):
        p = np.asarray(mesh.p, dtype=float)
        if p.ndim != 2 or p.shape[0] != 2:
            raise InputError(f"membrane: expected a flat reference mesh with p of shape (2, nn), "
                             f"found {p.shape}")
        t = np.asarray(mesh.t)
        area = 0.5 * np.abs(np.sum(p[0, t] * p[1, np.roll(t, -1, axis=0)]
                                   - p[0, np.roll(t, -1, axis=0)] * p[1, t], axis=0))
        if np.any(area <= 0):
            bad = np.flatnonzero(area <= 0)
            raise InputError(f"membrane: expected reference elements of positive area, found "
                             f"{bad.size} of zero area (elements {bad[:5].tolist()})")
        self.mesh = mesh
        self.material = material
        self.skmesh = mesh.to_skfem()
        self._basis = None
        self.nn = p.shape[1]
        self.ndof = 3 * self.nn
        self.X = np.vstack([p, np.zeros((1, self.nn))])
        self.law = membrane_law(law, material)
        self._M = None
        self.ne = t.shape[1]
        self._gauss_cache = None
        self._asm_cache = None
        if not np.array_equal(np.asarray(self.skmesh.t), np.asarray(mesh.t)):
            raise RuntimeError("scikit-fem reordered the quadrilateral connectivity")

    @property
    def basis(self):
        """The vector scikit-fem basis (class docstring), built on first use."""
        if self._basis is None:
            from skfem import Basis, ElementQuad1, ElementVector
            basis = Basis(self.skmesh, ElementVector(ElementQuad1(), dim=3), intorder=3)
            nd = basis.nodal_dofs
            if not np.array_equal(nd, 3 * np.arange(self.nn)[None, :] + np.arange(3)[:, None]):
                raise RuntimeError("scikit-fem changed its vector dof numbering: expected "
                                   "node-interleaved nodal_dofs (dof = 3 node + component)")
            self._basis = basis
        return self._basis

    def _gauss(self, elements: slice, *, keep: bool = True):
        """Shape functions N (4, ne, nqp), gradients dN (4, 2, ne, nqp) and weights dx
        (ne, nqp) of the ``elements`` (a slice; :func:`q1_gauss_arrays`). The arrays of the
        last block asked for that the kept ones do not cover are kept (with ``keep``): a
        rank of a distributed assembly, which asks for its own share only, holds the data
        of its own elements only (~0.4 kB per element)."""
        lo, hi, step = elements.indices(self.ne)
        need = (lo, hi) if step == 1 else (0, self.ne)
        c = self._gauss_cache
        if c is None or need[0] < c[0] or need[1] > c[1]:
            arrays = q1_gauss_arrays(np.asarray(self.mesh.p, dtype=float),
                                      np.asarray(self.mesh.t)[:, need[0]:need[1]])
            c = (*need, *arrays)
            if keep:
                self._gauss_cache = c
        at = slice(lo - c[0], hi - c[0]) if step == 1 else np.arange(lo, hi, step)
        N, dN, dx = c[2:]
        return N[:, at], dN[:, :, at], dx[at]

    # ------------------------------------------------------------------ kinematics
    def _check_x(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if x.shape != (3, self.nn):
            raise InputError(f"membrane: expected current positions of shape (3, {self.nn}), "
                             f"found {x.shape}")
        return x

    def strain(self, x, *, elements: slice = slice(None)):
        """Deformation gradient F (3, 2, ne, nqp) and Green-Lagrange strain E (2, 2, ...) at
        the Gauss points (eq. 4.7) of the ``elements`` (a slice; default all):
        F_ia = delta_ia + sum_k u_i(node k) N_k,a, u = x - X (X = (x_f, y_f, 0))."""
        return self._strain_u(self._check_x(x) - self.X, elements)

    def _strain_u(self, u, elements: slice):
        """:meth:`strain` from the displacements u = x - X (3, nn)."""
        ue = u[:, self.skmesh.t[:, elements]]                           # (3, 4, ne)
        F = np.einsum("ike,kaeq->iaeq", ue, self._gauss(elements)[1], optimize=True)
        F[0, 0] += 1.0
        F[1, 1] += 1.0
        C = np.einsum("ia...,ib...->ab...", F, F)
        Eg = 0.5 * C
        Eg[0, 0] -= 0.5
        Eg[1, 1] -= 0.5
        return F, Eg

    def kinematics(self, x):
        """Deformation gradient F (3, 2, ne, nqp), Green-Lagrange E (2, 2, ...) and 2nd PK S
        (2, 2, ...) of the membrane law at the Gauss points (eqs. 4.7, 4.9)."""
        F, Eg = self.strain(x)
        S, _ = self.law.stress(Eg, tangent=False)
        return F, Eg, S

    def strain_energy(self, x, *, elements: slice = slice(None)) -> float:
        """Strain energy [J] at current positions x (3, nn): h int W(E) dA with the law's
        energy density (SVK: lam tr(E)^2 / 2 + mu E:E, the potential of eq. 4.9), of the
        ``elements`` (a slice; default all)."""
        _, Eg = self.strain(x, elements=elements)
        dens = self.law.energy_density(Eg)
        return self.material.h * float(np.sum(dens * self._gauss(elements)[2]))

    def wrinkling(self, x) -> dict:
        """State of each element under the mixed criterion of the law
        (:meth:`tmfem.fem.tension_field.MembraneLaw.state`) at current positions x (3, nn).

        Returns ``state`` (ne,) int8: the state (0 taut, 1 wrinkled, 2 slack) of most of the
        element's Gauss points (ties to the more relaxed state); ``fractions`` (3,) of Gauss
        points taut/wrinkled/slack; ``direction`` (3, ne): the tension (wrinkle-crest)
        direction in the reference plane (x_f, y_f, 0), the mean of the doubled angles over the
        element's wrinkled Gauss points, zero where none is wrinkled; ``state_qp`` (ne, nqp).
        With the SVK law these are the states the membrane would take if it could wrinkle.
        """
        _, Eg = self.strain(x)
        return element_wrinkling(self.law, Eg)

    # ------------------------------------------------------------------ residual/tangent
    def internal(self, x, *, tangent: bool = True):
        """Internal nodal forces f (3 nn,) and tangent K (csr) at current positions x (3, nn).

        Eq. 4.4-4.6: f = F (element stresses), K = K_L + K_NL, assembled from
        :meth:`element_arrays` on the membrane's own nodes (dof = 3 node + component).
        """
        fe, Ke = self.element_arrays(x, tangent=tangent)
        return self._asm.vector(fe), (self._asm.matrix(Ke) if tangent else None)

    @property
    def _asm(self) -> Assembler:
        """The CSR assembler of the membrane's own dofs, built on first use (its pattern
        index is 144 entries per element: 0.5 GB at 4 x 320 x 320, unused by the
        distributed assembly)."""
        if self._asm_cache is None:
            self._asm_cache = Assembler(element_dofs(self.skmesh.t, 3), self.ndof)
        return self._asm_cache

    def element_arrays(self, x, *, tangent: bool = True, elements: slice = slice(None)):
        """Element internal forces fe (ne, 12) and tangents Ke (ne, 12, 12) (or None) at
        current positions x (3, nn), local dofs node-major (3 per node), of the ``elements``
        (a slice; default all).

        Vectorised B-matrix kernel of eqs. 4.4-4.6: the variation of the Green-Lagrange strain
        of node k, component i is (Voigt) B = [F_i1 N_k,1, F_i2 N_k,2, F_i1 N_k,2 + F_i2 N_k,1].
        Evaluated in chunks of :data:`KERNEL_CHUNK` elements into the output arrays, so that
        the kernel's temporaries (~7 kB per element) stay chunk-sized.
        """
        u = self._check_x(x) - self.X
        self._gauss(elements)               # the block's quadrature data, for all its chunks
        lo, hi, step = elements.indices(self.ne)
        ne = max(hi - lo, 0)
        if ne <= KERNEL_CHUNK or step != 1:
            return self._element_arrays(u, tangent, elements)
        fe = np.empty((ne, 12))
        Ke = np.empty((ne, 12, 12)) if tangent else None
        for a in range(0, ne, KERNEL_CHUNK):
            b = min(a + KERNEL_CHUNK, ne)
            f, K = self._element_arrays(u, tangent, slice(lo + a, lo + b))
            fe[a:b] = f
            if tangent:
                Ke[a:b] = K
        return fe, Ke

    def _element_arrays(self, u, tangent: bool, elements: slice):
        """:meth:`element_arrays` of one chunk of elements, from u = x - X."""
        F, Eg = self._strain_u(u, elements)
        S, D = self.law.stress(Eg, tangent=tangent)
        h = self.material.h
        _, dN, dx = self._gauss(elements)
        P = h * np.einsum("ia...,ab...->ib...", F, S)                 # (3, 2, ne, nqp)
        fe = np.einsum("ibeq,kbeq,eq->eki", P, dN, dx).reshape(-1, 12)
        if not tangent:
            return fe, None
        ne, nq = dx.shape
        # B (ne, nq, 3 Voigt, 12 = (node k, component i)), element-major for batched matmuls
        Ft = np.transpose(F, (2, 3, 1, 0))                            # (ne, nq, a, i)
        dNt = np.transpose(dN, (2, 3, 1, 0))                          # (ne, nq, a, k)
        B = np.empty((ne, nq, 3, 4, 3))
        B[:, :, 0] = dNt[:, :, 0, :, None] * Ft[:, :, 0, None, :]
        B[:, :, 1] = dNt[:, :, 1, :, None] * Ft[:, :, 1, None, :]
        B[:, :, 2] = dNt[:, :, 1, :, None] * Ft[:, :, 0, None, :] + dNt[:, :, 0, :, None] * Ft[:, :, 1, None, :]
        B = B.reshape(ne, nq, 3, 12)
        hdx = (h * dx)[:, :, None, None]
        DB = np.matmul(np.transpose(D, (2, 3, 0, 1)) * hdx, B)        # (ne, nq, 3, 12)
        Km = np.matmul(np.swapaxes(B.reshape(ne, nq * 3, 12), 1, 2), DB.reshape(ne, nq * 3, 12))
        # initial-stress part: delta_ij N_k,a S_ab N_l,b
        SdN = np.matmul(np.transpose(S, (2, 3, 0, 1)) * hdx, dNt)      # (ne, nq, b, l)
        g = np.matmul(np.swapaxes(dNt.reshape(ne, nq * 2, 4), 1, 2), SdN.reshape(ne, nq * 2, 4))
        K4 = Km.reshape(ne, 4, 3, 4, 3)
        for i in range(3):
            K4[:, :, i, :, i] += g
        return fe, Km

    def internal_forms(self, x, *, tangent: bool = True):
        """Same as :meth:`internal`, assembled with the scikit-fem forms (reference)."""
        F, Eg = self.strain(x)
        S, D = self.law.stress(Eg, tangent=tangent)
        h = self.material.h
        P = h * np.einsum("ia...,ab...->ib...", F, S)
        residual, tangent_form = _forms()
        f = residual.assemble(self.basis, P=P)
        if not tangent:
            return f, None
        K = tangent_form.assemble(self.basis, F=F, S=S, D=np.ascontiguousarray(D), h=h)
        return f, K.tocsr()

    def mass(self) -> sp.csr_matrix:
        """Consistent mass matrix rho h int u.v dA: the scalar element blocks rho h sum_q
        N_k N_l dx_q (the 2 x 2 Gauss points of the kernels) times the 3 x 3 identity
        (kron with the node-interleaved dofs 3 node + component)."""
        if self._M is None:
            me = self._node_mass()
            t = np.asarray(self.skmesh.t)
            rows = np.broadcast_to(t.T[:, :, None], me.shape).ravel()
            cols = np.broadcast_to(t.T[:, None, :], me.shape).ravel()
            Ms = sp.csr_matrix((me.ravel(), (rows, cols)), shape=(self.nn, self.nn))
            self._M = sp.kron(Ms, sp.identity(3), format="csr")
        return self._M

    def _node_mass(self, elements: slice = slice(None)) -> np.ndarray:
        """Scalar element mass blocks rho h sum_q N_k N_l dx_q (ne, 4, 4) of the ``elements``."""
        rhoh = self.material.rho * self.material.h
        N, _, dx = self._gauss(elements)
        return rhoh * np.einsum("keq,leq,eq->ekl", N, N, dx)

    def element_mass(self, *, elements: slice = slice(None)) -> np.ndarray:
        """Element mass matrices (ne, 12, 12) of the ``elements``, local dofs node-major as in
        :meth:`element_arrays`: the blocks of :meth:`_node_mass` times the 3 x 3 identity."""
        me = self._node_mass(elements)
        return np.einsum("ekl,ij->ekilj", me, np.eye(3)).reshape(-1, 12, 12)

    def area(self) -> float:
        """Reference area of the membrane."""
        return float(np.sum(self._gauss(slice(None), keep=False)[2]))

    # ------------------------------------------------------------------ stresses
    def stresses(self, x) -> MembraneStresses:
        """Second Piola-Kirchhoff and Cauchy stresses, principal and von Mises (eqs. 5.29-5.30).

        The Cauchy stress is sigma = F S F^T / J with J = j lambda_3, j = sqrt(det F^T F) the
        area ratio and lambda_3 = sqrt(1 + 2 E_33), E_33 = -nu/(1-nu) (E_11 + E_22) the
        thickness stretch of plane-stress SVK (used with either law: with the tension-field law
        it differs from the wrinkled state's by a relative O(strain)). It is reported in the reference axes rotated with
        the material, R^T sigma R = U S U / J with U = sqrt(F^T F).
        """
        F, Eg, S = self.kinematics(x)
        C = np.einsum("ia...,ib...->ab...", F, F)
        detC = C[0, 0] * C[1, 1] - C[0, 1] ** 2
        j = np.sqrt(detC)
        nu = self.material.nu
        E33 = -nu / (1.0 - nu) * (Eg[0, 0] + Eg[1, 1])
        J = j * np.sqrt(1.0 + 2.0 * E33)
        # U = sqrt(C) for 2x2 SPD C: (C + sqrt(det C) I) / sqrt(tr C + 2 sqrt(det C))
        U = C.copy()
        U[0, 0] += j
        U[1, 1] += j
        U /= np.sqrt(C[0, 0] + C[1, 1] + 2.0 * j)
        sig = np.einsum("ab...,bc...,cd...->ad...", U, S, U) / J
        cauchy = np.stack([sig[0, 0], sig[1, 1], sig[0, 1]])
        points = np.einsum("keq,jke->jeq", self._gauss(slice(None))[0], self.X[:2, self.skmesh.t])
        return MembraneStresses(S=np.stack([S[0, 0], S[1, 1], S[0, 1]]),
                                cauchy=cauchy, principal=principal_stresses(cauchy),
                                von_mises=von_mises(cauchy), points=points)


class MembraneElement:
    """A :class:`MembraneTL` behind the element interface of :mod:`tmfem.fem.element`: its
    mesh nodes are the global nodes ``nodes`` of ``dofmap`` (their translations)."""

    def __init__(self, membrane: MembraneTL, nodes, dofmap):
        nodes = np.asarray(nodes, dtype=np.int64)
        if nodes.shape != (membrane.nn,):
            raise InputError(f"membrane element: expected {membrane.nn} global nodes, found "
                             f"{nodes.shape}")
        self.membrane, self.nodes, self.dofmap = membrane, nodes, dofmap
        self._asm_cache = None
        self._M = None

    def internal(self, state, *, tangent: bool = True):
        """Internal force and tangent of eqs. 4.4-4.6 in the global numbering."""
        fe, Ke = self.membrane.element_arrays(state.x[:, self.nodes], tangent=tangent)
        return self._asm.vector(fe), (self._asm.matrix(Ke) if tangent else None)

    @property
    def _asm(self) -> Assembler:
        """The CSR assembler on the global dofs, built on first use (the distributed
        assembly has its own)."""
        if self._asm_cache is None:
            self._asm_cache = Assembler(self.element_dofs, self.dofmap.ndof)
        return self._asm_cache

    def energy(self, state, *, elements: slice = slice(None)) -> float:
        """Strain energy (:meth:`MembraneTL.strain_energy`) of the ``elements`` (default all)."""
        return self.membrane.strain_energy(state.x[:, self.nodes], elements=elements)

    @property
    def element_dofs(self) -> np.ndarray:
        """(n_elements, 12) global dofs of each quadrilateral (its assembly numbering; the
        share protocol of :class:`tmfem.fem.distributed.DistributedElements`), evaluated on
        each call (not kept: a distributed assembly keeps its share of them)."""
        return self.dofmap.element_dofs(self.nodes[np.asarray(self.membrane.skmesh.t)])

    def element_arrays(self, state, *, tangent: bool = True, elements: slice = slice(None)):
        """Element forces (ne, 12) and tangents (ne, 12, 12) of the ``elements`` at ``state``
        (:meth:`MembraneTL.element_arrays`), local dofs ordered as :attr:`element_dofs`."""
        return self.membrane.element_arrays(state.x[:, self.nodes], tangent=tangent,
                                            elements=elements)

    def element_mass(self, state=None, *, elements: slice = slice(None)) -> np.ndarray:
        """Element mass matrices (ne, 12, 12) of the ``elements`` (:meth:`MembraneTL.element_mass`),
        local dofs ordered as :attr:`element_dofs`; the same at every ``state`` (translations
        only: the mass of the share protocol at a state, as the shells')."""
        return self.membrane.element_mass(elements=elements)

    def mass(self, state=None) -> sp.csr_matrix:
        """Consistent mass (:meth:`MembraneTL.mass`) on the global dofs, the same at every
        ``state``."""
        if self._M is None:
            g = self.dofmap.translation_dofs(self.nodes).ravel()
            P = sp.csr_matrix((np.ones(g.size), (g, np.arange(g.size))),
                              shape=(self.dofmap.ndof, g.size))
            self._M = (P @ self.membrane.mass() @ P.T).tocsr()
        return self._M
