"""Four-node total-Lagrangian beam element (dissertation 4.3.2, eqs. 4.19-4.22).

Kinematics (eq. 4.19). A material point of the beam at the natural coordinate r1 and the
section coordinates y = r2 a/2 (along the director V1), z = r3 b/2 (along V2) is

    x(r1, y, z) = sum_k h_k x_k + y sum_k h_k V1_k + z sum_k h_k V2_k,

with the cubic Lagrange functions h_k of eq. 4.20 (nodes at r1 = -1, -1/3, 1/3, 1) and the
nodal directors V1_k, V2_k. Each node carries six dofs: three translations and three
rotations. The directors are rotated *finitely*: ``V_k = R_n D_k`` with R_n the rotation of
the node (:class:`tmfem.fem.element.State`, updated by the exponential map) and D_k the
reference directors of the element at that node. Eq. 4.22 (V = theta x V) is the
linearisation of this update; it is what the tangent below differentiates, but the state
itself is never advanced by a small-angle increment.

Strain (eq. 4.7). With the five fields at a point of the axis

    a0 = x0' = sum h_k' x_k,  a1 = V1' ,  a2 = V2' ,  d1 = V1 = sum h_k V1_k,  d2 = V2

(' = d/dr1) the covariant base vectors are g1 = a0 + y a1 + z a2, g_y = d1, g_z = d2, and
the Green-Lagrange strains that a beam carries (the beam assumption: only S11, S12, S13
are non-zero; Bathe [48] 6.3.5) are polynomials in (y, z):

    2 E_11 = |g1|^2 - |G1|^2 = 2 E0 + 2 y E1 + 2 z E2 + 2 y^2 E3 + 2 y z E4 + 2 z^2 E5,
    2 E_1y = g1.d1 - G1.D1   = G0 + y G1 + z G2,
    2 E_1z = g1.d2 - G1.D2   = H0 + y H1 + z H2,

where each of the twelve *generalised strains* e = (E0..E5, G0..G2, H0..H2) is a difference
of inner products of the fields (E0 = (a0.a0 - A0.A0)/2, E1 = a0.a1 - A0.A1, G0 = a0.d1 -
A0.D1, ...). They are invariant under any rigid motion (translation and finite rotation of
every node together), so rigid motions give zero strain exactly. With J = |A0| the local
(engineering) strains are eps11 = E_11 / J^2 and gamma_1y = 2 E_1y / J.

Stress and section integration (eqs. 4.1, 4.9). St.Venant-Kirchhoff in the beam sense
(S11 = E eps11, S12 = kappa G gamma_1y on the section-constant part) integrated over the
section *exactly*: the energy density is a polynomial of degree four in (y, z), so it needs
only the section moments A, int y^2, int z^2, int y^4, int y^2 z^2, int z^4 (odd ones vanish
for the doubly symmetric rectangle and circle). The strain energy is then

    W = sum_e sum_g w_g  e^T D e / 2,

with D = (E / J^3) D_axial + (G / J) D_shear (eq. 4.9 integrated over the section; see
:func:`section_matrix`). Torsion: the section-linear part of the transverse shear strains
is the St.Venant twist; without warping it would give the polar moment I_p = I_s + I_t, so
it is weighted by k_t = J / I_p (exact for the circle, k_t = 1; the St.Venant torsion
constant of a rectangle for the rectangle, :meth:`BeamSection.rectangle`).

Integration along the axis (4.3.2: "the reduced integration technique is used to
eliminate membrane locking and shear locking"): 3-point Gauss by default (``"reduced"``,
one point fewer than the 4 of exact integration of the stiffness of a straight element;
it leaves 18 = 24 - 6 deformation modes at 3 x 6 generalised strains, so no spurious
zero-energy mode); ``"full"`` uses 4 points (the element "still performs well", 4.3.2).
The mass is integrated with 4 points in every case (exact for straight elements).

Internal force and tangent (eqs. 4.4-4.6) are the first and second derivatives of W with
respect to the translations and the *spatial* rotation increments theta of the nodes
(V -> exp(theta) V), i.e. exactly the linearisation of the update the solvers use; with
g_V = dW/dV the rotational force is f_theta = sum V x g_V and the tangent gets, besides
the material and initial-stress parts, the term skew(g_V) skew(V) on each node's
rotational block (non-symmetric away from equilibrium, as the exact linearisation of a
finite-rotation update is). Everything is vectorised over elements and Gauss points.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.polynomial import Polynomial

from tmfem.errors import InputError
from tmfem.fem.assembly import Assembler
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import skew

#: Gauss points along the axis for the stiffness, by integration rule (4.3.2)
INTEGRATION = {"reduced": 3, "full": 4}

#: nodes of the four-node element in the natural coordinate r1 (eq. 4.20)
R_NODES = np.array([-1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0])

_P = Polynomial
#: the cubic Lagrange functions of eq. 4.20
_H = (-1.0 / 16.0 * _P([1, -1]) * _P([1, -3]) * _P([1, 3]),
      9.0 / 16.0 * _P([1, -1]) * _P([1, 1]) * _P([1, -3]),
      9.0 / 16.0 * _P([1, -1]) * _P([1, 1]) * _P([1, 3]),
      -1.0 / 16.0 * _P([1, 1]) * _P([1, -3]) * _P([1, 3]))
_DH = tuple(h.deriv() for h in _H)

# the twelve generalised strains as pairs (p, q) of the fields (a0, a1, a2, d1, d2):
# e_c = w_c (f_p . f_q - F_p . F_q), w_c = 1/2 on the diagonal
_PAIRS = np.array([(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2),
                   (0, 3), (1, 3), (2, 3), (0, 4), (1, 4), (2, 4)])
_WC = np.where(_PAIRS[:, 0] == _PAIRS[:, 1], 0.5, 1.0)
#: e_c = f^T C_c f / 2 - reference, C_c symmetric (12, 5, 5)
_C = np.zeros((12, 5, 5))
_C[np.arange(12), _PAIRS[:, 0], _PAIRS[:, 1]] = 1.0
_C[np.arange(12), _PAIRS[:, 1], _PAIRS[:, 0]] = 1.0


def shape_functions(r) -> tuple[np.ndarray, np.ndarray]:
    """The cubic Lagrange functions h_k(r1) of eq. 4.20 and their derivatives dh_k/dr1, each
    of shape (4, len(r))."""
    r = np.atleast_1d(np.asarray(r, dtype=float))
    return np.array([h(r) for h in _H]), np.array([d(r) for d in _DH])


def rectangle_torsion_constant(a: float, b: float, *, terms: int = 50) -> float:
    """St.Venant torsion constant of a solid a x b rectangle (Timoshenko & Goodier, Theory of
    Elasticity, 3rd ed., eq. 165 of ch. 10; c >= e the long and short sides):

        J = (c e^3 / 3) [1 - (192 / pi^5) (e / c) sum_{n = 1, 3, 5, ...} tanh(n pi c / (2 e)) / n^5].
    """
    c, e = max(a, b), min(a, b)
    n = np.arange(1, 2 * terms, 2, dtype=float)
    return c * e**3 / 3.0 * (1.0 - 192.0 / np.pi**5 * (e / c) * np.sum(np.tanh(n * np.pi * c / (2 * e)) / n**5))


@dataclass(frozen=True)
class BeamSection:
    """A doubly symmetric cross-section: a rectangle a x b or a solid circle (eq. 4.19's
    thicknesses a along V1 and b along V2).

    Coordinates: y along the director V1, z along V2 (the section's principal axes).

    Attributes
    ----------
    shape : "rectangle" or "circle"
    a, b : float
        Rectangle: the side along V1 and the side along V2 [m]; circle: the diameter (a = b).
    A : float
        Area [m^2].
    I_s, I_t : float
        Second moments about the V1 axis (int z^2 dA) and about the V2 axis (int y^2 dA)
        [m^4]: the bending stiffnesses are E I_s (bending about V1) and E I_t (about V2).
    J : float
        St.Venant torsion constant [m^4]: the circle's polar moment pi d^4 / 32; the
        rectangle's series of :func:`rectangle_torsion_constant`.
    Q_yyyy, Q_yyzz, Q_zzzz : float
        Fourth moments int y^4, int y^2 z^2, int z^4 dA [m^6] (the Green-Lagrange strain is
        quadratic in y, z; its energy needs them).
    """

    shape: str
    a: float
    b: float
    A: float
    I_s: float
    I_t: float
    J: float
    Q_yyyy: float
    Q_yyzz: float
    Q_zzzz: float

    @classmethod
    def rectangle(cls, *, a: float, b: float) -> "BeamSection":
        """Solid rectangle, side a along V1 and b along V2 [m]: A = a b, I_s = a b^3 / 12,
        I_t = a^3 b / 12, int y^4 = a^5 b / 80, int y^2 z^2 = a^3 b^3 / 144, int z^4 = a b^5 / 80."""
        _positive_dims(a=a, b=b)
        a, b = float(a), float(b)
        return cls("rectangle", a, b, A=a * b, I_s=a * b**3 / 12, I_t=a**3 * b / 12,
                   J=rectangle_torsion_constant(a, b), Q_yyyy=a**5 * b / 80,
                   Q_yyzz=a**3 * b**3 / 144, Q_zzzz=a * b**5 / 80)

    @classmethod
    def circle(cls, *, d: float) -> "BeamSection":
        """Solid circle of diameter d [m] (radius c = d/2): A = pi c^2, I_s = I_t = pi c^4 / 4,
        J = pi c^4 / 2, int y^4 = int z^4 = pi c^6 / 8, int y^2 z^2 = pi c^6 / 24."""
        _positive_dims(d=d)
        c = 0.5 * float(d)
        return cls("circle", float(d), float(d), A=np.pi * c**2, I_s=np.pi * c**4 / 4,
                   I_t=np.pi * c**4 / 4, J=np.pi * c**4 / 2, Q_yyyy=np.pi * c**6 / 8,
                   Q_yyzz=np.pi * c**6 / 24, Q_zzzz=np.pi * c**6 / 8)

    @property
    def I_p(self) -> float:
        """Polar moment I_s + I_t [m^4]."""
        return self.I_s + self.I_t

    def shear_coefficient(self, nu: float) -> float:
        """Timoshenko shear coefficient of Cowper (J. Appl. Mech. 33, 1966, Table 1):
        10 (1 + nu) / (12 + 11 nu) for the rectangle, 6 (1 + nu) / (7 + 6 nu) for the circle."""
        if self.shape == "rectangle":
            return 10 * (1 + nu) / (12 + 11 * nu)
        return 6 * (1 + nu) / (7 + 6 * nu)


def _positive_dims(**dims):
    for k, v in dims.items():
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"beam section: expected {k} > 0 [m], found {v!r}")


def section_matrix(section: BeamSection, *, nu: float) -> tuple[np.ndarray, np.ndarray]:
    """The two section matrices (12, 12) of the energy W' = (E / J^3) e^T D_axial e / 2 +
    (G / J) e^T D_shear e / 2 per unit r1 (eq. 4.9 integrated exactly over the section; module
    docstring). e = (E0, E1, E2, E3, E4, E5, G0, G1, G2, H0, H1, H2)."""
    s = section
    Da = np.zeros((12, 12))
    Da[0, 0], Da[1, 1], Da[2, 2] = s.A, s.I_t, s.I_s
    Da[0, 3] = Da[3, 0] = s.I_t
    Da[0, 5] = Da[5, 0] = s.I_s
    Da[3, 3], Da[5, 5], Da[4, 4] = s.Q_yyyy, s.Q_zzzz, s.Q_yyzz
    Da[3, 5] = Da[5, 3] = s.Q_yyzz
    kappa, kt = s.shear_coefficient(nu), s.J / s.I_p
    Ds = np.diag([0.0] * 6 + [kappa * s.A, kt * s.I_t, kt * s.I_s, kappa * s.A, kt * s.I_t, kt * s.I_s])
    return Da, Ds


def _gauss(n: int):
    r, w = np.polynomial.legendre.leggauss(n)
    return r, w


@dataclass
class BeamSet:
    """A set of four-node beam elements of one section and material.

    Attributes
    ----------
    conn : ndarray (4, ne) int
        Nodes of each element in order along its axis (r1 = -1, -1/3, 1/3, 1).
    section : BeamSection
    E, nu, rho : float
        Young's modulus [Pa], Poisson's ratio (G = E / (2 (1 + nu))), density [kg/m^3].
    v1 : array (3,) or (ne, 3) or None
        A vector in the plane of the reference axis and V1 of each element; V1 is its part
        orthogonal to the axis. Default (the rule of eq. 4.16 for a beam axis t): the part of
        e_y orthogonal to t, or of e_z when t is parallel to e_y. V2 = t x V1.
    """

    conn: np.ndarray
    section: BeamSection
    E: float
    nu: float
    rho: float
    v1: np.ndarray | None = None

    def __post_init__(self):
        self.conn = np.asarray(self.conn, dtype=np.int64)
        if self.conn.ndim != 2 or self.conn.shape[0] != 4:
            raise InputError(f"beam: expected conn of shape (4, ne), found {self.conn.shape}")
        if not (np.isfinite(self.E) and self.E > 0 and np.isfinite(self.rho) and self.rho >= 0):
            raise InputError(f"beam: expected E > 0 and rho >= 0, found E={self.E!r}, rho={self.rho!r}")
        if not (-1.0 < self.nu < 0.5):
            raise InputError(f"beam: expected -1 < nu < 0.5, found nu={self.nu!r}")
        bad = [k for k in range(self.ne) if np.unique(self.conn[:, k]).size != 4]
        if bad:
            raise InputError(f"beam: element {bad[0]} repeats a node: {self.conn[:, bad[0]].tolist()}")

    @property
    def ne(self) -> int:
        return self.conn.shape[1]

    @property
    def G(self) -> float:
        return self.E / (2.0 * (1.0 + self.nu))


def reference_directors(X: np.ndarray, conn: np.ndarray, v1=None) -> np.ndarray:
    """Reference triads (ne, 4, 3, 3) of every element at its four nodes, columns [t, D1, D2]:
    t the unit tangent of the interpolated axis (eq. 4.19 at r2 = r3 = 0) at the node, D1 the
    part of ``v1`` (default: e_y, or e_z where t is parallel to e_y, as eq. 4.16) orthogonal
    to t, D2 = t x D1."""
    _, dh = shape_functions(R_NODES)                                # (4 fns, 4 nodes)
    Xe = X[:, conn]                                                  # (3, 4, ne)
    t = np.einsum("mk,ime->eki", dh, Xe)                            # (ne, 4 nodes, 3)
    nt = np.linalg.norm(t, axis=-1)
    if np.any(nt <= 1e-12 * max(1.0, float(np.abs(X).max()))):
        e = int(np.argwhere(nt <= 1e-12 * max(1.0, float(np.abs(X).max())))[0, 0])
        raise InputError(f"beam: element {e} has a degenerate axis (nodes {conn[:, e].tolist()} "
                         f"coincide or fold back)")
    t = t / nt[..., None]
    chord = (Xe[:, 3] - Xe[:, 0]).T                                  # (ne, 3)
    fold = np.einsum("eki,ei->ek", t, chord) <= 0.0
    if np.any(fold):
        e, k = (int(i) for i in np.argwhere(fold)[0])
        raise InputError(f"beam: element {e}: expected the axis to run from node 1 to node 4 "
                         f"(dx/dr1 along the chord), found it folding back at its node {k + 1} "
                         f"(interior nodes too far from r1 = -1/3, 1/3: nodes {conn[:, e].tolist()})")
    ne = conn.shape[1]
    if v1 is None:
        ey, ez = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
        par = np.linalg.norm(np.cross(ey, t), axis=-1) < 1e-8
        v = np.where(par[..., None], ez, ey)
    else:
        v = np.asarray(v1, dtype=float)
        if v.shape == (3,):
            v = np.broadcast_to(v, (ne, 3))
        if v.shape != (ne, 3):
            raise InputError(f"beam: expected v1 of shape (3,) or ({ne}, 3), found {v.shape}")
        v = np.broadcast_to(v[:, None, :], (ne, 4, 3))
    D1 = v - np.einsum("eki,eki->ek", v, t)[..., None] * t
    n1 = np.linalg.norm(D1, axis=-1)
    if np.any(n1 < 1e-8 * np.linalg.norm(v, axis=-1)):
        e = int(np.argwhere(n1 < 1e-8 * np.linalg.norm(v, axis=-1))[0, 0])
        raise InputError(f"beam: element {e}: expected v1 not parallel to the axis, found v1 = "
                         f"{np.asarray(v[e, 0]).tolist()} along t = {t[e, 0].tolist()}")
    D1 = D1 / n1[..., None]
    D2 = np.cross(t, D1)
    return np.stack([t, D1, D2], axis=-1)


@dataclass
class BeamResponse:
    """Internal force, tangent and section state of a :class:`BeamElement` at a state.

    f : (ndof,); K : csr or None; e : (ne, ngp, 12) generalised strains; energy : float
    (section resultants: :meth:`BeamElement.section_forces`).
    """

    f: np.ndarray
    K: sp.csr_matrix | None
    e: np.ndarray
    energy: float


class BeamElement:
    """A :class:`BeamSet` behind the element interface of :mod:`tmfem.fem.element`.

    Parameters
    ----------
    beams : BeamSet
    dofmap : DofMap
        Every node of ``beams.conn`` must carry six dofs (three rotations).
    X : ndarray (3, n_nodes)
        Reference positions (the stress-free configuration).
    integration : "reduced" or "full"
        3 or 4 Gauss points along the axis for the stiffness (4.3.2; module docstring).
    """

    def __init__(self, beams: BeamSet, dofmap: DofMap, *, X: np.ndarray, integration: str = "reduced"):
        if integration not in INTEGRATION:
            raise InputError(f"beam: expected integration in {sorted(INTEGRATION)}, found {integration!r}")
        X = np.asarray(X, dtype=float)
        if X.shape != (3, dofmap.n_nodes):
            raise InputError(f"beam: expected reference positions of shape (3, {dofmap.n_nodes}), "
                             f"found {X.shape}")
        conn = beams.conn
        dofmap.check_element_nodes(conn, 6, element="beam", dofs="six dofs")
        self.beams, self.dofmap, self.integration = beams, dofmap, integration
        self.triads = reference_directors(X, conn, beams.v1)         # (ne, 4, 3, 3)
        r, w = _gauss(INTEGRATION[integration])
        self.r_gauss, self.w_gauss = r, w
        self.h, self.dh = shape_functions(r)                         # (4, ngp)
        Da, Ds = section_matrix(beams.section, nu=beams.nu)
        self._Da, self._Ds = Da, np.diag(Ds)
        F0 = self._fields(X[:, conn].transpose(2, 1, 0), self.triads[..., 1], self.triads[..., 2],
                          self.h, self.dh)
        self._gram0 = np.einsum("egpi,egqi->egpq", F0, F0)
        J = np.linalg.norm(F0[:, :, 0], axis=-1)                     # (ne, ngp)
        self.J = J
        self._cA = beams.E * w[None, :] / J**3
        self._cS = beams.G * w[None, :] / J
        self._asm = Assembler(dofmap.element_dofs(conn, rotations=True), dofmap.ndof)
        # Pm[g, p, (b, k)]: field p at Gauss point g from block b (x, V1, V2) of node k
        N = np.stack([self.dh, self.dh, self.dh, self.h, self.h])            # (5, 4, ngp)
        self._Pm = np.zeros((r.size, 5, 3, 4))
        for p, b in enumerate((0, 1, 2, 1, 2)):
            self._Pm[:, p, b] = N[p].T
        self._Pm = self._Pm.reshape(r.size, 5, 12)
        self._X = X
        self._M = None

    # -- kinematics -------------------------------------------------------------------------
    @staticmethod
    def _fields(x, V1, V2, h, dh):
        """The fields (a0, a1, a2, d1, d2) at the Gauss points (ne, ngp, 5, 3) from nodal x,
        V1, V2 (ne, 4, 3) (eq. 4.19 and its r1-derivative on the axis)."""
        return np.stack([np.einsum("kg,eki->egi", dh, x), np.einsum("kg,eki->egi", dh, V1),
                         np.einsum("kg,eki->egi", dh, V2), np.einsum("kg,eki->egi", h, V1),
                         np.einsum("kg,eki->egi", h, V2)], axis=2)

    def directors(self, state) -> tuple[np.ndarray, np.ndarray]:
        """Current directors V1, V2 (ne, 4, 3) of every element at its nodes: R_n D_k."""
        if state.R is None:
            raise InputError("beam: expected a state with nodal rotations, found R = None")
        Rn = state.R[self.beams.conn.T]                              # (ne, 4, 3, 3)
        V = np.einsum("ekij,ekjc->ekic", Rn, self.triads[..., 1:])
        return V[..., 0], V[..., 1]

    def strains(self, state) -> np.ndarray:
        """Generalised strains e (ne, ngp, 12) at the Gauss points (module docstring)."""
        return self._kinematics(state)[1]

    def _kinematics(self, state):
        x = state.x[:, self.beams.conn].transpose(2, 1, 0)          # (ne, 4, 3)
        V1, V2 = self.directors(state)
        F = self._fields(x, V1, V2, self.h, self.dh)
        gram = np.einsum("egpi,egqi->egpq", F, F)
        p, q = _PAIRS[:, 0], _PAIRS[:, 1]
        e = _WC * (gram[..., p, q] - self._gram0[..., p, q])
        return F, e, V1, V2

    def _stress(self, e):
        """Generalised stresses s = D e (ne, ngp, 12) (the Gauss weight included)."""
        return self._cA[..., None] * (e @ self._Da) + self._cS[..., None] * self._Ds * e

    # -- element interface --------------------------------------------------------------------
    def energy(self, state) -> float:
        """Strain energy W = sum_e sum_g e^T D e / 2 [J] (eq. 4.9 on the reference volume)."""
        e = self.strains(state)
        return 0.5 * float(np.sum(e * self._stress(e)))

    def internal(self, state, *, tangent: bool = True):
        """Internal force and tangent of eqs. 4.4-4.6 in the global numbering."""
        r = self.response(state, tangent=tangent)
        return r.f, r.K

    def response(self, state, *, tangent: bool = True) -> BeamResponse:
        """Internal force f = dW/du, tangent K = df/du (u: translations and spatial rotation
        increments; module docstring) and the generalised strains at ``state``."""
        F, e, V1, V2 = self._kinematics(state)
        s = self._stress(e)
        S = np.einsum("egc,cpq->egpq", s, _C)                       # (ne, ngp, 5, 5)
        psi = S @ F                                                  # dW/dF (ne, ngp, 5, 3)
        h, dh = self.h, self.dh
        gx = np.einsum("kg,egi->eki", dh, psi[:, :, 0])
        gV1 = np.einsum("kg,egi->eki", dh, psi[:, :, 1]) + np.einsum("kg,egi->eki", h, psi[:, :, 3])
        gV2 = np.einsum("kg,egi->eki", dh, psi[:, :, 2]) + np.einsum("kg,egi->eki", h, psi[:, :, 4])
        ne = e.shape[0]
        fe = np.concatenate([gx, np.cross(V1, gV1) + np.cross(V2, gV2)], axis=-1)   # (ne, 4, 6)
        f = self._asm.vector(fe.reshape(ne, 24))
        energy = 0.5 * float(np.sum(e * s))
        K = None
        if tangent:
            K = self._asm.matrix(self._tangent(F, s, S, V1, V2, gV1, gV2))
        return BeamResponse(f=f, K=K, e=e, energy=energy)

    def _tangent(self, F, s, S, V1, V2, gV1, gV2):
        """Element tangents (ne, 24, 24): material part sum_g B^T D B, initial-stress part
        sum S_pq dF_p . dF_q, and the finite-rotation term skew(g_V) skew(V)."""
        ne, ngp = F.shape[:2]
        h, dh = self.h, self.dh
        # B_c = de_c/dF (ne, ngp, 12, 5, 3)
        B = np.einsum("cpq,egqi->egcpi", _C, F)
        # de_c / d(node dofs): translations from a0, rotations from the directors (dV = theta x V)
        Bx = np.einsum("kg,egci->egcki", dh, B[:, :, :, 0])
        BV1 = np.einsum("kg,egci->egcki", dh, B[:, :, :, 1]) + np.einsum("kg,egci->egcki", h, B[:, :, :, 3])
        BV2 = np.einsum("kg,egci->egcki", dh, B[:, :, :, 2]) + np.einsum("kg,egci->egcki", h, B[:, :, :, 4])
        Bt = np.cross(V1[:, None, None], BV1) + np.cross(V2[:, None, None], BV2)
        BL = np.concatenate([Bx, Bt], axis=-1).reshape(ne, ngp, 12, 24)
        DBL = self._cA[..., None, None] * (self._Da @ BL) + (self._cS[..., None] * self._Ds)[..., None] * BL
        Ke = np.matmul(BL.reshape(ne, ngp * 12, 24).transpose(0, 2, 1), DBL.reshape(ne, ngp * 12, 24))
        # initial stress: Zb[(b, k), (b', l)] = sum_g sum_{p in b, q in b'} S_pq N_pk N_ql with the
        # constant map Pm_g (5 fields -> 3 blocks (x, V1, V2) x 4 nodes)
        Zb = np.einsum("gpm,egpn->emn", self._Pm, S @ self._Pm[None], optimize=True)
        Zb = Zb.reshape(ne, 3, 4, 3, 4).transpose(0, 1, 3, 2, 4)           # (ne, b, b', k, l)
        T = -skew(np.stack([V1, V2], axis=2))                       # dV = T theta, (ne, 4, 2, 3, 3)
        Kg = np.zeros((ne, 4, 6, 4, 6))
        Kg[:, :, :3, :, :3] = np.einsum("ekl,ij->ekilj", Zb[:, 0, 0], np.eye(3))
        xt = np.einsum("ekl,elij->ekilj", Zb[:, 0, 1], T[:, :, 0]) \
            + np.einsum("ekl,elij->ekilj", Zb[:, 0, 2], T[:, :, 1])
        Kg[:, :, :3, :, 3:] = xt
        Kg[:, :, 3:, :, :3] = xt.transpose(0, 3, 4, 1, 2)
        tt = np.zeros((ne, 4, 3, 4, 3))
        for a in range(2):
            for b in range(2):
                tt += np.einsum("ekl,ekji,eljm->ekilm", Zb[:, 1 + a, 1 + b], T[:, :, a], T[:, :, b],
                                optimize=True)
        # finite-rotation term on each node's own rotational block
        G = np.einsum("ekij,ekjl->ekil", skew(gV1), skew(V1)) + np.einsum("ekij,ekjl->ekil", skew(gV2), skew(V2))
        k = np.arange(4)
        tt[:, k, :, k, :] += G.transpose(1, 0, 2, 3)
        Kg[:, :, 3:, :, 3:] = tt
        return Ke + Kg.reshape(ne, 24, 24)

    def mass(self, state=None) -> sp.csr_matrix:
        """Consistent mass (eq. 4.6): the kinetic energy of eq. 4.19's velocity field,
        rho int (|sum h xdot|^2 A + |sum h V1dot|^2 I_t + |sum h V2dot|^2 I_s) J dr1 / 2 with
        Vdot = omega x V (translational and rotary inertia; 4-point Gauss), at the reference
        directors, or at the current directors of ``state`` (modes about a rotated state:
        the rotary inertia turns with the section)."""
        if state is None and self._M is not None:
            return self._M
        b, sec = self.beams, self.beams.section
        r, w = _gauss(4)
        h, dh = shape_functions(r)
        x = self._X[:, b.conn].transpose(2, 1, 0)
        J = np.linalg.norm(np.einsum("kg,eki->egi", dh, x), axis=-1)        # (ne, 4)
        hh = np.einsum("eg,kg,lg->ekl", b.rho * w[None, :] * J, h, h)
        V = (self.triads[..., 1], self.triads[..., 2]) if state is None else self.directors(state)
        T = -skew(np.stack(V, axis=2))                                      # (ne, 4, 2, 3, 3)
        Me = np.zeros((b.ne, 4, 6, 4, 6))
        Me[:, :, :3, :, :3] = sec.A * np.einsum("ekl,ij->ekilj", hh, np.eye(3))
        Me[:, :, 3:, :, 3:] = np.einsum("ekl,ekji,eljm->ekilm", hh, sec.I_t * T[:, :, 0], T[:, :, 0]) \
            + np.einsum("ekl,ekji,eljm->ekilm", hh, sec.I_s * T[:, :, 1], T[:, :, 1])
        M = self._asm.matrix(Me.reshape(b.ne, 24, 24))
        if state is None:
            self._M = M
        return M

    # -- post ------------------------------------------------------------------------------
    def gauss_points(self) -> np.ndarray:
        """Reference positions (3, ne, ngp) of the Gauss points on the axis."""
        x = self._X[:, self.beams.conn]                                 # (3, 4, ne)
        return np.einsum("kg,ike->ieg", self.h, x)

    def section_forces(self, state) -> dict:
        """Section resultants of the second Piola-Kirchhoff stress at the Gauss points, each
        (ne, ngp): ``N`` = int S11 dA (axial force), ``M1`` = int z S11 dA (bending about V1),
        ``M2`` = int y S11 dA (about V2, sign of y), ``Q1`` = int S12 dA, ``Q2`` = int S13 dA
        (shear along V1, V2), ``T`` = int (y S13 - z S12) dA (torque about the axis)."""
        e = self.strains(state)
        sec, b, J = self.beams.section, self.beams, self.J
        eps = e[..., :6] / J[..., None] ** 2
        gam = e[..., 6:] / J[..., None]
        kappa, kt = sec.shear_coefficient(b.nu), sec.J / sec.I_p
        return {"N": b.E * (sec.A * eps[..., 0] + sec.I_t * eps[..., 3] + sec.I_s * eps[..., 5]),
                "M1": b.E * sec.I_s * eps[..., 2], "M2": b.E * sec.I_t * eps[..., 1],
                "Q1": kappa * b.G * sec.A * gam[..., 0], "Q2": kappa * b.G * sec.A * gam[..., 3],
                "T": kt * b.G * (sec.I_t * gam[..., 4] - sec.I_s * gam[..., 2])}

    def centerline(self, state, *, points_per_element: int = 16) -> np.ndarray:
        """Current axis positions (3, ne * points_per_element) along every element (eq. 4.19
        at r2 = r3 = 0), for plots."""
        r = np.linspace(-1.0, 1.0, points_per_element)
        h, _ = shape_functions(r)
        x = state.x[:, self.beams.conn]                                  # (3, 4, ne)
        return np.einsum("kg,ike->ieg", h, x).reshape(3, -1)


def line_mesh(start, end, *, n_elements: int) -> tuple[np.ndarray, np.ndarray]:
    """Straight beam from ``start`` to ``end`` (3-vectors) in ``n_elements`` four-node
    elements: positions (3, 3 n + 1), equally spaced, and connectivity (4, n) (neighbours
    share their end nodes)."""
    if not (isinstance(n_elements, (int, np.integer)) and n_elements >= 1):
        raise InputError(f"beam mesh: expected n_elements >= 1, found {n_elements!r}")
    a, b = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    if a.shape != (3,) or b.shape != (3,) or not np.linalg.norm(b - a) > 0:
        raise InputError(f"beam mesh: expected two distinct 3-vectors, found {a.tolist()} and {b.tolist()}")
    s = np.linspace(0.0, 1.0, 3 * n_elements + 1)
    X = a[:, None] + (b - a)[:, None] * s[None, :]
    conn = 3 * np.arange(n_elements)[None, :] + np.arange(4)[:, None]
    return X, conn


def spin_constraint(beam: BeamElement, *, nodes, state=None) -> tuple[int, np.ndarray, np.ndarray]:
    """The constraint that removes the rigid spin of a bar whose ends are pinned.

    A bar connected only through translations (pinned to the base, to tendons, to membrane
    corners) can spin about its own axis at no energy: its tangent is singular and its
    spectrum has a zero. The spin phi_s (rotation about the bar axis a at every node of the
    bar, ``nodes`` from end to end; a = the unit chord of the end nodes at ``state``) is
    removed by the mass-orthogonality constraint

        c^T u = 0,    c = M phi_s    (rotation dofs of the bar),

    which every elastic mode of the free bar satisfies already (modes are M-orthogonal), so
    the elastic frequencies are unchanged and only the zero-frequency spin goes. In statics
    the energy and loads do not depend on the spin, so the constrained equilibrium is an
    equilibrium of the unconstrained problem (the constraint force is zero). Exact for a
    straight bar (its nodes on the axis); the constraint is linear in the increments and
    stays valid while the axis turns by less than 90 degrees from ``a``.

    Returns
    -------
    (dof, master_dofs, weights) for ``ConstraintMap.build(dependent_dofs=[...])``: the bar's
    rotation dof with the largest |c| expressed by the others, u_d = -sum c_j u_j / c_d.
    """
    nodes = np.asarray(nodes, dtype=np.int64)
    if nodes.ndim != 1 or nodes.size < 2 or not np.isin(nodes, beam.beams.conn).all():
        raise InputError(f"spin constraint: expected >= 2 nodes of the beam set, found {nodes.tolist()}")
    dm = beam.dofmap
    x = beam._X if state is None else state.x
    a = x[:, nodes[-1]] - x[:, nodes[0]]
    if not np.linalg.norm(a) > 0:
        raise InputError("spin constraint: expected distinct end nodes, found coincident ones")
    a = a / np.linalg.norm(a)
    rot = dm.rotation_dofs(nodes)                                            # (n, 3)
    phi = np.zeros(dm.ndof)
    phi[rot] = a
    c = (beam.mass(state) @ phi)[rot.ravel()]
    if not np.abs(c).max() > 0:
        raise InputError("spin constraint: expected a bar with rotary inertia (rho > 0), found none")
    k = int(np.argmax(np.abs(c)))
    others = np.flatnonzero((np.arange(c.size) != k) & (c != 0.0))
    return int(rot.ravel()[k]), rot.ravel()[others], -c[others] / c[k]


def point_on_bar(beam: BeamElement, *, element: int, r1: float) -> tuple[np.ndarray, np.ndarray]:
    """Masters and weights of a point of the beam axis at natural coordinate r1 of
    ``element``: x = sum_k h_k(r1) x_k (eq. 4.19 at r2 = r3 = 0; eq. 4.20 weights sum to
    one). A tendon end pinned there is a ``ConstraintMap`` dependent node
    ``(node, masters, weights)``; a point that is a node of the mesh is that node."""
    if not (0 <= element < beam.beams.ne and -1.0 <= r1 <= 1.0):
        raise InputError(f"point on bar: expected element in [0, {beam.beams.ne}) and -1 <= r1 <= 1, "
                         f"found element {element}, r1 {r1}")
    h, _ = shape_functions([r1])
    return beam.beams.conn[:, element].copy(), h[:, 0]


def locate_on_line(k: float, *, n_elements: int) -> tuple[int, float]:
    """Element and r1 of the point at the fraction ``k`` (0..1) of the length of a straight
    bar of :func:`line_mesh` (equally spaced nodes: x is linear in r1), e.g. H_1j at k_H."""
    if not (0.0 <= k <= 1.0):
        raise InputError(f"locate on line: expected 0 <= k <= 1, found {k!r}")
    e = min(int(np.floor(k * n_elements)), n_elements - 1)
    return e, 2.0 * (k * n_elements - e) - 1.0
