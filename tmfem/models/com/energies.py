"""The energies of the control-oriented model's Lagrangian and Lagrange's equations, in
casadi SX form (eqs. 3.6, 5.2-5.6, 5.12-5.13, 5.19).

The Lagrangian of eq. 5.12 is L = T_b + T_m - U_td - U_m (+ lambda^T Phi, eliminated by
:mod:`tmfem.models.com.graphs`); the bar kinetic energy T_b (eqs. 5.9-5.11) is
:func:`tmfem.models.com.kinematics.bar_kinetic_energy_sx`. Every function here returns an
expression that casadi differentiates exactly.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from tmfem.models.com.kinematics import bars_sx, rotation_ef_sx, tendon_lengths_sx


def membrane_kinetic_energy_sx(system, membrane, layout, q, zeta, eta, ddt):
    """Kinetic energy of the membrane in the floating frame (eqs. 5.2-5.3).

    With r_f = sum_a xibar_a P_a (P_0 = undeformed position, then the static shapes of
    Delta and the modes of eta) and Jt[a, b] = int rho P_a P_b^T dA:
    T_m = m/2 |O'|^2 + O'.(R' c + R c') + 1/2 tr(R' J R'^T) + tr(R'^T R H) + 1/2 xi'^T M_xi xi'.

    Parameters
    ----------
    system : System
    membrane : MembraneBasis
        Shapes and their mass invariants (:mod:`tmfem.models.com.membrane_modes`).
    layout : ZetaLayout
    q, zeta, eta : SX
        Bar coordinates, dependent coordinates (Delta, gamma) and membrane coordinates.
    ddt : callable
        ``ddt(expr)`` is the time derivative of ``expr`` (a casadi directional derivative).
    """
    nd = layout.n_delta
    nP = membrane.shapes.shape[0]
    _, _, B = bars_sx(system, q)
    O = B[-1]
    Od = ddt(O)
    R = rotation_ef_sx(zeta[nd:])
    Rd = ca.reshape(ddt(ca.vec(R)), 3, 3)
    xb = ca.vertcat(1.0, zeta[:nd], eta)
    xbd = ca.vertcat(0.0, ddt(zeta[:nd]), ddt(eta))
    Jflat = ca.DM(membrane.Jt.reshape(nP * nP, 9).T)           # row-major 3x3 entries
    J = ca.reshape(ca.mtimes(Jflat, ca.kron(xb, xb)), 3, 3).T
    H = ca.reshape(ca.mtimes(Jflat, ca.kron(xbd, xb)), 3, 3).T   # int r_f' r_f^T
    first = ca.DM(membrane.first.T)                              # (3, nP)
    c = ca.mtimes(first, xb)
    cd = ca.mtimes(first, xbd)
    Mxi = ca.DM(np.trace(membrane.Jt, axis1=2, axis2=3))
    T = 0.5 * membrane.mass * ca.dot(Od, Od) + ca.dot(Od, ca.mtimes(Rd, c) + ca.mtimes(R, cd))
    T += 0.5 * ca.trace(ca.mtimes(ca.mtimes(Rd, J), Rd.T))
    T += ca.trace(ca.mtimes(ca.mtimes(Rd.T, R), H))
    T += 0.5 * ca.dot(xbd, ca.mtimes(Mxi, xbd))
    return T


def membrane_potential_sx(membrane, layout, zeta, eta, *, prestress_scale: float, delta0):
    """Membrane strain energy U_m = 1/2 Delta^T S Delta + 1/2 sum omega_i^2 eta_i^2 (eqs.
    5.4-5.6 for static shapes and fixed-corner modes, which are K-orthogonal), plus
    (s - 1) (S Delta_0)^T Delta when the designed prestress is scaled by s (the corner forces
    at the design Delta_0 become s S Delta_0, the stiffness S is unchanged; docs/guides/com.md)."""
    d = zeta[: layout.n_delta]
    U = 0.5 * ca.dot(d, ca.mtimes(ca.DM(membrane.S), d))
    if prestress_scale != 1.0:
        U += (prestress_scale - 1.0) * ca.dot(ca.DM(membrane.S @ np.asarray(delta0)), d)
    if membrane.K:
        U += 0.5 * ca.dot(eta, ca.DM(membrane.omega**2) * eta)
    return U


def tendon_energy_sx(system, k, q):
    """Tendon lengths |d| and the u-independent part sum k |d|^2 / 2 of U_td (eq. 3.6 with
    the fixed spring constants k of eq. 3.9); the part -sum k |d| u gives B(x) u of eq.
    5.19 and sum k u^2 / 2 is a constant."""
    L = tendon_lengths_sx(system, q)
    return L, 0.5 * ca.dot(ca.DM(k), L * L)


def lagrange_terms_sx(T, U, kL, x, xd, etad, *, nq: int, damping: float):
    """M, F, B of Lagrange's equations M x'' + F + B u = 0 in coordinates x = (q, eta, ...)
    (eq. 5.19 without the constraint forces; eq. 5.27 when x = z): M = T_x'x',
    F = T_x'x x' - T_x + U_x plus the modal damping c_m eta' of the Rayleigh function
    (eq. 5.13), B = -(k L)_x with kL the tendon forces' length part k |d|."""
    M = ca.hessian(T, xd)[0]
    F = ca.jtimes(ca.gradient(T, xd), x, xd) - ca.gradient(T, x) + ca.gradient(U, x)
    K = etad.numel()
    if K and damping:
        rest = x.numel() - nq - K
        F += ca.vertcat(ca.SX.zeros(nq), damping * etad, ca.SX.zeros(rest))
    return M, F, -ca.jacobian(kL, x).T
