"""Reference solutions of tension-field (wrinkling) membrane theory (docs/guides/wrinkling.md).

:func:`twisted_annulus`: an annular membrane a <= r <= b, prestressed by a radial
displacement delta of its outer edge (held there, u_theta(b) = 0) and twisted by a rigid hub
at r = a (u_r(a) = 0, u_theta(a) = a phi). Small-strain tension-field theory (Wagner,
Reissner, Mansfield; the problem of Mansfield 1970, "Load transfer via a wrinkled membrane",
Proc. R. Soc. A 316, 269-289, and the benchmark of Miller & Hedgepeth 1982, AIAA J. 20,
1761-1763, and Miller, Hedgepeth et al. 1985, Comput. Struct. 20, 631-639), derived here:

* torque: tau_r_theta = -k / r^2 everywhere (moment equilibrium), T = 2 pi h k;
* taut zone R <= r <= b (Lame + shear): u_r = alpha r + beta / r, omega = u_theta / r =
  k / (2 G) (1 / r^2 - 1 / b^2);
* wrinkled zone a <= r <= R (uniaxial tension sigma_1 along rays at angle psi to the radius,
  sigma_2 = 0 <=> sigma_r sigma_theta = tau^2): radial equilibrium d(r sigma_r)/dr =
  sigma_theta gives (r sigma_r)^2 = C - k^2 / r^2 (the tension rays are straight lines tangent
  to the circle of radius k / sqrt(C)); the kinematics of the relaxed law are
  eps_nn = sigma_1 / E along the ray and eps_nm = 0 (the principal strain directions follow
  the rays), two ODEs for (u_r, omega) integrated from R to a;
* the unknowns (alpha, beta, C, R) follow from u_r(b) = delta, sigma_2(R) = 0 (onset on the
  taut side), continuity of sigma_r at R and u_r(a) = 0; then phi = omega(a).

For k below the onset torque the annulus is taut throughout (R = a).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from tmfem.errors import InputError
from tmfem.system.materials import MembraneMaterial


@dataclass(frozen=True)
class AnnulusSolution:
    """Twisted prestressed annulus of :func:`twisted_annulus`.

    Attributes
    ----------
    R : float
        Outer radius of the wrinkled zone [m] (a: no wrinkles).
    phi : float
        Hub rotation [rad].
    torque : float
        Torque on the hub, 2 pi h k [N m].
    k : float
        -tau_r_theta r^2 [N/m^2 * m^2 = Pa m^2].
    sigma_r_hub : float
        Radial stress at the hub [Pa].
    ray_radius : float
        Radius of the circle the tension rays of the wrinkled zone are tangent to [m].
    """

    R: float
    phi: float
    torque: float
    k: float
    sigma_r_hub: float
    ray_radius: float


def _taut(r, alpha, beta, mat):
    P = mat.E / (1.0 - mat.nu**2)
    s_r = P * ((1 + mat.nu) * alpha - (1 - mat.nu) * beta / r**2)
    s_t = P * ((1 + mat.nu) * alpha + (1 - mat.nu) * beta / r**2)
    return s_r, s_t


def _onset_alpha(R, k, b, delta, mat, branch):
    """alpha, beta with u_r(b) = delta and sigma_r sigma_theta = (k / R^2)^2 at R (taut
    side, both positive); ``branch`` 0/1: the larger/smaller root of the quadratic."""
    P = mat.E / (1.0 - mat.nu**2)
    nu = mat.nu
    c1 = (1 + nu) + (1 - nu) * b**2 / R**2
    c2 = (1 + nu) - (1 - nu) * b**2 / R**2
    d = (1 - nu) * b * delta / R**2
    K = (k / (R**2 * P))**2
    roots = np.roots([c1 * c2, (c1 - c2) * d, -d * d - K])
    ok = []
    for al in sorted(roots.real[np.abs(roots.imag) < 1e-14 * np.abs(roots).max()], reverse=True):
        be = b * (delta - al * b)
        s_r, s_t = _taut(R, al, be, mat)
        if s_r > 0 and s_t > 0:
            ok.append((al, be))
    if len(ok) > branch:
        return ok[branch]
    raise InputError(f"twisted annulus: no taut prestress with sigma_2(R) = 0 at R = {R:g} m")


def _wrinkled_ur_at_hub(R, k, a, b, delta, mat, branch=0):
    """Integrate the wrinkled-zone ODEs from R to a; returns u_r(a), omega(a), C."""
    al, be = _onset_alpha(R, k, b, delta, mat, branch)
    s_rR, _ = _taut(R, al, be, mat)
    C = (R * s_rR)**2 + k**2 / R**2
    G = mat.E / (2 * (1 + mat.nu))
    u0 = al * R + be / R
    w0 = k / (2 * G) * (1 / R**2 - 1 / b**2)

    if C - k**2 / a**2 <= 0.0:
        # the tension rays (tangent to the circle of radius k / sqrt(C)) miss the hub
        return np.nan, np.nan, C

    def rhs(r, y):
        u = y[0]
        s_r = np.sqrt(C - k**2 / r**2) / r
        tau = -k / r**2
        s_t = tau**2 / s_r
        s1 = s_r + s_t
        c2, s2, sc = s_r / s1, s_t / s1, tau / s1
        A = np.array([[c2, sc], [-sc, 0.5 * (c2 - s2)]])
        p, q = np.linalg.solve(A, [s1 / mat.E - u / r * s2, -u / r * sc])
        return [p, q / r]

    sol = solve_ivp(rhs, (R, a), [u0, w0], method="DOP853", rtol=1e-12, atol=1e-18)
    return sol.y[0, -1], sol.y[1, -1], C


def twisted_annulus(*, a: float, b: float, material: MembraneMaterial, delta: float,
                    torque: float) -> AnnulusSolution:
    """Wrinkled radius and hub rotation of the prestressed annulus twisted by ``torque`` [N m]
    (module docstring; small-strain tension-field theory, derived there).

    Parameters
    ----------
    a, b : float
        Hub and outer radius [m], 0 < a < b.
    material : MembraneMaterial
    delta : float
        Outward radial displacement of the outer edge [m] (> 0: prestress).
    torque : float
        Torque applied to the hub [N m] (> 0).
    """
    if not (0 < a < b and delta > 0 and torque > 0):
        raise InputError(f"twisted annulus: expected 0 < a < b, delta > 0, torque > 0, found "
                         f"a={a}, b={b}, delta={delta}, torque={torque}")
    mat = material
    k = torque / (2 * np.pi * mat.h)
    G = mat.E / (2 * (1 + mat.nu))
    # fully taut: u_r(a) = 0, u_r(b) = delta
    al = delta * b / (b**2 - a**2)
    be = -al * a**2
    s_r, s_t = _taut(a, al, be, mat)
    if (k / a**2)**2 <= s_r * s_t:
        return AnnulusSolution(R=a, phi=k / (2 * G) * (1 / a**2 - 1 / b**2), torque=torque, k=k,
                               sigma_r_hub=s_r, ray_radius=float("nan"))
    Rs = np.linspace(a * (1 + 1e-9), b * (1 - 1e-9), 400)

    def g(R, branch):
        try:
            return _wrinkled_ur_at_hub(R, k, a, b, delta, mat, branch)[0]
        except InputError:
            return np.nan
    found = []
    vals = {}
    for branch in (0, 1):
        vals[branch] = v = np.array([g(R, branch) for R in Rs])
        for i in np.flatnonzero(np.isfinite(v[:-1]) & np.isfinite(v[1:])
                                & (np.sign(v[:-1]) != np.sign(v[1:]))):
            found.append((brentq(g, Rs[i], Rs[i + 1], args=(branch,), xtol=1e-14 * b), branch))
    # the two roots of the onset quadratic meet at a fold R*: a root can sit on the fold,
    # between the first valid samples of the two branches; follow the fold parametrised by
    # s in [-1, 1], R = R* + (R_1 - R*) s^2 (s > 0: branch 0, s < 0: branch 1)
    both = np.flatnonzero(np.isfinite(vals[0]) & np.isfinite(vals[1]))
    if both.size and both[0] > 0 and np.sign(vals[0][both[0]]) != np.sign(vals[1][both[0]]):
        R1 = Rs[both[0]]
        Rstar = brentq(lambda R: 1.0 if np.isfinite(g(R, 0)) else -1.0, Rs[both[0] - 1], R1,
                       xtol=1e-15 * b)
        Rstar = Rstar + 1e-13 * b if not np.isfinite(g(Rstar, 0)) else Rstar
        def fold(t, Rstar=Rstar, R1=R1):
            return g(Rstar + (R1 - Rstar) * t * t, 0 if t > 0 else 1)
        t = brentq(fold, -1.0, 1.0, xtol=1e-12)
        found.append((Rstar + (R1 - Rstar) * t * t, 0 if t > 0 else 1))
    if len(found) != 1:
        raise InputError(f"twisted annulus: expected one wrinkled radius in ({a}, {b}) for "
                         f"torque {torque:g} N m, found {len(found)}: {found}")
    R, branch = found[0]
    _, phi, C = _wrinkled_ur_at_hub(R, k, a, b, delta, mat, branch)
    return AnnulusSolution(R=float(R), phi=float(phi), torque=torque, k=k,
                           sigma_r_hub=float(np.sqrt(C - k**2 / a**2) / a),
                           ray_radius=float(k / np.sqrt(C)))
