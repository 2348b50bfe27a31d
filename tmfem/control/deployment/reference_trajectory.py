"""Reference trajectories of a deployment (dissertation 7.4, eqs. 5.68, 3.19-3.20, 3.41).

The declination angle theta_r(t) follows the critically damped second-order system of
eq. 5.68 (xi_r = 1):

    theta_r'' + 2 xi_r omega_r theta_r' + omega_r^2 theta_r = omega_r^2 theta_e,
    theta_r(0) = theta_0,  theta_r'(0) = 0,

whose closed form for xi_r = 1 is theta_r = theta_e + (theta_0 - theta_e)(1 + omega_r t)
exp(-omega_r t). The path through the symmetric configurations is parametrised by the
progress s(t) = (theta_r - theta_0) / (theta_e - theta_0) in [0, 1]: by default every
symmetric parameter p of eqs. 3.19-3.20 (theta_i, psi_i, z_i, r_i, sigma_i) moves as
p(s) = p_0 + s (p_e - p_0). Two rules keep the membrane stretch Delta of eq. 3.22 -- and
with it the prestress -- between its end values instead (a linear psi or linear bases
stretch the membrane mid-path, see docs/guides/deployment.md):

* 1-N(D) (``r_mb`` given): psi_r from eq. 3.22 solved for psi with
  Delta(s) = Delta_0 + s (Delta_e - Delta_0),
  sin(psi + pi/N) = (l^2 sin^2 theta + r_1^2 - (r_mb + Delta)^2) / (2 r_1 l sin theta)
  (psi_r "from the equilibrium conditions of eq. 3.41", 7.4);
* multi-stage (2-3, ``bases`` given): the stage bases (r_i, z_i, sigma_i, i >= 2) from a rule
  ``bases(theta, psi)`` of the eq. 5.97 family (the reconstructed Table 7.7 rule,
  :func:`tmfem.reference.tables.deployment_bases`: z_2 = 0.7 l cos(theta), r_2 such that
  Delta = 1 mm);
* any symmetric M >= 2 system (``path`` given): the automatic path of
  :mod:`tmfem.equilibrium.deployment_path` (stage bases as a smooth continuation of feasible
  bases, Delta linear in s), a map s -> configuration.

The path is checked against the equilibrium conditions (eq. 3.41 for 1-N(D): positive null
vector of eq. 3.40 and Delta > 0; the positive null vector of the reduced symmetric
equilibrium matrix of 3.3.2 otherwise). The dissertation does not print its psi_r(t) or its
2-3 path; these rules are our choice (docs/guides/deployment.md). q_d, q_d' and q_d'' follow from
eqs. 3.19-3.20 by the chain rule (q, dq/ds, d2q/ds2 from a cubic spline through the exact
map s -> q at 401 points).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.interpolate import CubicSpline

from tmfem.errors import InputError, InfeasibleDesign
from tmfem.system.geometry import SymmetricConfig, wrap_angle


def theta_reference(t, *, theta_0: float, theta_e: float, omega_r: float, xi_r: float = 1.0):
    """theta_r, theta_r', theta_r'' of eq. 5.68 at times t (closed form; xi_r = 1 only).

    Raises
    ------
    InputError
        xi_r != 1 (the dissertation's choice; the closed form here is the critically damped
        one) or omega_r <= 0.
    """
    if xi_r != 1.0:
        raise InputError(f"eq. 5.68: expected xi_r = 1 (critically damped, 7.4), found {xi_r!r}")
    if not (np.isfinite(omega_r) and omega_r > 0):
        raise InputError(f"eq. 5.68: expected omega_r > 0, found {omega_r!r}")
    t = np.asarray(t, dtype=float)
    a = theta_0 - theta_e
    w = omega_r
    ex = np.exp(-w * t)
    th = theta_e + a * (1 + w * t) * ex
    thd = -a * w**2 * t * ex
    thdd = -a * w**2 * (1 - w * t) * ex
    return th, thd, thdd


#: spline intervals of the path s -> q (q_d'' to about 1e-6 relative, see the tests)
N_PATH = 400


def angle_mask(q_names) -> np.ndarray:
    """True where a bar coordinate of ``q_names`` is an angle (theta, psi of eqs. 3.1-3.2,
    [rad]), False where it is a position (the bases x, y, z of the upper stages, [m])."""
    return np.array([n.startswith(("theta", "psi")) for n in q_names], dtype=bool)


@dataclass
class DeploymentReference:
    """The deployment path between two symmetric configurations of the same system.

    Parameters
    ----------
    initial, final : SymmetricConfig
        Packaged and deployed configurations (eqs. 3.19-3.20).
    N : int
        Bars per stage.
    q_names : list of str
        Names of q (the angle entries are wrapped continuously).
    omega_r : float
        Natural frequency of eq. 5.68 [rad/s] (7.4: 0.7, 0.35, 0.5).
    bases : callable, optional
        ``bases(theta, psi) -> {"r", "z", "sigma"}`` (psi relative to the stage base, eq.
        5.97, psi_i = psi + sigma_i): the stage bases along the path instead of their
        linear interpolation. It must reproduce both ends.
    r_mb : float, optional
        Membrane circumradius of a one-stage system: psi_r from eq. 3.22 with Delta linear
        in s (module docstring).
    path : callable, optional
        ``path(s) -> SymmetricConfig``: the whole configuration along the progress s (e.g.
        :meth:`tmfem.equilibrium.deployment_path.SymmetricPath.config`). It must reproduce
        both ends.
    """

    initial: SymmetricConfig
    final: SymmetricConfig
    N: int
    q_names: list
    omega_r: float
    bases: Callable | None = None
    r_mb: float | None = None
    path: Callable | None = None

    def __post_init__(self):
        th0, the = self.initial.theta[0], self.final.theta[0]
        if abs(th0 - the) < 1e-9:
            raise InputError("deployment reference: expected different initial and final "
                             f"declination angles, found theta_0 = theta_e = {np.degrees(th0):.6g} deg")
        self._angles = angle_mask(self.q_names)
        if self.r_mb is not None:
            if self.bases is not None or self.initial.M != 1:
                raise InputError("deployment path: expected the Delta rule (r_mb) for a "
                                 f"one-stage system without a bases rule, found M = "
                                 f"{self.initial.M}" + (" and a bases rule" if self.bases else ""))
            self._Delta = [c.membrane_delta(self.N, self.r_mb) for c in (self.initial, self.final)]
        if sum(x is not None for x in (self.bases, self.r_mb, self.path)) > 1:
            raise InputError("deployment path: expected one rule of bases, r_mb (Delta) and path, "
                             "found several")
        if self.bases is not None or self.r_mb is not None or self.path is not None:
            for s, end in ((0.0, self.initial), (1.0, self.final)):
                c = self.config(s)
                err = max(float(np.max(np.abs(getattr(c, k) - getattr(end, k))))
                          for k in ("psi", "r", "z", "sigma"))
                if err > 1e-5:
                    raise InputError(f"deployment path: expected the path rule to reproduce "
                                     f"the stage bases of the {'initial' if s == 0 else 'final'} "
                                     f"configuration, found a difference of {err:.3g} (m or rad)")
        self.q_0 = self.initial.to_q(self.N)
        self.q_e = self._continuous(self.final.to_q(self.N))
        self._last = (None, None)

    def _continuous(self, q):
        d = q - self.q_0
        d[self._angles] = wrap_angle(d[self._angles])
        return self.q_0 + d

    def config(self, s: float) -> SymmetricConfig:
        """The symmetric configuration at progress s (linear in every parameter, the
        stage bases from ``bases``, psi from the Delta rule, or ``path(s)``)."""
        if self.path is not None:
            return self.path(s)
        a, b = self.initial, self.final
        lerp = lambda x, y: x + s * (y - x)                                     # noqa: E731
        theta, psi = lerp(a.theta, b.theta), lerp(a.psi, b.psi)
        if self.r_mb is not None:
            return SymmetricConfig(theta=theta, psi=[self._psi_for_delta(theta[0], s)],
                                   sigma=a.sigma, z=a.z, r=a.r, l=a.l)
        if self.bases is None:
            return SymmetricConfig(theta=theta, psi=psi, sigma=lerp(a.sigma, b.sigma),
                                   z=lerp(a.z, b.z), r=lerp(a.r, b.r), l=a.l)
        rule = self.bases(float(theta[0]), float(psi[0]))                 # eq. 5.97 family
        sigma = np.asarray(rule["sigma"], dtype=float)
        return SymmetricConfig(theta=theta, psi=psi[0] + sigma, sigma=sigma, z=rule["z"],
                               r=rule["r"], l=a.l)

    def _psi_for_delta(self, theta: float, s: float) -> float:
        """psi of eq. 3.22 for Delta(s) = Delta_0 + s (Delta_e - Delta_0), one-stage system,
        on the branch psi + pi/N = asin(...) of the end configurations."""
        D = self._Delta[0] + s * (self._Delta[1] - self._Delta[0])
        c = self.initial
        L, r = c.l[0] * np.sin(theta), c.r[0]
        x = (L**2 + r**2 - (self.r_mb + D)**2) / (2 * r * L)
        if abs(x) > 1:
            raise InfeasibleDesign(f"deployment path at s = {s:.3g}: no azimuth gives Delta = "
                                   f"{D:.4g} m (eq. 3.22) at theta = {np.degrees(theta):.4g} deg")
        return float(np.arcsin(x) - np.pi / self.N)

    def q_of_s(self, s: float) -> np.ndarray:
        return self._continuous(self.config(s).to_q(self.N))

    def progress(self, t):
        """s, s', s'' of the progress s = (theta_r - theta_0)/(theta_e - theta_0)."""
        th0, the = self.initial.theta[0], self.final.theta[0]
        th, thd, thdd = theta_reference(t, theta_0=th0, theta_e=the, omega_r=self.omega_r)
        k = 1.0 / (the - th0)
        return (th - th0) * k, thd * k, thdd * k

    def __call__(self, t: float):
        """q_d, q_d', q_d'' at time t (the last evaluation is cached)."""
        if self._last[0] == t:
            return self._last[1]
        s, sd, sdd = (float(v) for v in self.progress(t))
        c = self._path()
        i = min(max(int(s * N_PATH), 0), N_PATH - 1)
        x = s - i / N_PATH
        c3, c2, c1, c0 = c[:, i]                   # the cubic piece on [s_i, s_i+1]
        q0 = ((c3 * x + c2) * x + c1) * x + c0
        dq = (3 * c3 * x + 2 * c2) * x + c1
        d2q = 6 * c3 * x + 2 * c2
        out = (q0, dq * sd, d2q * sd**2 + dq * sdd)
        self._last = (t, out)
        return out

    def _path(self) -> np.ndarray:
        """s -> q as a cubic spline (scipy ``CubicSpline``, not-a-knot) through the exact
        map at N_PATH + 1 evenly spaced progress values, built once; exact at its knots
        (s = 0 and s = 1 among them). Returns its coefficients (4, N_PATH, n_q), highest
        power first, for q, dq/ds and d2q/ds2 of the chain rule of q_d' and q_d''."""
        if getattr(self, "_spline", None) is None:
            ss = np.linspace(0.0, 1.0, N_PATH + 1)
            self._spline = CubicSpline(ss, np.array([self.q_of_s(s) for s in ss]), axis=0).c
        return self._spline

    def check_equilibria(self, *, checker, n: int = 21) -> np.ndarray:
        """Run ``checker(config)`` (raising an InfeasibleDesign where the configuration is not
        an equilibrium) at n progress values; returns the s values checked.

        Raises
        ------
        InfeasibleDesign
            naming the progress s and the angles where the path leaves the equilibria.
        """
        ss = np.linspace(0.0, 1.0, n)
        for s in ss:
            c = self.config(s)
            try:
                checker(c)
            except InfeasibleDesign as exc:
                raise type(exc)(f"deployment path at s = {s:.3g} (theta = "
                                f"{np.degrees(c.theta).round(3).tolist()} deg, psi = "
                                f"{np.degrees(c.psi).round(3).tolist()} deg) is not an "
                                f"equilibrium: {exc}") from None
        return ss
