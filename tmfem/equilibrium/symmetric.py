"""Closed-form equilibrium conditions of symmetric one-stage systems (dissertation 3.3.3-3.3.4).

1-N systems (eqs. 3.29-3.37): tendon length |S_1|, the 2 x 2 matrix A_1N acting on the
averaged forces (T_1^S / |S_1|, F_Delta / (Delta + r_mb)), its determinant, the base radius
r_1 that makes it singular, the null vector and the tension conditions.

1-N(D) systems (eqs. 3.38-3.41): tendon lengths |SL|, |SU|, the 2 x 3 matrix A_1N^D, its
null vector and the tension conditions.

Delta of eq. 3.22 (any symmetric M-N system) is :func:`membrane_delta`
(:func:`tmfem.system.geometry.membrane_delta`, also ``SymmetricConfig.membrane_delta``).

All functions take plain numbers (radians); the ``*_system`` helpers read them from a
symmetric :class:`tmfem.system.System`. The checks raise :class:`SlackMembrane`,
:class:`SlackTendon` or :class:`InfeasibleDesign` naming the violated condition (equation
number) with its numbers.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InfeasibleDesign, InputError, SlackMembrane, SlackTendon
from tmfem.system.geometry import cross3
from tmfem.system.geometry import membrane_delta  # noqa: F401 (eq. 3.22, re-exported)


# ---------------------------------------------------------------------------- any M-N
def _sym(system):
    cfg = system.symmetric
    if cfg is None:
        raise InputError(f"system {system.name!r} has no symmetric parametrisation (3.3.1)")
    if system.r_mb is None:
        raise InputError(f"system {system.name!r}: expected a regular membrane (r_mb), found none")
    return cfg


def membrane_delta_system(system) -> float:
    """Delta of eq. 3.22 for a symmetric system."""
    return _sym(system).membrane_delta(system.N, system.r_mb)


# ---------------------------------------------------------------------------- 1-N
def s1_length(*, l1, theta1, psi1, r1, N):
    """Length |S_1| of every tendon S_1j of a symmetric 1-N system (eq. 3.29)."""
    s = np.sin(np.pi / N)
    return np.sqrt(l1**2 + 4 * r1**2 * s**2 - 4 * r1 * l1 * s * np.sin(theta1) * np.cos(psi1))


def A_1N(*, l1, theta1, psi1, r1, N) -> np.ndarray:
    """The 2 x 2 matrix of eq. 3.31 acting on the averaged forces (T_1^S/|S_1|, F_D/(D+r_mb)).

    Rows are the generalised forces Q_theta^1, Q_psi^1 (up to a common factor per row).
    """
    s, c = np.sin(theta1), np.cos(theta1)
    sn = np.sin(np.pi / N)
    return np.array([
        [-2 * r1 * l1 * sn * c * np.cos(psi1), l1 * c * (l1 * s - r1 * np.sin(psi1 + np.pi / N))],
        [2 * r1 * l1 * sn * s * np.sin(psi1), -r1 * l1 * s * np.cos(psi1 + np.pi / N)],
    ])


def det_A_1N(*, l1, theta1, psi1, r1, N):
    """Determinant of A_1N in the closed form of eq. 3.32."""
    return (r1 * l1**2 * np.sin(2 * theta1) * np.sin(np.pi / N)
            * (r1 * np.cos(np.pi / N) - l1 * np.sin(theta1) * np.sin(psi1)))


def r1_1N(*, l1, theta1, psi1, N):
    """Base radius r_1 of a 1-N equilibrium (eq. 3.33): the nontrivial root of eq. 3.32."""
    return l1 * np.sin(theta1) * np.sin(psi1) / np.cos(np.pi / N)


def force_density_ratio_1N(*, psi1, N):
    """Ratio (T_1^S/|S_1|) / (F_Delta/(Delta + r_mb)) of the null vector of A_1N (eq. 3.34)."""
    return np.cos(psi1 + np.pi / N) / (2 * np.sin(psi1) * np.sin(np.pi / N))


def delta_1N(*, l1, theta1, psi1, r_mb, N):
    """Delta of a 1-N equilibrium, eq. 3.22 with r_1 of eq. 3.33 inserted (eq. 3.36)."""
    return -r_mb + l1 * np.sin(theta1) * np.cos(np.pi / N + psi1) / np.cos(np.pi / N)


def closed_form_1N(system) -> dict:
    """All closed-form quantities of eqs. 3.29-3.36 for a symmetric 1-N system."""
    c = _sym(system)
    if system.M != 1 or system.deployable:
        raise InputError(f"expected a 1-N system, found {system.M}-{system.N}"
                         f"{'(D)' if system.deployable else ''}")
    p = dict(l1=c.l[0], theta1=c.theta[0], psi1=c.psi[0], N=system.N)
    S1 = float(s1_length(r1=c.r[0], **p))
    delta = membrane_delta_system(system)
    ratio = float(force_density_ratio_1N(psi1=c.psi[0], N=system.N))
    return {
        "S1": S1, "A": A_1N(r1=c.r[0], **p), "det": float(det_A_1N(r1=c.r[0], **p)),
        "r1_equilibrium": float(r1_1N(**p)), "ratio": ratio, "delta": delta,
        "delta_3_36": float(delta_1N(r_mb=system.r_mb, **p)), "r_mb": system.r_mb,
    }


def tendon_force_1N(system, F_delta: float) -> float:
    """T_1^S = |S_1| * ratio * F_Delta / (Delta + r_mb) from the null vector (eqs. 3.30, 3.34)."""
    cf = closed_form_1N(system)
    return cf["S1"] * cf["ratio"] * F_delta / (cf["delta"] + system.r_mb)


def check_1N(system, *, rtol: float = 1e-3) -> dict:
    """Check the equilibrium conditions of eq. 3.37 and return the closed forms.

    Raises
    ------
    InfeasibleDesign
        r_1 differs from eq. 3.33 by more than ``rtol`` (relative).
    SlackTendon
        ``cot psi_1 <= tan(pi/N)`` or ``psi_1 <= 0`` (eq. 3.35): tendons S would push.
    SlackMembrane
        Delta <= 0 (eq. 3.36): the membrane is not stretched.
    """
    c = _sym(system)
    cf = closed_form_1N(system)
    N = system.N
    psi = c.psi[0]
    r_eq = cf["r1_equilibrium"]
    if not (r_eq > 0 and np.tan(np.pi / N) < 1 / np.tan(psi)):
        raise SlackTendon(
            f"eq. 3.35 violated: expected 0 < psi_1 and cot(psi_1) > tan(pi/N) = "
            f"{np.tan(np.pi / N):.4g}, found psi_1 = {np.degrees(psi):.4g} deg, cot(psi_1) = "
            f"{1 / np.tan(psi):.4g}; force density ratio T_S/F_D (eq. 3.34) = {cf['ratio']:.4g}")
    if abs(c.r[0] - r_eq) > rtol * r_eq:
        raise InfeasibleDesign(
            f"eq. 3.33 violated: expected r_1 = l_1 sin(theta_1) sin(psi_1)/cos(pi/N) = "
            f"{r_eq:.6g} m, found r_1 = {c.r[0]:.6g} m (relative difference "
            f"{abs(c.r[0] - r_eq) / r_eq:.3g} > {rtol:g}); det A_1N (eq. 3.32) = {cf['det']:.4g}")
    if not cf["delta"] > 0:
        raise SlackMembrane(
            f"eq. 3.36 violated: expected Delta > 0, found Delta = {cf['delta']:.6g} m "
            f"(r_mb = {system.r_mb:.6g} m must be < l_1 sin(theta_1) cos(pi/N + psi_1)/cos(pi/N)"
            f" = {cf['delta'] + system.r_mb:.6g} m)")
    return cf


# ---------------------------------------------------------------------------- 1-N(D)
def sl_su_lengths(*, l1, theta1, psi1, r1, k_H, N):
    """Lengths |SL| and |SU| of a symmetric 1-N(D) system (eq. 3.38)."""
    sn = np.sin(np.pi / N)
    st = np.sin(theta1)
    SL = np.sqrt(4 * r1**2 * sn**2 + k_H**2 * l1**2 - 4 * k_H * r1 * l1 * st * np.cos(psi1) * sn)
    SU = np.sqrt(4 * r1 * sn * (r1 * sn + l1 * st * (np.cos(psi1 + 2 * np.pi / N) - k_H * np.cos(psi1)))
                 + l1**2 * (1 + k_H**2 - 2 * k_H * (np.cos(np.pi / N)**2
                                                   + sn**2 * np.cos(2 * theta1))))
    return SL, SU


def A_1ND(*, l1, theta1, psi1, r1, k_H, N) -> np.ndarray:
    """The 2 x 3 matrix of eq. 3.40 acting on (T_SL/|SL|, T_SU/|SU|, F_D/(D + r_mb))."""
    s, c = np.sin(theta1), np.cos(theta1)
    sn = np.sin(np.pi / N)
    a = np.pi / N
    return np.array([
        [-2 * k_H * r1 * l1 * c * np.cos(psi1),
         2 * l1 * c * (r1 * (np.cos(psi1 + 2 * a) - k_H * np.cos(psi1)) + 2 * k_H * l1 * s * sn),
         l1 * c * (l1 * s - r1 * np.sin(psi1 + a)) / sn],
        [2 * k_H * r1 * l1 * s * np.sin(psi1),
         -2 * r1 * l1 * s * (np.sin(psi1 + 2 * a) - k_H * np.sin(psi1)),
         -r1 * l1 * s * np.cos(psi1 + a) / sn],
    ])


def null_vector_1ND(A: np.ndarray) -> np.ndarray:
    """Null vector of a full-rank 2 x 3 matrix (cross product of its rows), scaled so that
    the last entry (the averaged membrane force) is 1 when it is nonzero; A of shape
    (2, 3, ...) gives the null vectors (3, ...) of a stack of matrices."""
    v = cross3(A[0], A[1])
    scaled = np.abs(v[2]) > 1e-14 * np.sqrt(np.sum(v * v, axis=0))
    return np.where(scaled, v / np.where(scaled, v[2], 1.0), v)


def feasible_1ND(system, *, theta1, psi1) -> tuple[np.ndarray, np.ndarray]:
    """The conditions of :func:`check_1ND` for the symmetric 1-N(D) ``system`` moved to the
    declinations ``theta1`` and azimuths ``psi1`` [rad] (arrays that broadcast; its r_1, l_1,
    k_H and r_mb held): a null vector of A_1N^D (eq. 3.40) with all entries positive and
    Delta > 0 (eq. 3.22). Returns the mask of the feasible configurations and their Delta."""
    c = _sym(system)
    v = null_vector_1ND(A_1ND(l1=c.l[0], theta1=theta1, psi1=psi1, r1=c.r[0], k_H=system.k_H, N=system.N))
    D = membrane_delta(l_M=c.l[0], theta_M=theta1, psi_M=psi1, sigma_M=c.sigma[0], r_M=c.r[0],
                       r_mb=system.r_mb, N=system.N)
    return np.all(v > 0, axis=0) & (D > 0), D


def r1_bounds_1ND(*, l1, theta1, psi1, k_H, N):
    """Bounds on r_1 for a positive null vector of A_1N^D (eq. 3.40).

    With L = l_1 sin(theta_1) and a = pi/N, the null vector (cross product of the rows of
    eq. 3.40) is, up to positive factors,

        T_SL/|SL| ~ (1 - k_H) (L sin(psi_1 + 2a) - r_1 cos a)
        T_SU/|SU| ~ k_H (L sin(psi_1) - r_1 cos a)
        F_D/(D + r_mb) ~ k_H (r_1 cos a - k_H L sin(psi_1)),

    so it is positive if and only if ``lower < r_1 < min(upper, upper_SL)`` with
    lower = k_H L sin(psi_1)/cos a, upper = L sin(psi_1)/cos a (the two bounds of eq. 3.41)
    and upper_SL = L sin(psi_1 + 2a)/cos a, which eq. 3.41 omits; it binds when
    psi_1 > pi/2 - pi/N (docs/validation/errata.md).

    Returns
    -------
    lower, upper, upper_SL : float
    """
    L = l1 * np.sin(theta1)
    ca = np.cos(np.pi / N)
    return (k_H * L * np.sin(psi1) / ca, L * np.sin(psi1) / ca,
            L * np.sin(psi1 + 2 * np.pi / N) / ca)


def closed_form_1ND(system) -> dict:
    """Closed-form quantities of eqs. 3.38-3.41 for a symmetric 1-N(D) system."""
    c = _sym(system)
    if not system.deployable:
        raise InputError(f"expected a 1-N(D) system, found {system.M}-{system.N}")
    g = dict(l1=c.l[0], theta1=c.theta[0], psi1=c.psi[0], N=system.N)
    p = dict(g, r1=c.r[0], k_H=system.k_H)
    SL, SU = sl_su_lengths(**p)
    A = A_1ND(**p)
    v = null_vector_1ND(A)
    lo, up, up_sl = r1_bounds_1ND(k_H=system.k_H, **g)
    return {"SL": float(SL), "SU": float(SU), "A": A, "null": v,
            "r1_upper": float(up), "r1_lower": float(lo), "r1_upper_SL": float(up_sl),
            "delta": membrane_delta_system(system),
            "delta_3_41": float(delta_1N(r_mb=system.r_mb, **g)),
            "r_mb": system.r_mb}


def check_1ND(system) -> dict:
    """Check that a 1-N(D) design has a positive null vector of A_1N^D and Delta > 0.

    The null vector of eq. 3.40 is tested directly; the bounds on r_1 of eq. 3.41 are
    reported alongside. Delta is that of eq. 3.22 with the actual r_1 (eq. 3.41 uses the
    1-N expression of eq. 3.36, which assumes r_1 of eq. 3.33; see docs/validation/errata.md).

    Raises
    ------
    SlackTendon
        an entry of the null vector (T_SL/|SL|, T_SU/|SU|) is not positive.
    SlackMembrane
        Delta <= 0.
    """
    cf = closed_form_1ND(system)
    v = cf["null"]
    r1 = system.symmetric.r[0]
    if not (np.all(v > 0)):
        raise SlackTendon(
            "eq. 3.41 violated: expected a null vector of A_1N^D (eq. 3.40) with all entries "
            f"positive, found (T_SL/|SL|, T_SU/|SU|, F_D/(D+r_mb)) proportional to "
            f"({v[0]:.4g}, {v[1]:.4g}, {v[2]:.4g}); r_1 = {r1:.6g} m, expected "
            f"{cf['r1_lower']:.6g} < r_1 < min({cf['r1_upper']:.6g}, {cf['r1_upper_SL']:.6g}) m "
            "(eq. 3.41 and the bound r_1 < l_1 sin(theta_1) sin(psi_1 + 2 pi/N)/cos(pi/N) "
            "that it omits)")
    if not cf["delta"] > 0:
        raise SlackMembrane(f"eq. 3.22 violated: expected Delta > 0, found Delta = "
                            f"{cf['delta']:.6g} m (r_mb = {system.r_mb:.6g} m)")
    return cf
