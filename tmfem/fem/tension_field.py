"""Membrane constitutive laws on the in-plane Green-Lagrange strain: St.Venant-Kirchhoff and
the tension-field (relaxed-energy) law of a wrinkling membrane.

Both laws map the 2 x 2 strain E (arrays of shape (2, 2, ...), vectorised over elements and
quadrature points) to the second Piola-Kirchhoff stress S (2, 2, ...) and the consistent
material tangent D = dS/dE in the engineering Voigt form of the membrane kernel,

    [S_11, S_22, S_12] = D [dE_11, dE_22, 2 dE_12],          D of shape (3, 3, ...).

**SVK** (eq. 4.9, plane stress): S = lam tr(E) I + 2 mu E, lam = E nu / (1 - nu^2),
mu = E / (2 (1 + nu)), energy W = lam tr(E)^2 / 2 + mu E:E.

**Tension field.** A thin membrane carries no compression: it wrinkles. The relaxed energy
of Pipkin (1986, IMA J. Appl. Math. 36, 85-99) replaces W by its tension-field
relaxation; for an isotropic W written in the principal strains e1 >= e2 of E it is the
minimum of W over a larger minor strain e2' >= e2 (the wrinkles take up the difference),
which for SVK gives

    taut      e1 > 0, e2 > -nu e1:  W = W_SVK(e1, e2)                     (both S_i > 0)
    wrinkled  e1 > 0, e2 <= -nu e1: W = E e1^2 / 2,  S = E e1 n1 (x) n1   (uniaxial tension)
    slack     e1 <= 0:              W = 0,           S = 0

with n1 the major principal direction of E (the tension direction: the wrinkle crests run
along it). The states are those of the mixed stress-strain criterion of Roddeman et al.
(1987, J. Appl. Mech. 54, 884-892) and Kang & Im (1997, J. Appl. Mech. 64, 263-269):
taut if the minor principal stress of the elastic law is positive (S_2^SVK > 0
<=> e2 + nu e1 > 0), slack if the major principal strain is not positive (e1 <= 0), wrinkled
otherwise. For the isotropic law the tension direction of the wrinkled state is the major
principal strain direction and the stress is continuous across both state boundaries.

The wrinkled tangent is consistent, including the rotation of n1 with the strain: with
n2 the minor direction and Q = n1 (x) n2 + n2 (x) n1, d(n1 (x) n1) = Q (Q : dE) / (2 (e1 - e2)),

    D_wrinkled = E p p^T + E e1 / (2 (e1 - e2)) q q^T,     p = Voigt(n1 (x) n1), q = Voigt(Q);

e1 - e2 >= (1 + nu) e1 > 0 in the wrinkled state, so it is bounded. Keeping the taut shear
stiffness instead (as some implementations do) overstates the stiffness.

**Regularisation.** The wrinkled tangent is singular along n2 (x) n2 and the slack one is
zero. The law used is W = (1 - eta) W_TF + eta W_SVK: exactly SVK in the taut state, a
compressive stiffness of eta times SVK in the wrinkled and slack states (default
eta = 1e-6), continuous stress, consistent tangent. eta = 0 is allowed (singular tangents).
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError
from tmfem.fem.shell_section import ShellSection
from tmfem.system.materials import MembraneMaterial

MEMBRANE_LAWS = ("svk", "tension-field")
"""Names of the membrane laws (``membrane_law=`` / ``--membrane-law``)."""

TAUT, WRINKLED, SLACK = 0, 1, 2
"""State codes of :meth:`MembraneLaw.state` (cell data ``membrane_state``)."""
STATE_NAMES = ("taut", "wrinkled", "slack")


def principal_strains(E: np.ndarray):
    """Principal values e1 >= e2 and the angle theta of the major direction
    n1 = (cos theta, sin theta) of symmetric 2 x 2 tensors E (2, 2, ...).

    e_1,2 = (E11 + E22) / 2 +- sqrt(((E11 - E22) / 2)^2 + E12^2),
    theta = atan2(2 E12, E11 - E22) / 2 (0 where E is isotropic).
    """
    c = 0.5 * (E[0, 0] + E[1, 1])
    d = 0.5 * (E[0, 0] - E[1, 1])
    r = np.hypot(d, E[0, 1])
    return c + r, c - r, 0.5 * np.arctan2(E[0, 1], d)


def _voigt_outer(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a b^T for Voigt vectors a, b (3, ...) -> (3, 3, ...)."""
    return a[:, None] * b[None, :]


class MembraneLaw:
    """Common part of the membrane laws: the isotropic plane-stress SVK constants.

    Parameters
    ----------
    material : MembraneMaterial or ShellSection
        Isotropic material: its modulus E and Poisson ratio nu are used (a shell section
        gives the law of the shell's lamina, :mod:`tmfem.fem.mitc4`).
    """

    name = ""

    def __init__(self, material):
        if not isinstance(material, (MembraneMaterial, ShellSection)):
            raise InputError(f"membrane law: expected a MembraneMaterial or ShellSection, found "
                             f"{type(material).__name__}")
        self.material = material
        E, nu = material.E, material.nu
        self.E, self.nu = E, nu
        self.lam = E * nu / (1.0 - nu**2)        # plane-stress Lame constant
        self.mu = E / (2.0 * (1.0 + nu))
        self.D_svk = np.array([[self.lam + 2 * self.mu, self.lam, 0.0],
                               [self.lam, self.lam + 2 * self.mu, 0.0],
                               [0.0, 0.0, self.mu]])

    def _svk(self, E: np.ndarray) -> np.ndarray:
        """SVK stress lam tr(E) I + 2 mu E (eq. 4.9)."""
        S = 2.0 * self.mu * E
        tr = E[0, 0] + E[1, 1]
        S[0, 0] += self.lam * tr
        S[1, 1] += self.lam * tr
        return S

    def _svk_energy(self, E: np.ndarray) -> np.ndarray:
        tr = E[0, 0] + E[1, 1]
        return 0.5 * self.lam * tr**2 + self.mu * np.einsum("ab...,ab...->...", E, E)

    def state(self, E: np.ndarray) -> np.ndarray:
        """State codes TAUT/WRINKLED/SLACK (int8, shape E.shape[2:]) of the mixed criterion
        (Roddeman et al. 1987; Kang & Im 1997): slack if e1 <= 0, taut if e2 + nu e1 > 0,
        wrinkled otherwise. For SVK this reports where the membrane *would* wrinkle."""
        E = np.asarray(E, dtype=float)
        e1, e2, _ = principal_strains(E)
        s = np.full(e1.shape, WRINKLED, dtype=np.int8)
        s[e2 + self.nu * e1 > 0.0] = TAUT
        s[e1 <= 0.0] = SLACK
        return s

    def tension_direction(self, E: np.ndarray) -> np.ndarray:
        """Major principal direction n1 (2, ...) of E: the tension (wrinkle-crest) direction
        of the wrinkled state."""
        _, _, th = principal_strains(np.asarray(E, dtype=float))
        return np.stack([np.cos(th), np.sin(th)])


class SVKLaw(MembraneLaw):
    """Plane-stress St.Venant-Kirchhoff law (eq. 4.9): the default membrane law."""

    name = "svk"

    def stress(self, E: np.ndarray, *, tangent: bool = True):
        """S (2, 2, ...) and D (3, 3, ...) (a broadcast view of the constant matrix) or None."""
        E = np.asarray(E, dtype=float)
        S = self._svk(E)
        if not tangent:
            return S, None
        return S, np.broadcast_to(self.D_svk.reshape((3, 3) + (1,) * (E.ndim - 2)),
                                  (3, 3) + E.shape[2:])

    def energy_density(self, E: np.ndarray) -> np.ndarray:
        """W = lam tr(E)^2 / 2 + mu E:E per unit reference volume."""
        return self._svk_energy(np.asarray(E, dtype=float))


class TensionFieldLaw(MembraneLaw):
    """Tension-field (relaxed-energy) membrane law of the module docstring.

    Parameters
    ----------
    material : MembraneMaterial
    eta : float
        Regularisation: compressive stiffness of the wrinkled and slack states as a fraction
        of SVK's, W = (1 - eta) W_TF + eta W_SVK (0 <= eta < 1; default 1e-6).
    """

    name = "tension-field"

    def __init__(self, material: MembraneMaterial, *, eta: float = 1e-6):
        super().__init__(material)
        if not (isinstance(eta, (int, float)) and 0.0 <= eta < 1.0):
            raise InputError(f"tension-field law: expected 0 <= eta < 1, found eta={eta!r}")
        self.eta = float(eta)

    def stress(self, E: np.ndarray, *, tangent: bool = True):
        """S (2, 2, ...) and the consistent D = dS/dE (3, 3, ...) (or None) of the relaxed
        law, W = (1 - eta) W_TF + eta W_SVK."""
        E = np.asarray(E, dtype=float)
        e1, e2, th = principal_strains(E)
        state = self.state(E)
        taut, wr = state == TAUT, state == WRINKLED
        c, s = np.cos(th), np.sin(th)
        p = np.stack([c * c, s * s, c * s])                  # Voigt(n1 (x) n1)
        S_svk = self._svk(E)
        s1 = self.E * np.where(wr, e1, 0.0)                   # uniaxial tension E e1
        S_tf = np.where(taut, S_svk, s1 * np.stack([np.stack([p[0], p[2]]),
                                                    np.stack([p[2], p[1]])]))
        eta = self.eta
        S = (1.0 - eta) * S_tf + eta * S_svk
        if not tangent:
            return S, None
        q = np.stack([-2.0 * c * s, 2.0 * c * s, c * c - s * s])   # Voigt(n1 n2 + n2 n1)
        gap = np.where(wr, e1 - e2, 1.0)
        D_wr = self.E * _voigt_outer(p, p) + (self.E * np.where(wr, e1, 0.0) / (2.0 * gap)) \
            * _voigt_outer(q, q)
        D_svk = self.D_svk.reshape((3, 3) + (1,) * (E.ndim - 2))
        D_tf = np.where(taut, D_svk, np.where(wr, D_wr, 0.0))
        return S, (1.0 - eta) * D_tf + eta * D_svk

    def energy_density(self, E: np.ndarray) -> np.ndarray:
        """Relaxed energy (1 - eta) W_TF + eta W_SVK: W_SVK taut, E e1^2 / 2 wrinkled, 0 slack."""
        E = np.asarray(E, dtype=float)
        e1, _, _ = principal_strains(E)
        state = self.state(E)
        W_svk = self._svk_energy(E)
        W_tf = np.where(state == TAUT, W_svk, np.where(state == WRINKLED, 0.5 * self.E * e1**2, 0.0))
        return (1.0 - self.eta) * W_tf + self.eta * W_svk


def membrane_law(law, material) -> MembraneLaw:
    """The law object for ``law``: a name of :data:`MEMBRANE_LAWS` or a :class:`MembraneLaw`
    (returned as is when it carries the same material: a MembraneMaterial, or the
    ShellSection of a shell)."""
    if isinstance(law, MembraneLaw):
        if law.material != material:
            raise InputError(f"membrane law: its material {law.material} differs from the "
                             f"membrane's {material}")
        return law
    if law == "svk":
        return SVKLaw(material)
    if law == "tension-field":
        return TensionFieldLaw(material)
    raise InputError(f"membrane law: expected one of {MEMBRANE_LAWS} or a MembraneLaw, found {law!r}")


def check_law_name(law) -> str:
    """The name of a law given by name or object (for summaries and refusals)."""
    if isinstance(law, MembraneLaw):
        return law.name
    if law not in MEMBRANE_LAWS:
        raise InputError(f"membrane law: expected one of {MEMBRANE_LAWS}, found {law!r}")
    return law


def element_wrinkling(law: MembraneLaw, E: np.ndarray) -> dict:
    """Element states and tension directions from the strain E (2, 2, ne, nqp) at the Gauss
    points: ``state`` (ne,) int8, the state of most of the element's points (ties to the more
    relaxed state); ``direction`` (3, ne), the tension (wrinkle-crest) direction in the
    reference plane, the mean of the doubled angles over the element's wrinkled points, zero
    where none is wrinkled; ``state_qp`` (ne, nqp); ``fractions`` of points per state."""
    sq = law.state(E)
    counts = np.stack([(sq == k).sum(axis=1) for k in range(3)])       # (3, ne)
    state = (2 - np.argmax(counts[::-1], axis=0)).astype(np.int8)
    n = law.tension_direction(E)
    w = sq == WRINKLED
    c2 = np.sum(np.where(w, n[0]**2 - n[1]**2, 0.0), axis=1)
    s2 = np.sum(np.where(w, 2 * n[0] * n[1], 0.0), axis=1)
    th = 0.5 * np.arctan2(s2, c2)
    any_w = w.any(axis=1)
    direction = np.stack([np.where(any_w, np.cos(th), 0.0), np.where(any_w, np.sin(th), 0.0),
                          np.zeros_like(th)])
    fractions = counts.sum(axis=1) / sq.size
    return {"state": state, "direction": direction, "state_qp": sq,
            "fractions": dict(zip(STATE_NAMES, fractions.tolist()))}
