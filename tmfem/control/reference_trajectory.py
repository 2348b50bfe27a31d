"""Reference trajectories of a deployment (dissertation 7.4, eqs. 5.68, 3.19-3.20, 3.41).

The declination angle theta_r(t) follows the critically damped second-order system of
eq. 5.68 (xi_r = 1):

    theta_r'' + 2 xi_r omega_r theta_r' + omega_r^2 theta_r = omega_r^2 theta_e,
    theta_r(0) = theta_0,  theta_r'(0) = 0,

whose closed form for xi_r = 1 is theta_r = theta_e + (theta_0 - theta_e)(1 + omega_r t)
exp(-omega_r t). The path through the symmetric configurations is parametrised by the
progress s(t) = (theta_r - theta_0) / (theta_e - theta_0) in [0, 1]: every symmetric
parameter p of eqs. 3.19-3.20 (theta_i, psi_i, z_i, r_i, sigma_i) moves as
p(s) = p_0 + s (p_e - p_0). For a 1-N(D) system this gives psi_r linear in theta_r, and
the path is checked against the equilibrium conditions of eq. 3.41 (positive null vector of
eq. 3.40 and Delta > 0); for the 2-3 system the path runs through the region of symmetric
equilibria (eq. 5.97 family with the stage-2 base interpolated) and is checked by the
positive null vector of the reduced symmetric equilibrium matrix (3.3.2). The dissertation
does not print its psi_r(t) or its 2-3 path; this linear-in-s rule is our choice (see
docs/deployment.md). q_d, q_d' and q_d'' follow from eqs. 3.19-3.20 by the chain rule
(dq/ds, d2q/ds2 by central differences of the exact map s -> q).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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


def _angle_mask(q_names) -> np.ndarray:
    return np.array([n.startswith(("theta", "psi")) for n in q_names])


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
    """

    initial: SymmetricConfig
    final: SymmetricConfig
    N: int
    q_names: list
    omega_r: float

    def __post_init__(self):
        th0, the = self.initial.theta[0], self.final.theta[0]
        if abs(th0 - the) < 1e-9:
            raise InputError("deployment reference: expected different initial and final "
                             f"declination angles, found theta_0 = theta_e = {np.degrees(th0):.6g} deg")
        self._angles = _angle_mask(self.q_names)
        self.q_0 = self.initial.to_q(self.N)
        self.q_e = self._continuous(self.final.to_q(self.N))
        self._last = (None, None)

    def _continuous(self, q):
        d = q - self.q_0
        d[self._angles] = wrap_angle(d[self._angles])
        return self.q_0 + d

    def config(self, s: float) -> SymmetricConfig:
        """The symmetric configuration at progress s (linear in every parameter)."""
        a, b = self.initial, self.final
        lerp = lambda x, y: x + s * (y - x)                                     # noqa: E731
        return SymmetricConfig(theta=lerp(a.theta, b.theta), psi=lerp(a.psi, b.psi),
                               sigma=lerp(a.sigma, b.sigma), z=lerp(a.z, b.z), r=lerp(a.r, b.r),
                               l=a.l)

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
        h = 1e-5
        qp, q0, qm = self.q_of_s(s + h), self.q_of_s(s), self.q_of_s(s - h)
        dq = (qp - qm) / (2 * h)
        d2q = (qp - 2 * q0 + qm) / h**2
        out = (q0, dq * sd, d2q * sd**2 + dq * sdd)
        self._last = (t, out)
        return out

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
