"""A small LPV plant whose matrices depend on cos(rho) and sin(rho): the design example of
:func:`tmfem.control.lpv.gridded_synthesis.lpvsyn` (docs/guides/lpvsyn.md, its tests and benchmark).

A unit mass moving in a plane (positions q = (q1, q2)) held by an anisotropic spring whose
stiff axis turns with the angle rho/2 (a spring on a rotating mount)::

    q'' + c q' + K(rho) q = f_w + b u,
    K(rho) = k0 I + k1 [[cos rho, sin rho], [sin rho, -cos rho]]

(eigenvalues k0 +- k1, stiff direction (cos rho/2, sin rho/2); with k1 > k0 the soft
direction has negative stiffness, a saddle that turns with rho, and every frozen plant is
unstable); two actuators of unequal
strength in the fixed axes, b = diag(1, b2), the disturbance forces f_w in both directions.
Regulated outputs p = [q1, q2, r u1, r u2]; the measurement (output feedback) y = q + n_v v
with noise v. Every frozen plant is controllable and observable; the stiff axis turns, so a
Lyapunov matrix that follows it, R(rho/2) X_0 R(rho/2)^T, lies in span{1, cos rho, sin rho}.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError


def rotating_spring(*, k0: float = 1.0, k1: float = 0.6, c: float = 0.1, r: float = 0.1,
                    b2: float = 0.5, noise: float = 0.1, output_feedback: bool = True):
    """The plant as a callable rho -> (A, B, C, D) with inputs [f_w (2), v (2, output feedback
    only), u (2)] and outputs [q1, q2, r u (2), y (2, output feedback only)] (module docstring)."""
    for nm, v in (("c", c), ("r", r), ("b2", b2), ("noise", noise)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"rotating spring: expected {nm} > 0, found {v!r}")
    if not (np.isfinite(k1) and k1 >= 0):
        raise InputError(f"rotating spring: expected k1 >= 0, found {k1!r}")
    nw = 4 if output_feedback else 2

    def P(rho):
        t = float(np.asarray(rho, dtype=float).reshape(-1)[0])
        K = k0 * np.eye(2) + k1 * np.array([[np.cos(t), np.sin(t)], [np.sin(t), -np.cos(t)]])
        A = np.block([[np.zeros((2, 2)), np.eye(2)], [-K, -c * np.eye(2)]])
        B1 = np.zeros((4, nw))
        B1[:2, :2] = np.eye(2)
        B2 = np.zeros((4, 2))
        B2[2, 0], B2[3, 1] = 1.0, b2
        C1 = np.zeros((4, 4))
        C1[0, 0] = C1[1, 1] = 1.0
        D1 = np.zeros((4, nw + 2))
        D1[2:, nw:] = r * np.eye(2)
        B = np.hstack([B1, B2])
        if not output_feedback:
            return A, B, C1, D1
        C2 = np.hstack([np.eye(2), np.zeros((2, 2))])
        D2 = np.zeros((2, nw + 2))
        D2[:, 2:4] = noise * np.eye(2)
        return A, B, np.vstack([C1, C2]), np.vstack([D1, D2])

    return P
