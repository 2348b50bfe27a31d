"""Linear plane-stress finite elements of the flat membrane (eq. 5.8, 3.2-3.3).

The undeformed membrane polygon (floating frame O_f) is meshed with
:func:`tmfem.mesh.polygon_quad_mesh` (N quadrilaterals of n x n bilinear quads, as in
6.2) and discretised with scikit-fem (``ElementVector(ElementQuad1())``, two in-plane
displacement components u, v). The membrane is loaded only through its corners, which
are point attachments to the bar ends B_Mj: the corner nodes carry prescribed in-plane
displacements (Dirichlet), every other node is free. Rigid motions are then fixed
automatically; the boundary conditions of 3.2 (B_M1 free in x_f, B_M,N-1 free in x_f,
y_f, ...) are the statically determinate subset of these.

Stresses follow eq. 5.8 (plane stress, tensor shear strain):

    s_xx = E/(1-nu^2) (e_xx + nu e_yy),  s_yy = E/(1-nu^2) (e_yy + nu e_xx),
    s_xy = E/(1+nu) e_xy,

the principal stresses are those of the plane state plus sigma_p3 = 0 (through the
thickness), and the von Mises stress is eq. 5.30.

Note: a displacement prescribed at a *point* of a 2-D elastic sheet is singular (the
point-load solution grows like log r), so the corner force for a given corner
displacement decreases slowly (about like 1 / log n) and the peak stresses next to the
corners grow without bound as the mesh is refined. The corner force F_Delta of eq. 3.21
and the maximum stresses of Tables 6.3 and 6.5 are therefore properties of the mesh
(4 x 10 x 10 in 6.2), not of the continuum; see tests/fem/test_plane_stress.py.

``law="tension-field"`` replaces eq. 5.8 by the tension-field (wrinkling) law of
:mod:`tmfem.fem.tension_field` applied to the small strain eps: the problem is then
nonlinear (piecewise linear, positively homogeneous in the corner displacements) and is solved
by Newton's method (:func:`tmfem.solvers.newton.newton`) from the linear solution.

``attachment="distributed"`` removes the singularity: each corner displacement is imposed
on a small patch around the corner through the kinematic (RBE3-type, affine-fit) coupling of
:func:`tmfem.fem.attachment.attachment_weights` (the one of the MTC model), sum_i w_i u_i =
delta_j, by Lagrange multipliers; the multiplier is the resultant corner force on the patch.
F_Delta then converges under mesh refinement (for a fixed patch radius).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError, SlackMembrane
from tmfem.fem.tension_field import element_wrinkling, membrane_law
from tmfem.fem.attachment import (ATTACHMENTS, attachment_weights, coupling_matrix,
                                  default_patch_radius)
from tmfem.mesh import MembraneMesh, polygon_quad_mesh
from tmfem.system.geometry import beta
from tmfem.solvers.backends import get_backend
from tmfem.solvers.newton import newton
from tmfem.system.materials import MembraneMaterial


def plane_stress_moduli(material: MembraneMaterial) -> tuple[float, float]:
    """Lame-type constants (lambda*, mu) of plane stress: sigma = 2 mu eps + lambda* tr(eps) I.

    lambda* = E nu / (1 - nu^2), mu = E / (2 (1 + nu)); these reproduce eq. 5.8.
    """
    E, nu = material.E, material.nu
    return E * nu / (1.0 - nu**2), E / (2.0 * (1.0 + nu))


def stress_from_grad(grad_u: np.ndarray, material: MembraneMaterial) -> np.ndarray:
    """Plane stresses (s_xx, s_yy, s_xy) of eq. 5.8 from displacement gradients.

    Parameters
    ----------
    grad_u : ndarray (2, 2, ...)
        grad_u[a, b] = d u_a / d x_b.

    Returns
    -------
    ndarray (3, ...)
    """
    E, nu = material.E, material.nu
    exx, eyy = grad_u[0, 0], grad_u[1, 1]
    exy = 0.5 * (grad_u[0, 1] + grad_u[1, 0])
    c = E / (1.0 - nu**2)
    return np.array([c * (exx + nu * eyy), c * (eyy + nu * exx), E / (1.0 + nu) * exy])


def principal_stresses(sigma: np.ndarray) -> np.ndarray:
    """Principal stresses sigma_p1 >= sigma_p2 >= sigma_p3 of a plane stress state.

    The third principal direction is the membrane normal with stress 0 (plane stress).

    Parameters
    ----------
    sigma : ndarray (3, ...)
        (s_xx, s_yy, s_xy).

    Returns
    -------
    ndarray (3, ...) sorted descending along axis 0.
    """
    sxx, syy, sxy = sigma
    m = 0.5 * (sxx + syy)
    r = np.sqrt((0.5 * (sxx - syy))**2 + sxy**2)
    return -np.sort(-np.array([m + r, m - r, np.zeros_like(m)]), axis=0)


def von_mises(sigma: np.ndarray) -> np.ndarray:
    """von Mises stress of eq. 5.30 with sigma_33 = 0,
    sqrt(s11^2 - s11 s22 + s22^2 + 3 (s12^2 + s13^2 + s23^2)), of the components along axis 0:
    [s11, s22, s12] (plane stress, s13 = s23 = 0) or [s11, s22, s12, s13, s23] (a shell
    lamina with its transverse shear, :mod:`tmfem.fem.mitc4`)."""
    s = np.asarray(sigma, dtype=float)
    if s.shape[0] not in (3, 5):
        raise InputError(f"von Mises: expected 3 or 5 stress components along axis 0, found {s.shape[0]}")
    s11, s22, s12 = s[:3]
    shear = s12**2 if s.shape[0] == 3 else s12**2 + s[3]**2 + s[4]**2
    return np.sqrt(s11**2 - s11 * s22 + s22**2 + 3 * shear)


def radial_directions(corners) -> np.ndarray:
    """Unit vectors (2, N) from the centroid of a membrane polygon (2, N) to each corner:
    (cos beta_i, sin beta_i) of eq. 3.21 for the regular polygon of 3.3.1."""
    c = np.asarray(corners, dtype=float)
    d = c - c.mean(axis=1, keepdims=True)
    return d / np.linalg.norm(d, axis=0)


@dataclass(frozen=True)
class PlaneStressSolution:
    """Linear plane-stress state of the membrane for prescribed corner displacements.

    Attributes
    ----------
    delta : ndarray (2, N)
        Prescribed in-plane corner displacements (O_f frame).
    corner_forces : ndarray (2, N)
        Forces exerted *on* the membrane at its corners (the reactions, F_ui, F_vi of 3.2).
    u : ndarray (2, n_nodes)
        Nodal displacements.
    sigma : ndarray (3, n_el, n_qp)
        (s_xx, s_yy, s_xy) at the quadrature points (eq. 5.8).
    qp : ndarray (2, n_el, n_qp)
        Quadrature point coordinates (O_f).
    dx : ndarray (n_el, n_qp)
        Quadrature weights times Jacobians (areas), so that ``(f * dx).sum()`` integrates f.
    h : float
        Thickness.
    """

    delta: np.ndarray
    corner_forces: np.ndarray
    u: np.ndarray
    sigma: np.ndarray
    qp: np.ndarray
    dx: np.ndarray
    h: float

    def principal(self) -> np.ndarray:
        """Principal stresses (3, n_el, n_qp), sigma_p1 >= sigma_p2 >= sigma_p3 = 0 side."""
        return principal_stresses(self.sigma)

    def von_mises(self) -> np.ndarray:
        """von Mises stress (n_el, n_qp), eq. 5.30."""
        return von_mises(self.sigma)

    @property
    def max_principal(self) -> float:
        """Maximum sigma_p1 over all quadrature points (eq. 5.29)."""
        return float(self.principal()[0].max())

    @property
    def max_von_mises(self) -> float:
        """Maximum von Mises stress over all quadrature points (eq. 5.30)."""
        return float(self.von_mises().max())

    @property
    def stress_resultants(self) -> np.ndarray:
        """Membrane forces per unit length (N_xx, N_yy, N_xy) = h sigma, (3, n_el, n_qp)."""
        return self.h * self.sigma


class PlaneStressMembrane:
    """Linear plane-stress model of the flat membrane loaded at its corners.

    Parameters
    ----------
    corners : array_like (2, N)
        Undeformed membrane corners in O_f, counter-clockwise.
    material : MembraneMaterial
        E, nu, thickness h.
    n : int
        Elements per side of each of the N quadrilateral patches (6.2 uses 10).
    attachment : {"point", "distributed"}
        ``"point"`` (the dissertation's model): the corner node carries the prescribed
        displacement (Dirichlet); singular, F_Delta falls like 1/log(n). ``"distributed"``:
        the displacement is imposed on the patch of nodes within ``patch`` of the corner
        through the affine-fit coupling sum_i w_i u_i = delta_j
        (:func:`tmfem.fem.attachment.attachment_weights`); converges under refinement.
    patch : float, optional
        Patch radius [m] of the distributed attachment; default 10 % of the corner polygon's
        circumradius (:func:`tmfem.fem.attachment.default_patch_radius`).
    law : {"svk", "tension-field"}
        Plane-stress law: linear elastic (eq. 5.8, default) or the tension-field law of
        :mod:`tmfem.fem.tension_field` on the small strain (nonlinear solve).
    """

    def __init__(self, *, corners, material: MembraneMaterial, n: int = 10,
                 attachment: str = "point", patch: float | None = None, backend="scipy",
                 law: str = "svk"):
        from skfem import Basis, ElementQuad1, ElementVector

        if not isinstance(material, MembraneMaterial):
            raise InputError(f"expected a MembraneMaterial, found {type(material).__name__}")
        if attachment not in ATTACHMENTS:
            raise InputError(f"attachment: expected one of {ATTACHMENTS}, found {attachment!r}")
        self.material = material
        self.backend = get_backend(backend)
        self.law = membrane_law(law, material)
        self.mesh: MembraneMesh = polygon_quad_mesh(corners, n)
        self.corners = self.mesh.p[:, self.mesh.corners].copy()
        self.N = self.corners.shape[1]
        self.skmesh = self.mesh.to_skfem()
        self.basis = Basis(self.skmesh, ElementVector(ElementQuad1()))
        nd = self.basis.nodal_dofs  # (2, n_nodes): dofs of (u, v) at each node
        self.corner_dofs = nd[:, self.mesh.corners].T.ravel()  # interleaved u_1, v_1, u_2, ...
        mask = np.ones(self.basis.N, dtype=bool)
        mask[self.corner_dofs] = False
        self.interior_dofs = np.flatnonzero(mask)
        self.attachment = attachment
        self.patch = None
        if attachment == "distributed":
            self.patch = float(default_patch_radius(self.corners) if patch is None else patch)
        self.weights = attachment_weights(self.mesh, attachment=attachment,
                                          patch=self.patch if self.patch is not None else 1.0)

    # ------------------------------------------------------------------ assembly
    @cached_property
    def K(self) -> sp.csr_matrix:
        """Global stiffness matrix (thickness included), scikit-fem DOF numbering."""
        from skfem import BilinearForm, asm
        from skfem.helpers import ddot, sym_grad, trace, eye

        lam, mu = plane_stress_moduli(self.material)
        h = self.material.h

        @BilinearForm
        def stiffness(u, v, w):
            eps_u = sym_grad(u)
            sig = 2.0 * mu * eps_u + lam * eye(trace(eps_u), 2)
            return h * ddot(sig, sym_grad(v))

        return asm(stiffness, self.basis).tocsr()

    @cached_property
    def _interior_solve(self):
        """``solve(b)`` with the interior block K_II (the backend's factorisation)."""
        I = self.interior_dofs
        return self.backend.factorize(self.K[I][:, I].tocsc())

    @cached_property
    def coupling(self) -> sp.csr_matrix:
        """Coupling C (2N, n_dofs): corner displacements (u_1, v_1, ...) = C x (scikit-fem
        DOF numbering); the corner rows of the identity for a point attachment."""
        C = coupling_matrix(self.weights, self.mesh.p.shape[1], 2)
        perm = self.basis.nodal_dofs.T.ravel()      # skfem dof of interleaved dof 2 node + a
        return sp.csr_matrix((C.data, perm[C.indices], C.indptr), shape=(C.shape[0], self.basis.N))

    @cached_property
    def _kkt(self):
        """Solver of the bordered system [[K, s C^T], [s C, 0]] (distributed attachment; the
        backend's factorisation); s scales the coupling rows to the stiffness."""
        s = float(np.abs(self.K.diagonal()).mean())
        C = self.coupling
        A = sp.bmat([[self.K, s * C.T], [s * C, None]], format="csc")
        return self.backend.factorize(A), s

    def _solve_distributed(self, rhs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """DOF vectors x (n_dofs, k) and corner forces mu (2N, k) for corner displacements
        rhs (2N, k): K x = C^T mu, C x = rhs."""
        solve, s = self._kkt
        nd = self.basis.N
        b = np.zeros((nd + rhs.shape[0], rhs.shape[1]))
        b[nd:] = s * rhs                      # s C x = s rhs
        y = solve(b)
        return y[:nd], -s * y[nd:]              # K x + s C^T y = 0: K x = C^T mu, mu = -s y

    def corner_stiffness(self) -> np.ndarray:
        """Condensed in-plane corner stiffness S (2N, 2N): f_c = S delta, DOFs interleaved
        (u_1, v_1, ..., u_N, v_N), O_f frame.

        Point attachment: static condensation of all non-corner DOFs,
        S = K_cc - K_ci K_ii^{-1} K_ic. Distributed: the corner forces (Lagrange multipliers)
        for unit corner displacements imposed through the coupling C. Either way symmetric
        positive semidefinite with the three in-plane rigid motions as its null space.
        Linear law only (the tension-field law has no constant corner stiffness).
        """
        if self.law.name != "svk":
            raise InputError(f"corner_stiffness: expected the linear law 'svk', found "
                             f"{self.law.name!r} (its corner forces are nonlinear in the corner "
                             "displacements; use solve())")
        if self.attachment == "distributed":
            _, S = self._solve_distributed(np.eye(2 * self.N))
            return 0.5 * (S + S.T)
        c, I = self.corner_dofs, self.interior_dofs
        K = self.K
        Kic = K[I][:, c].toarray()
        S = K[c][:, c].toarray() - Kic.T @ self._interior_solve(Kic)
        return 0.5 * (S + S.T)

    # ------------------------------------------------------------------ solution
    def displacement(self, delta) -> np.ndarray:
        """Full DOF vector for prescribed corner displacements delta (2, N)."""
        return self._displacement(delta)[0]

    def _displacement(self, delta) -> tuple[np.ndarray, np.ndarray]:
        """DOF vector and corner forces (2, N) on the membrane for corner displacements."""
        delta = np.asarray(delta, dtype=float)
        if delta.shape != (2, self.N) or not np.all(np.isfinite(delta)):
            raise InputError(f"expected corner displacements of shape (2, {self.N}) with finite "
                             f"entries, found shape {delta.shape}")
        if self.attachment == "distributed":
            x, mu = self._solve_distributed(delta.T.reshape(-1, 1))
            x, mu = x[:, 0], mu[:, 0]
            if self.law.name != "svk":
                x, mu = self._nonlinear_distributed(x, mu, delta)
            return x, mu.reshape(self.N, 2).T
        x = np.zeros(self.basis.N)
        c, I = self.corner_dofs, self.interior_dofs
        x[c] = delta.T.ravel()
        x[I] = -self._interior_solve(self.K[I][:, c] @ x[c])
        if self.law.name != "svk":
            free = np.zeros(self.basis.N, dtype=bool)
            free[I] = True
            f0 = self.K @ x
            x = newton(lambda u: self._internal(u), x, free=free, tol=1e-10,
                       scale=float(np.linalg.norm(f0[c])) + 1e-300, max_iter=100,
                       backend=self.backend).u
        f = self.K @ x if self.law.name == "svk" else self._internal(x, tangent=False)[0]
        return x, f[self.basis.nodal_dofs[:, self.mesh.corners]]

    def _internal(self, x: np.ndarray, *, tangent: bool = True):
        """Internal force h int sigma(eps(u)) : eps(v) dA and its tangent for the law (small
        strain eps = sym grad u; eq. 5.8 for SVK)."""
        from skfem import BilinearForm, LinearForm, asm
        from skfem.helpers import sym_grad

        g = np.array(self.basis.interpolate(x).grad)
        eps = 0.5 * (g + np.swapaxes(g, 0, 1))
        sig, D = self.law.stress(eps, tangent=tangent)
        h = self.material.h

        @LinearForm
        def residual(v, w):
            return h * np.einsum("ab...,ab...->...", w["sig"], sym_grad(v))

        f = asm(residual, self.basis, sig=sig)
        if not tangent:
            return f, None

        @BilinearForm
        def stiffness(u, v, w):
            eu, ev = sym_grad(u), sym_grad(v)
            vu = np.stack([eu[0, 0], eu[1, 1], 2 * eu[0, 1]])
            vv = np.stack([ev[0, 0], ev[1, 1], 2 * ev[0, 1]])
            return h * np.einsum("v...,vw...,w...->...", vv, w["D"], vu)

        return f, asm(stiffness, self.basis, D=np.ascontiguousarray(D)).tocsr()

    def wrinkling(self, x: np.ndarray) -> dict:
        """Element states (taut / wrinkled / slack) and tension directions of the law's
        criterion on the small strain of DOF vector x
        (:func:`tmfem.fem.tension_field.element_wrinkling`)."""
        g = np.array(self.basis.interpolate(x).grad)
        return element_wrinkling(self.law, 0.5 * (g + np.swapaxes(g, 0, 1)))

    def tangent(self, x: np.ndarray) -> sp.csr_matrix:
        """Stiffness (thickness included) of the law at the DOF vector x: ``K`` for the linear
        law, the consistent tangent of the tension-field law otherwise. By the positive
        homogeneity of the small-strain tension-field law (Euler: D(eps) eps = sigma(eps)),
        K_t(x) x equals the internal force at x."""
        if self.law.name == "svk":
            return self.K
        return self._internal(np.asarray(x, dtype=float))[1]

    def _nonlinear_distributed(self, x, mu, delta):
        """Newton on the bordered system [f(x) - C^T mu, s (C x - delta)] = 0 from the linear
        solution (x, mu) (nonlinear law, distributed attachment)."""
        _, s = self._kkt
        C = self.coupling
        nd = self.basis.N
        rhs = delta.T.ravel()

        def residual(w):
            f, K = self._internal(w[:nd])
            r = np.concatenate([f + s * (C.T @ w[nd:]), s * (C @ w[:nd] - rhs)])
            return r, sp.bmat([[K, s * C.T], [s * C, None]], format="csr")

        res = newton(residual, np.concatenate([x, -mu / s]), tol=1e-10,
                     scale=float(np.linalg.norm(mu)) + 1e-300, max_iter=100, backend=self.backend)
        return res.u[:nd], -s * res.u[nd:]

    def stresses(self, x: np.ndarray) -> np.ndarray:
        """(s_xx, s_yy, s_xy) at the quadrature points (3, n_el, n_qp) of DOF vector x (eq. 5.8,
        or the tension-field law on the small strain)."""
        g = np.array(self.basis.interpolate(x).grad)
        if self.law.name == "svk":
            return stress_from_grad(g, self.material)
        sig, _ = self.law.stress(0.5 * (g + np.swapaxes(g, 0, 1)), tangent=False)
        return np.stack([sig[0, 0], sig[1, 1], sig[0, 1]])

    def solve(self, delta) -> PlaneStressSolution:
        """Plane-stress state for corner displacements delta (2, N) in O_f."""
        x, corner_forces = self._displacement(delta)
        nd = self.basis.nodal_dofs
        return PlaneStressSolution(
            delta=np.asarray(delta, dtype=float).copy(),
            corner_forces=corner_forces,
            u=x[nd],
            sigma=self.stresses(x),
            qp=np.array(self.basis.global_coordinates()),
            dx=np.asarray(self.basis.dx),
            h=self.material.h,
        )

    # ------------------------------------------------------------------ symmetric load
    def radial_directions(self) -> np.ndarray:
        """Unit vectors (2, N) from the membrane centroid to each corner
        (:func:`radial_directions`)."""
        return radial_directions(self.corners)

    def symmetric_delta(self, Delta: float) -> np.ndarray:
        """Corner displacements of eq. 3.21: Delta (cos b_i - cos b_N, sin b_i - sin b_N).

        This is a radial expansion by Delta of every corner, shifted so that corner N
        (the origin O_f) stays fixed. The radial directions are taken from the mesh
        corners (they equal (cos beta_i, sin beta_i) for the regular polygon of 3.3.1).
        """
        e = self.radial_directions()
        return float(Delta) * (e - e[:, [-1]])

    def symmetric_response(self, Delta: float) -> "SymmetricCornerResponse":
        """Corner forces for the symmetric corner displacement of eq. 3.21, split into
        radial and tangential parts (tests the symmetry assumption of 3.3.1)."""
        sol = self.solve(self.symmetric_delta(Delta))
        e = self.radial_directions()
        t = np.array([-e[1], e[0]])
        radial = np.sum(sol.corner_forces * e, axis=0)
        tangential = np.sum(sol.corner_forces * t, axis=0)
        return SymmetricCornerResponse(Delta=float(Delta), F_Delta=float(radial.mean()),
                                       radial=radial, tangential=tangential, solution=sol)


@dataclass(frozen=True)
class SymmetricCornerResponse:
    """Corner forces of the symmetrically stretched membrane (eq. 3.21).

    Attributes
    ----------
    Delta : float
        Radial corner displacement.
    F_Delta : float
        Mean radial corner force (outward positive).
    radial, tangential : ndarray (N,)
        Radial and tangential components of each corner force.
    solution : PlaneStressSolution
    """

    Delta: float
    F_Delta: float
    radial: np.ndarray
    tangential: np.ndarray
    solution: PlaneStressSolution

    @property
    def asymmetry(self) -> float:
        """max(|radial - F_Delta|, |tangential|) / |F_Delta|: 0 for an exactly symmetric response."""
        dev = max(np.abs(self.radial - self.F_Delta).max(), np.abs(self.tangential).max())
        return float(dev / abs(self.F_Delta))


def symmetric_corner_force(system, *, n: int = 10, Delta: float | None = None,
                           allow_slack: bool = False, symmetry_tol: float = 1e-6,
                           attachment: str = "point", patch: float | None = None) -> float:
    """Membrane corner force F_Delta of a symmetric system (eqs. 3.21-3.22), linear FE.

    Parameters
    ----------
    system : System
        A symmetric system (``system.symmetric`` set) with a regular membrane.
    n : int
        Mesh subdivisions per quadrilateral patch (6.2: 10).
    Delta : float, optional
        Radial corner displacement; default eq. 3.22 for the system's configuration.
    allow_slack : bool
        If False (default) Delta <= 0 raises SlackMembrane (eq. 3.36); if True the linear
        (compressive, physically meaningless) force is returned.
    symmetry_tol : float
        Largest accepted asymmetry of the corner forces relative to F_Delta.
    attachment, patch
        Corner attachment of :class:`PlaneStressMembrane` (default patch 10 % of r_mb).

    Returns
    -------
    float
        F_Delta, positive when the membrane is stretched.
    """
    if Delta is None:
        if system.symmetric is None or system.r_mb is None:
            raise InputError(f"system {system.name!r}: symmetric_corner_force needs a symmetric "
                             "system with r_mb, or an explicit Delta")
        Delta = system.symmetric.membrane_delta(system.N, system.r_mb)
    if not allow_slack and not Delta > 0:
        raise SlackMembrane(f"system {system.name!r}: expected membrane corner displacement "
                            f"Delta > 0 (eq. 3.36), found Delta = {Delta:.6g} m")
    corners = np.asarray(system.membrane_corners, dtype=float)
    b = beta(system.N)
    if not np.allclose(radial_directions(corners), [np.cos(b), np.sin(b)], atol=1e-9):
        raise InputError(f"system {system.name!r}: membrane corners are not a regular polygon "
                         "oriented as beta_j of eq. 3.21")
    resp = PlaneStressMembrane(corners=corners, material=system.membrane, n=n,
                               attachment=attachment, patch=patch).symmetric_response(Delta)
    if resp.asymmetry > symmetry_tol:
        raise InputError(f"system {system.name!r}: corner forces not symmetric: expected "
                         f"asymmetry <= {symmetry_tol:g}, found {resp.asymmetry:.3g}")
    return resp.F_Delta
