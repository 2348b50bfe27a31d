"""Two-node total-Lagrangian truss element for bars and tendons (dissertation 4.3.3).

Geometry is linear between the end nodes (eqs. 4.23-4.24, h_k = (1 + r_1^k r_1)/2), so
the covariant base vector g_1 = (x_2 - x_1)/2 is constant along the element and the
Green-Lagrange strain of eq. 4.7, referred to the *rest* length L (the reference
configuration of a tendon is its unstretched state), is

    E = (l^2 - L^2) / (2 L^2),            l = |x_2 - x_1|.

With the St.Venant-Kirchhoff law S = E_mod E (eq. 4.9) and the reference volume A L the
strain energy is W = EA L E^2 / 2, which gives the internal force and the tangent of
eqs. 4.4-4.6 (material part K_L plus initial-stress part K_NL):

    f_2 = -f_1 = (EA E / L) d,             d = x_2 - x_1,
    K_22 = (EA / L^3) d d^T + (EA E / L) I,   K = [[K_22, -K_22], [-K_22, K_22]].

The true (Cauchy) axial force is N = EA E l / L (first Piola-Kirchhoff stress times A).
Tension-only members (tendons) carry zero force and stiffness when E <= 0 and are
reported as slack. Everything is vectorised over elements; assembly is sparse CSR.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.assembly import Assembler
from tmfem.fem.dofmap import DofMap


@dataclass
class TrussSet:
    """A set of two-node truss elements.

    Attributes
    ----------
    conn : ndarray (2, ne) int
        End nodes of each element.
    L : ndarray (ne,)
        Reference (rest) lengths [m].
    EA : ndarray (ne,)
        Axial stiffness [N].
    rhoA : ndarray (ne,)
        Mass per unit reference length [kg/m].
    tension_only : ndarray (ne,) bool
        True for tendons (no compression).
    """

    conn: np.ndarray
    L: np.ndarray
    EA: np.ndarray
    rhoA: np.ndarray
    tension_only: np.ndarray
    _assemblers: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        self.conn = np.asarray(self.conn, dtype=np.int64)
        if self.conn.ndim != 2 or self.conn.shape[0] != 2:
            raise InputError(f"truss: expected conn of shape (2, ne), found {self.conn.shape}")
        ne = self.conn.shape[1]
        for name in ("L", "EA", "rhoA", "tension_only"):
            v = np.asarray(getattr(self, name))
            if v.ndim == 0:
                v = np.full(ne, v)
            if v.shape != (ne,):
                raise InputError(f"truss: expected {name} of shape ({ne},), found {v.shape}")
            setattr(self, name, v.astype(bool) if name == "tension_only" else v.astype(float))
        if ne and not np.all(self.L > 0):
            raise InputError(f"truss: expected rest lengths L > 0, found min {self.L.min()!r}")
        if ne and not (np.all(self.EA > 0) and np.all(self.rhoA >= 0)):
            raise InputError(f"truss: expected EA > 0 and rhoA >= 0, found min EA {self.EA.min()!r}, "
                             f"min rhoA {self.rhoA.min()!r}")
        if ne and np.any(self.conn[0] == self.conn[1]):
            k = int(np.flatnonzero(self.conn[0] == self.conn[1])[0])
            raise InputError(f"truss: element {k} connects node {self.conn[0, k]} to itself")

    @property
    def ne(self) -> int:
        return self.conn.shape[1]

    def take(self, elements: slice) -> "TrussSet":
        """The elements ``elements`` (a slice) of this set, as a set of their own."""
        return TrussSet(self.conn[:, elements], self.L[elements], self.EA[elements],
                        self.rhoA[elements], self.tension_only[elements])

    def assembler(self, dofmap: DofMap) -> Assembler:
        """Sparse assembler on the translations of ``dofmap``, cached by dof layout."""
        key = dofmap.counts.tobytes()
        a = self._assemblers.get(key)
        if a is None:
            if self.ne and self.conn.max() >= dofmap.n_nodes:
                raise InputError(f"truss: expected node indices < {dofmap.n_nodes}, found "
                                 f"{self.conn.max()}")
            if len(self._assemblers) >= 8:
                self._assemblers.pop(next(iter(self._assemblers)))
            a = self._assemblers[key] = Assembler(dofmap.element_dofs(self.conn), dofmap.ndof)
        return a


@dataclass
class TrussResponse:
    """Internal force vector, tangent and member state of a :class:`TrussSet`.

    f : (ndof,) internal nodal forces; K : csr (ndof, ndof) tangent; N : (ne,) true axial
    force (tension positive); strain : (ne,) Green-Lagrange strain w.r.t. L;
    slack : (ne,) True for tension-only members with strain <= 0; length : (ne,) current l.
    """

    f: np.ndarray
    K: sp.csr_matrix
    N: np.ndarray
    strain: np.ndarray
    slack: np.ndarray
    length: np.ndarray


def truss_element_arrays(x: np.ndarray, trusses: TrussSet, *, tangent: bool = True):
    """Total-Lagrangian element forces and tangents of the truss elements (eqs. 4.4-4.7,
    4.23-4.24) with their member state.

    Parameters
    ----------
    x : ndarray (3, nn)
        Current nodal positions.
    trusses : TrussSet
    tangent : bool
        If False, ``Ke`` is None.

    Returns
    -------
    fe : (ne, 6) forces at the end nodes [x_1, x_2], three components each
    Ke : (ne, 6, 6) tangents, or None
    N, strain, slack, length : (ne,) as in :class:`TrussResponse`
    """
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[0] != 3:
        raise InputError(f"truss: expected positions of shape (3, nn), found {x.shape}")
    if trusses.ne and trusses.conn.max() >= x.shape[1]:
        raise InputError(f"truss: expected node indices < {x.shape[1]}, found {trusses.conn.max()}")
    d = x[:, trusses.conn[1]] - x[:, trusses.conn[0]]          # (3, ne)
    l2 = np.einsum("ie,ie->e", d, d)
    L = trusses.L
    E = (l2 - L**2) / (2.0 * L**2)
    slack = trusses.tension_only & (E <= 0.0)
    EAe = np.where(~slack, trusses.EA, 0.0)
    s = EAe * E / L                                            # f_2 = s d
    f2 = (s * d).T                                             # (ne, 3)
    fe = np.concatenate([-f2, f2], axis=1)
    l = np.sqrt(l2)
    N = EAe * E * l / L
    Ke = None
    if tangent:
        K22 = (EAe / L**3)[:, None, None] * np.einsum("ie,je->eij", d, d) \
            + s[:, None, None] * np.eye(3)[None]
        Ke = np.empty((trusses.ne, 6, 6))
        Ke[:, :3, :3] = K22
        Ke[:, 3:, 3:] = K22
        Ke[:, :3, 3:] = -K22
        Ke[:, 3:, :3] = -K22
    return fe, Ke, N, E, slack, l


def truss_internal(x: np.ndarray, trusses: TrussSet, *, tangent: bool = True,
                   dofmap: DofMap | None = None) -> TrussResponse:
    """Internal force and tangent of all truss elements (:func:`truss_element_arrays` of
    ``x``, ``trusses`` and ``tangent``; ``K`` None without it: the residual only, e.g.
    inside a line search) assembled on the global dofs of ``dofmap`` (default: three
    translations per node, dof = 3 node + component)."""
    fe, Ke, N, E, slack, l = truss_element_arrays(x, trusses, tangent=tangent)
    asm = trusses.assembler(dofmap or DofMap.translations(np.shape(x)[1]))
    return TrussResponse(f=asm.vector(fe), K=None if Ke is None else asm.matrix(Ke), N=N,
                         strain=E, slack=slack, length=l)


def truss_energy(x: np.ndarray, trusses: TrussSet) -> float:
    """Strain energy W = sum EA L E^2 / 2 [J] of the truss elements at positions x (3, nn)
    (St.Venant-Kirchhoff, eq. 4.9, on the reference volume A L); zero for slack
    tension-only members."""
    d = x[:, trusses.conn[1]] - x[:, trusses.conn[0]]
    L = trusses.L
    E = (np.einsum("ie,ie->e", d, d) - L**2) / (2 * L**2)
    E = np.where(trusses.tension_only & (E <= 0), 0.0, E)
    return 0.5 * float(np.sum(trusses.EA * L * E**2))


def truss_element_mass(trusses: TrussSet, *, lumped: bool = False) -> np.ndarray:
    """Element mass matrices (ne, 6, 6) of the truss elements, total mass rho A L per
    element, local dofs as in :func:`truss_element_arrays`.

    Consistent (eq. 4.6 with the shape functions of eq. 4.24): (rho A L / 6) [[2I, I], [I, 2I]];
    lumped: (rho A L / 2) I at each end.
    """
    m = trusses.rhoA * trusses.L
    if lumped:
        pattern = np.kron(np.eye(2), np.eye(3)) / 2.0
    else:
        pattern = np.kron(np.array([[2.0, 1.0], [1.0, 2.0]]), np.eye(3)) / 6.0
    return m[:, None, None] * pattern[None]


def truss_mass(trusses: TrussSet, nn: int | DofMap, *, lumped: bool = False) -> sp.csr_matrix:
    """Mass matrix of the truss elements (:func:`truss_element_mass`) on ``nn``
    translational nodes or on the translations of a :class:`DofMap`."""
    asm = trusses.assembler(nn if isinstance(nn, DofMap) else DofMap.translations(nn))
    return asm.matrix(truss_element_mass(trusses, lumped=lumped))


class TrussElement:
    """A :class:`TrussSet` behind the element interface of :mod:`tmfem.fem.element`, on the
    translations of ``dofmap`` (its nodes may carry rotations too: a truss ignores them),
    and the share protocol of :class:`tmfem.fem.distributed.DistributedElements` (its
    elements split over the ranks like the membrane's)."""

    def __init__(self, trusses: TrussSet, dofmap: DofMap, *, lumped_mass: bool = False):
        self.trusses, self.dofmap, self.lumped_mass = trusses, dofmap, lumped_mass

    def response(self, state, *, tangent: bool = True) -> TrussResponse:
        """Forces, tangent and member state (axial forces, strains, slack) at ``state``."""
        return truss_internal(state.x, self.trusses, tangent=tangent, dofmap=self.dofmap)

    def internal(self, state, *, tangent: bool = True):
        """Internal force and tangent of eqs. 4.4-4.7 in the global numbering."""
        r = self.response(state, tangent=tangent)
        return r.f, r.K

    @property
    def element_dofs(self) -> np.ndarray:
        """(ne, 6) global dofs of each element, the translations of its end nodes."""
        return self.dofmap.element_dofs(self.trusses.conn)

    def element_arrays(self, state, *, tangent: bool = True, elements: slice = slice(None)):
        """Element forces (ne, 6) and tangents (ne, 6, 6) (or None) of the ``elements``
        (:func:`truss_element_arrays`), local dofs as :attr:`element_dofs`."""
        fe, Ke, *_ = truss_element_arrays(state.x, self.trusses.take(elements), tangent=tangent)
        return fe, Ke

    def energy(self, state, *, elements: slice = slice(None)) -> float:
        """Strain energy of the ``elements`` (:func:`truss_energy`)."""
        return truss_energy(state.x, self.trusses.take(elements))

    def element_mass(self, state=None, *, elements: slice = slice(None)) -> np.ndarray:
        """Element mass matrices (ne, 6, 6) of the ``elements`` (:func:`truss_element_mass`),
        the same at every ``state``."""
        return truss_element_mass(self.trusses.take(elements), lumped=self.lumped_mass)

    def mass(self, state=None) -> sp.csr_matrix:
        """Consistent or lumped mass (:func:`truss_mass`); the same at every ``state``
        (translations only: the mass at a state, as the beams' and shells')."""
        return truss_mass(self.trusses, self.dofmap, lumped=self.lumped_mass)


def green_rest_length(length, tension, EA):
    """Rest length r of a total-Lagrangian truss that carries ``tension`` at ``length``.

    The truss of this module has N = EA E l / r with E = (l^2 - r^2) / (2 r^2);
    with s = l / r this is the cubic s^3 - s - 2 N / EA = 0 (one positive root for N > -EA/3),
    solved by Newton's method from the linear-spring value s = 1 + N / EA (eq. 3.8).
    """
    length = np.asarray(length, dtype=float)
    c = 2.0 * np.asarray(tension, dtype=float) / np.asarray(EA, dtype=float)
    s = 1.0 + 0.5 * c
    for _ in range(50):
        g = s**3 - s - c
        s = s - g / (3 * s**2 - 1)
        if np.all(np.abs(g) < 1e-15):
            break
    return length / s


def linear_rest_length(length, tension, EA):
    """Rest length of the linear spring of eqs. 3.8-3.9: T = EA (|d| - r) / r."""
    return np.asarray(EA) * np.asarray(length) / (np.asarray(tension) + np.asarray(EA))


def truss_rest_length_derivatives(x: np.ndarray, trusses: TrussSet, *,
                                  dofmap: DofMap | None = None) -> sp.csr_matrix:
    """Partial derivatives df/dL_e (ndof, ne) of the internal force with respect to each
    element's rest length L_e at fixed positions x (3, nn).

    From f_2 = -f_1 = s d with s = EA E / L = EA (l^2 / (2 L^3) - 1 / (2 L)):

        ds/dL = EA (1 / (2 L^2) - 3 l^2 / (2 L^4)),     df_2/dL = -df_1/dL = (ds/dL) d;

    zero for slack tension-only members (their force is identically zero nearby).
    """
    x = np.asarray(x, dtype=float)
    dofmap = dofmap or DofMap.translations(x.shape[1])
    d = x[:, trusses.conn[1]] - x[:, trusses.conn[0]]
    l2 = np.einsum("ie,ie->e", d, d)
    L = trusses.L
    slack = trusses.tension_only & (l2 <= L**2)
    ds = np.where(slack, 0.0, trusses.EA * (0.5 / L**2 - 1.5 * l2 / L**4))
    vals = np.concatenate([-(ds * d), ds * d], axis=0).T               # (ne, 6)
    rows = dofmap.element_dofs(trusses.conn)                           # (ne, 6)
    cols = np.broadcast_to(np.arange(trusses.ne)[:, None], rows.shape)
    return sp.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())), shape=(dofmap.ndof, trusses.ne))


def truss_axial_force_derivatives(x: np.ndarray, trusses: TrussSet):
    """True axial force N = EA E l / L = EA (l^3 / L^3 - l / L) / 2 of each element and its
    partial derivatives: dN/dl = EA (3 l^2 / L^3 - 1 / L) / 2, dN/dL = EA (-3 l^3 / L^4
    + l / L^2) / 2 (zero for slack tension-only members), and the unit chords e = d / l
    (3, ne), so that dN = dN/dl e . (dx_2 - dx_1) + dN/dL dL."""
    d = x[:, trusses.conn[1]] - x[:, trusses.conn[0]]
    l = np.sqrt(np.einsum("ie,ie->e", d, d))
    L, EA = trusses.L, np.where(trusses.tension_only & (l <= trusses.L), 0.0, trusses.EA)
    N = 0.5 * EA * (l**3 / L**3 - l / L)
    return N, 0.5 * EA * (3 * l**2 / L**3 - 1 / L), 0.5 * EA * (-3 * l**3 / L**4 + l / L**2), d / l
