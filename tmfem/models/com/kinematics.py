"""Kinematics of the rigid bars and of the floating frame in casadi form (eqs. 3.1-3.3).

Everything here builds casadi SX expressions so that the control-oriented model can be
differentiated exactly (automatic differentiation, no finite differences). The layout of
q follows :attr:`tmfem.system.System.q_names` (eqs. 3.1-3.2); node order follows
:attr:`tmfem.system.System.node_labels`.
"""
from __future__ import annotations

import casadi as ca

from tmfem.system.coordinates import q_index


def bar_direction_sx(theta, psi):
    """Unit vector (3,) of a bar with declination theta and azimuth psi (Fig. 3.1)."""
    return ca.vertcat(ca.sin(theta) * ca.cos(psi), ca.sin(theta) * ca.sin(psi), ca.cos(theta))


def bars_sx(system, q):
    """Lower ends A, unit directions e and upper ends B of every bar, as lists over
    (i, j) in stage-major order (the order of :attr:`System.bar_connectivity`).

    Parameters
    ----------
    system : System
    q : casadi SX (nq,)

    Returns
    -------
    A, e, B : list of SX (3,)
    """
    M, N = system.M, system.N
    xyz, ith, ips = q_index(M, N)
    A, e, B = [], [], []
    for i in range(M):
        for j in range(N):
            if i == 0:
                a = ca.SX(ca.DM(system.base[:, j]))
            else:
                a = ca.vertcat(*[q[int(k)] for k in xyz[:, i, j]])
            th, ps = q[int(ith[i, j])], q[int(ips[i, j])]
            d = bar_direction_sx(th, ps)
            A.append(a)
            e.append(d)
            B.append(a + float(system.l[i, j]) * d)
    return A, e, B


def nodes_sx(system, q):
    """Coordinates of all labelled nodes (SX 3 x n_nodes), in ``system.node_labels`` order."""
    A, e, B = bars_sx(system, q)
    cols = A + B
    if system.deployable:
        N = system.N
        cols += [A[j] + system.k_H * (B[j] - A[j]) for j in range(N)]
    return ca.horzcat(*cols)


def tendon_lengths_sx(system, q):
    """Tendon lengths |d| (SX n_t) in ``system.tendons`` order."""
    X = nodes_sx(system, q)
    c = system.tendon_connectivity
    L = [ca.norm_2(X[:, int(c[1, k])] - X[:, int(c[0, k])]) for k in range(c.shape[1])]
    return ca.vertcat(*L)


def bar_kinetic_energy_sx(system, q, qdot):
    """Kinetic energy of the rigid slender bars (eqs. 5.9-5.11).

    For a bar of mass m and length l with lower end A and unit direction e (spin about
    the bar axis ignored, assumption b of 5.2):
    T = m/2 |A'|^2 + m l/2 A'.e' + m l^2/6 |e'|^2, with |e'|^2 = theta'^2 + psi'^2 sin^2 theta;
    this is eq. 5.10-5.11 written with vectors (A' = 0 for the first stage, eq. 5.9).
    """
    A, e, _ = bars_sx(system, q)
    T = 0
    for k, (a, d) in enumerate(zip(A, e)):
        i, j = divmod(k, system.N)
        l = float(system.l[i, j])
        m = system.bar.mass(l)
        dd = ca.jtimes(d, q, qdot)
        T += m * l**2 / 6.0 * ca.dot(dd, dd)
        if i > 0:
            da = ca.jtimes(a, q, qdot)
            T += 0.5 * m * ca.dot(da, da) + 0.5 * m * l * ca.dot(da, dd)
    return T


def rotation_ef_sx(g):
    """Rotation matrix R^ef of the 3-2-1 Euler angles (gamma_1, gamma_2, gamma_3), eq. 3.3:
    R^ef = Rz(gamma_1) Ry(gamma_2) Rx(gamma_3); columns are the O_f axes in O-xyz. The numeric
    counterpart is :func:`tmfem.system.geometry.rotation_ef`."""
    c1, s1 = ca.cos(g[0]), ca.sin(g[0])
    c2, s2 = ca.cos(g[1]), ca.sin(g[1])
    c3, s3 = ca.cos(g[2]), ca.sin(g[2])
    return ca.vertcat(
        ca.horzcat(c1 * c2, c1 * s2 * s3 - c3 * s1, c1 * c3 * s2 + s1 * s3),
        ca.horzcat(c2 * s1, c1 * c3 + s1 * s2 * s3, c3 * s1 * s2 - c1 * s3),
        ca.horzcat(-s2, c2 * s3, c2 * c3))
