"""Membrane of the control-oriented model: static corner shapes and relative modes (eqs. 5.1-5.8).

The membrane deflection in O_f is split as in eq. 5.1,

    [u, v, w](x_f, y_f) = sum_k Psi_k(x_f, y_f) Delta_k  +  sum_i phi_i(x_f, y_f) eta_i,

where the *prestressing* part u^s, v^s, w^s is the static response to the corner
displacements Delta (the Delta entries of zeta, eq. 5.14) and the *relative* part is
expanded in modes phi_i computed with **all corners held** (a Craig-Bampton split). With
this choice the corner displacement of the membrane field is exactly Delta (phi_i = 0 at
the corners) and nothing is counted twice; the static shapes and the modes are
stiffness-orthogonal, so the strain energy separates exactly into
U = 1/2 Delta^T S Delta + 1/2 sum_i omega_i^2 eta_i^2 (eqs. 5.4-5.6), see docs/guides/com.md.

* In-plane: linear plane stress (eq. 5.8) of :class:`tmfem.fem.plane_stress.PlaneStressMembrane`
  (corner point attachments); Psi_k = response to a unit corner displacement.
* Transverse: the initial-stress (geometric) stiffness of eqs. 5.5-5.6,
  K_G = h int grad(N)^T tau^s grad(N) dA, with tau^s the in-plane stress of the designed
  corner displacements Delta_0 (eq. 5.8). Psi_k for Delta_w = static response of K_G.
* Modes: the K lowest of the fixed-corner in-plane (K_uv) and transverse (K_G) eigenproblems,
  mass-normalised with the consistent mass rho h int N N dA (phi^T M phi = 1).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError, SlackMembrane
from tmfem.fem.membrane import point_matrix
from tmfem.models.com.constraints import ZetaLayout


@dataclass
class MembraneBasis:
    """Shapes, stiffness and mass invariants of the membrane of the COM.

    Attributes
    ----------
    layout : ZetaLayout
    shapes : ndarray (1 + n_delta + K, 3, n_nodes)
        P_0 = undeformed position (x_f, y_f, 0); then the static shapes Psi_k of the Delta
        entries of zeta (layout order); then the relative modes phi_i.
    omega : ndarray (K,)
        Circular frequencies of the fixed-corner relative modes [rad/s].
    mode_kind : list of str
        ``"w"`` (transverse) or ``"uv"`` (in-plane) for each mode.
    S : ndarray (n_delta, n_delta)
        Condensed corner stiffness on the Delta entries (in-plane and transverse).
    mass : float
        Membrane mass rho h A.
    Jt : ndarray (nP, nP, 3, 3)
        Jt[a, b] = int rho P_a P_b^T dA: all second mass moments of eqs. 5.2-5.3.
    first : ndarray (nP, 3)
        first[a] = int rho P_a dA.
    tau : ndarray (3, n_el, n_qp)
        Designed in-plane prestress (s_xx, s_yy, s_xy) used in K_G (eq. 5.8).
    delta0 : ndarray (3, N)
        Corner displacements of the design, in O_f.
    node_mass : scipy.sparse matrix (n_nodes, n_nodes)
        Consistent scalar mass rho h int N_a N_b dA of the bilinear mesh (one component).
    """

    layout: ZetaLayout
    plane: object
    scalar_basis: object
    shapes: np.ndarray
    omega: np.ndarray
    mode_kind: list
    S: np.ndarray
    mass: float
    Jt: np.ndarray
    first: np.ndarray
    tau: np.ndarray
    delta0: np.ndarray
    node_mass: object = None
    n_in_plane_candidates: int = 0

    @property
    def K(self) -> int:
        return len(self.omega)

    @property
    def n_delta(self) -> int:
        return self.layout.n_delta

    @property
    def mesh(self):
        return self.plane.mesh

    def probe(self, points) -> np.ndarray:
        """Interpolation matrix (n_points, n_nodes) of the bilinear FE field at points (2, n)."""
        return point_matrix(self.scalar_basis.mesh, points).toarray()

    def point_matrix(self, points, component: int = 2) -> np.ndarray:
        """Deflection component (0 u, 1 v, 2 w) at points as a linear map of
        [1, Delta, eta]: returns (n_points, 1 + n_delta + K); column 0 is the undeformed
        position."""
        Pr = self.probe(points)
        return Pr @ self.shapes[:, component, :].T

    def modal_coordinates(self, d_rel) -> np.ndarray:
        """The relative-mode coordinates eta of a relative deflection field (eq. 5.1).

        eta_i = sum_c phi_i,c^T M_s d_c: the mass-weighted least-squares fit of d_rel by the
        modes phi_i (mass-normalised, phi_i^T M phi_j = delta_ij), i.e. the orthogonal
        projection of d_rel on their span in the kinetic-energy inner product.

        Parameters
        ----------
        d_rel : ndarray (3, n_nodes)
            u, v, w in O_f at the nodes of this basis, minus the prestressing part
            sum_k Psi_k Delta_k.
        """
        phi = self.shapes[1 + self.n_delta:]                     # (K, 3, n)
        Md = (self.node_mass @ np.asarray(d_rel, dtype=float).T)  # (n, 3)
        return np.einsum("kcn,nc->k", phi, Md)


def _mass_matrix(basis, rho_h: float):
    from skfem import BilinearForm, asm

    @BilinearForm
    def mass(u, v, w):
        return rho_h * u * v

    return asm(mass, basis).tocsr()


def _geometric_stiffness(basis, tau: np.ndarray, h: float):
    from skfem import BilinearForm, asm

    @BilinearForm
    def kg(u, v, w):
        gu, gv = u.grad, v.grad
        return h * (w["sxx"] * gu[0] * gv[0] + w["syy"] * gu[1] * gv[1]
                    + w["sxy"] * (gu[0] * gv[1] + gu[1] * gv[0]))

    return asm(kg, basis, sxx=tau[0], syy=tau[1], sxy=tau[2]).tocsr()


def build_membrane_basis(system, *, delta0, n_modes: int, mesh_n: int = 10,
                         prestress_scale: float = 1.0, membrane_law: str = "svk") -> MembraneBasis:
    """Static shapes, fixed-corner modes and mass invariants of the membrane (eqs. 5.1-5.8).

    Parameters
    ----------
    system : System
    delta0 : ndarray (3, N)
        Designed corner displacements in O_f (from zeta(q_design)); their in-plane part
        gives the prestress tau^s (eq. 5.8).
    n_modes : int
        Number K of relative modes (dissertation: 5 for 1-4, 4 for 2-3).
    mesh_n : int
        Elements per side of each of the N quadrilateral patches (6.2: 10).
    prestress_scale : float
        Factor on tau^s in the transverse stiffness only (for studies of the prestress the
        dissertation's printed numbers imply; 1 = designed prestress).
    membrane_law : {"svk", "tension-field"}
        ``"svk"``: linear plane stress (eq. 5.8), the dissertation's basis. ``"tension-field"``
        (docs/guides/wrinkling.md): tau^s is the tension-only prestress of the tension-field law at
        Delta_0, and the in-plane stiffness (static shapes, S, in-plane modes) is the law's
        consistent tangent about that state (a linearisation; S Delta_0 still equals the
        corner forces at Delta_0 since the law is positively homogeneous).
    """
    from skfem import Basis, ElementQuad1
    from tmfem.fem.plane_stress import PlaneStressMembrane

    if not (isinstance(n_modes, (int, np.integer)) and n_modes >= 0):
        raise InputError(f"membrane modes: expected an integer K >= 0, found {n_modes!r}")
    N = system.N
    layout = ZetaLayout.for_polygon(N)
    mat = system.membrane
    ps = PlaneStressMembrane(corners=system.membrane_corners, material=mat, n=mesh_n,
                             law=membrane_law)
    nn = ps.mesh.p.shape[1]
    corners = ps.mesh.corners
    nd = ps.basis.nodal_dofs                     # (2, nn)
    sb = Basis(ps.skmesh, ElementQuad1(), quadrature=ps.basis.quadrature)
    if not np.array_equal(sb.nodal_dofs[0], np.arange(nn)):
        raise RuntimeError("scalar basis: expected dof = node numbering")
    delta0 = np.asarray(delta0, dtype=float)
    sol0 = ps.solve(delta0[:2])
    tau = sol0.sigma * float(prestress_scale)
    Ms = _mass_matrix(sb, mat.rho * mat.h)
    KG = _geometric_stiffness(sb, tau, mat.h)
    Kuv = ps.tangent(ps.displacement(delta0[:2]))
    if membrane_law == "svk":
        inplane_shape = ps.displacement
    else:
        lu_uv = ps.backend.factorize(Kuv[ps.interior_dofs][:, ps.interior_dofs].tocsc())

        def inplane_shape(d):
            """Response of the tangent K_t to corner displacements d (2, N)."""
            x = np.zeros(Kuv.shape[0])
            x[ps.corner_dofs] = d.T.ravel()
            x[ps.interior_dofs] = -lu_uv(Kuv[ps.interior_dofs][:, ps.corner_dofs] @ x[ps.corner_dofs])
            return x
    # ---------------------------------------------------------------- static shapes
    free_w = np.setdiff1d(np.arange(nn), corners)
    lu_w = None
    shapes = [np.vstack([ps.mesh.p, np.zeros((1, nn))])]
    for (i, c) in layout.corner_components:
        P = np.zeros((3, nn))
        if c < 2:
            d = np.zeros((2, N))
            d[c, i] = 1.0
            x = inplane_shape(d)
            P[:2] = x[nd]
        else:
            if lu_w is None:
                lu_w = ps.backend.factorize(KG[free_w][:, free_w].tocsc())
            w = np.zeros(nn)
            w[corners[i]] = 1.0
            w[free_w] = -lu_w(KG[free_w][:, corners] @ w[corners])
            P[2] = w
        shapes.append(P)
    shapes = np.array(shapes)
    Psi = shapes[1:]
    # condensed stiffness (in-plane and transverse blocks), S = Psi^T K Psi
    uv = np.stack([P[:2].T.ravel() for P in Psi], axis=1) if len(Psi) else np.zeros((2 * nn, 0))
    # map (node, comp) interleaving to the skfem in-plane dof numbering
    perm = nd.T.ravel()
    U = np.zeros((Kuv.shape[0], len(Psi)))
    U[perm] = uv
    W = np.stack([P[2] for P in Psi], axis=1) if len(Psi) else np.zeros((nn, 0))
    S = U.T @ (Kuv @ U) + W.T @ (KG @ W)
    S = 0.5 * (S + S.T)
    # ---------------------------------------------------------------- fixed-corner modes
    modes, omega2, kind = [], [], []
    if n_modes > 0:
        Kw = KG[free_w][:, free_w]
        Mw = Ms[free_w][:, free_w]
        kw = min(n_modes, len(free_w) - 2)
        lw, vw = _lowest_modes(Kw, Mw, kw, ps.backend)
        if lw[0] <= 0:
            raise SlackMembrane(f"membrane prestress: expected a positive transverse stiffness "
                                f"with the corners held, found the eigenvalue {lw[0]:.4g} "
                                "(compressive prestress; is Delta > 0, eq. 3.36?)")
        Iuv = ps.interior_dofs
        Muv = _vector_mass(Ms, nd)
        lp, vp = _lowest_modes(Kuv[Iuv][:, Iuv], Muv[Iuv][:, Iuv], min(n_modes, len(Iuv) - 2),
                               ps.backend)
        cand = [(lw[k], "w", k) for k in range(kw)] + [(lp[k], "uv", k) for k in range(len(lp))]
        cand.sort(key=lambda t: t[0])
        for lam, kd, k in cand[:n_modes]:
            P = np.zeros((3, nn))
            if kd == "w":
                P[2, free_w] = vw[:, k]
            else:
                x = np.zeros(Kuv.shape[0])
                x[Iuv] = vp[:, k]
                P[:2] = x[nd]
            # sign convention: largest |entry| positive
            flat = P.ravel()
            if flat[np.argmax(np.abs(flat))] < 0:
                P = -P
            modes.append(P)
            omega2.append(lam)
            kind.append(kd)
    shapes = np.concatenate([shapes, np.array(modes).reshape(-1, 3, nn)], axis=0)
    # ---------------------------------------------------------------- mass invariants
    nP = shapes.shape[0]
    flat = shapes.reshape(nP * 3, nn)
    MsP = (Ms @ flat.T)                          # (nn, nP*3)
    Jt = (flat @ MsP).reshape(nP, 3, nP, 3).transpose(0, 2, 1, 3)
    ones = np.ones(nn)
    m1 = Ms @ ones
    first = shapes @ m1                          # (nP, 3)
    mass = float(ones @ m1)
    return MembraneBasis(layout=layout, plane=ps, scalar_basis=sb, shapes=shapes,
                         omega=np.sqrt(np.array(omega2, dtype=float)), mode_kind=kind, S=S,
                         mass=mass, Jt=Jt, first=first, tau=tau, delta0=delta0,
                         node_mass=Ms, n_in_plane_candidates=n_modes)


def _lowest_modes(K, M, k, backend):
    """k lowest eigenpairs of K phi = lambda M phi (shift-invert about 0), M-normalised."""
    # fixed start vector: degenerate pairs (e.g. 1.787 Hz of the square) come out the same
    # every time, so two models built from one system share their modal coordinates
    lam, vec = backend.eigsh(K.tocsc(), M.tocsc(), k, 0.0, v0=np.ones(K.shape[0]))
    order = np.argsort(lam)
    lam, vec = lam[order], vec[:, order]
    vec = vec / np.sqrt(np.einsum("ik,ik->k", vec, M @ vec))
    return lam, vec


def _vector_mass(Ms, nd):
    """Consistent in-plane mass matrix in the skfem vector dof numbering from the scalar one."""
    Ms = sp.coo_matrix(Ms)
    n = 2 * Ms.shape[0]
    rows = np.concatenate([nd[0][Ms.row], nd[1][Ms.row]])
    cols = np.concatenate([nd[0][Ms.col], nd[1][Ms.col]])
    data = np.concatenate([Ms.data, Ms.data])
    return sp.csr_matrix((data, (rows, cols)), shape=(n, n))
