"""Exact derivative of the ch. 3 equilibrium design along a change of the configuration.

The design (:func:`tmfem.equilibrium.design.design_equilibrium`) maps the configuration to
rest lengths in four steps; each is differentiated here in forward mode (one direction, the
rate of an angle variable), analytically, without a difference step:

1. **Nodes** (eqs. 3.19-3.20): A_ij and B_ij = A_ij + l_ij u(theta_ij, psi_ij) with
   u = (sin theta cos psi, sin theta sin psi, cos theta). Along the rates (theta', psi') of
   the bars' angles and the rate A_1' of the stage-1 base, X' = J q' + A_1' on A_1j, B_1j
   (J = dX/dq, :func:`tmfem.equilibrium.general.node_jacobian`), and the rate of J itself
   has the second derivatives of u in its angle columns (:func:`node_rates`).
2. **Corner displacements** (eq. 3.5, B_Mi - B_MN = R^ef(gamma) (P_i + Delta_i)): with
   y = (gamma, Delta_free) and G_y the Jacobian of the right-hand side, y' = G_y^-1 X_c'
   (X_c the corner differences), and the membrane columns of A(q) (eq. 3.11),
   Y_q = G_y^-1 X_q, move by Y_q' = G_y^-1 (X_q' - G_y' Y_q), where G_y' needs the second
   derivatives of R^ef (:func:`euler_R_second_derivatives`).
3. **Membrane forces**: on the fixed membrane mesh the plane-stress solve's stiffness does not
   depend on the angles; the corner forces F (the multipliers mu of the corner coupling C,
   K x = C^T mu, C x = Delta; C the corner rows of the identity for the point attachment)
   move by the bordered solve [[K_t, C^T], [C, 0]] (x', -F') = (0, Delta') with the law's
   tangent K_t at the design's membrane state (the constant K of the linear law ``"svk"``;
   the consistent tangent of the tension-field law, exact where no element changes between
   taut, wrinkled and slack).
4. **Tendon forces** (eq. 3.16): the design takes the least-squares solution of
   A_T T = b, b = -A_F f (f the free corner forces), which is the null vector of
   A(q) = [A_F A_T] normalised by the membrane's own forces f (the last column block is
   fixed by the membrane solve, not by a norm). With A_T of full column rank (no
   self-stress of the tendon network alone: 2N x N for a 1-N system, square for M-N),
   the normal equations A_T^T A_T T = A_T^T b differentiate to

       T' = (A_T^T A_T)^-1 [A_T^T (b' - A_T' T) + A_T'^T (b - A_T T)],

   exact also where eq. 3.16 is met only in the least-squares sense (a 1-N base radius r_1
   given to printed precision, residual 1e-5). Then the rest lengths (eqs. 3.8-3.9)
   r = EA L / (T + EA): r' = EA (L' (T + EA) - L T') / (T + EA)^2.

Limits: a design whose tendon network alone has self-stress (its forces picked by a linear
programme, not smooth in the configuration) is refused with InputError.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from tmfem.equilibrium.general import (corner_constraint_jacobian, corner_array, euler_R_derivatives, free_components,
                                       node_jacobian)
from tmfem.errors import InputError
from tmfem.system.coordinates import q_index
from tmfem.system.geometry import free_corner_components


@dataclass(frozen=True)
class DesignRate:
    """Rates of the design along one direction of the configuration.

    nodes : (3, n_nodes) X'; corner_delta : (3, N) Delta' (O_f); corner_forces : (2, N) F';
    tendon_forces, tendon_lengths, rest_lengths : (n_tendons,) T', L', r'.
    """

    nodes: np.ndarray
    corner_delta: np.ndarray
    corner_forces: np.ndarray
    tendon_forces: np.ndarray
    tendon_lengths: np.ndarray
    rest_lengths: np.ndarray


def _bar_direction_second_derivatives(theta, psi) -> tuple:
    """Second derivatives u_tt, u_tp, u_pp (3, ...) of the bar direction u(theta, psi)."""
    st, ct, sp_, cp = np.sin(theta), np.cos(theta), np.sin(psi), np.cos(psi)
    zero = np.zeros_like(st)
    return (np.array([-st * cp, -st * sp_, -ct]), np.array([-ct * sp_, ct * cp, zero]),
            np.array([-st * cp, -st * sp_, zero]))


def node_rates(system, *, dq: np.ndarray, dbase: np.ndarray) -> tuple:
    """J = dX/dq (3, n_nodes, n_q) of ``system`` at its q, and X' (3, n_nodes) and J' along the
    rate dq of q and dbase (3, N) of the stage-1 base A_1j (eqs. 3.19-3.20; module docstring)."""
    M, N = system.M, system.N
    J = node_jacobian(system)
    dX = np.einsum("cnq,q->cn", J, dq)
    _, theta, psi = system.split_q()
    _, th, ps = q_index(M, N)
    dth, dps = dq[th], dq[ps]                             # (M, N)
    u_tt, u_tp, u_pp = _bar_direction_second_derivatives(theta, psi)
    l = system.l
    dJB = np.zeros((3, M, N, dq.size))
    ii, jj = np.meshgrid(np.arange(M), np.arange(N), indexing="ij")
    for c in range(3):
        dJB[c, ii, jj, th] = l * (u_tt[c] * dth + u_tp[c] * dps)
        dJB[c, ii, jj, ps] = l * (u_tp[c] * dth + u_pp[c] * dps)
    nb = M * N
    dJ = np.zeros_like(J)
    dJ[:, nb:2 * nb] = dJB.reshape(3, nb, -1)
    dX[:, :N] += dbase                                    # A_1j
    dX[:, nb:nb + N] += dbase                             # B_1j = A_1j + l u
    if system.deployable:                                 # H_1j = A_1j + k_H (B_1j - A_1j)
        dJ[:, 2 * nb:] = system.k_H * dJB[:, 0]
        dX[:, 2 * nb:] += dbase
    return J, dX, dJ


def euler_R_second_derivatives(gamma) -> np.ndarray:
    """d^2 R^ef / dgamma_k dgamma_l of R^ef = Rz(gamma_1) Ry(gamma_2) Rx(gamma_3) (eq. 3.3),
    shape (3, 3, 3, 3) with k, l last."""
    g1, g2, g3 = gamma
    c1, s1, c2, s2, c3, s3 = np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2), np.cos(g3), np.sin(g3)
    F = [np.array([[c1, -s1, 0], [s1, c1, 0], [0, 0, 1]]),
         np.array([[c2, 0, s2], [0, 1, 0], [-s2, 0, c2]]),
         np.array([[1, 0, 0], [0, c3, -s3], [0, s3, c3]])]
    dF = [np.array([[-s1, -c1, 0], [c1, -s1, 0], [0, 0, 0]]),
          np.array([[-s2, 0, c2], [0, 0, 0], [-c2, 0, -s2]]),
          np.array([[0, 0, 0], [0, -s3, -c3], [0, c3, -s3]])]
    ddF = [np.array([[-c1, s1, 0], [-s1, -c1, 0], [0, 0, 0]]),
           np.array([[-c2, 0, -s2], [0, 0, 0], [s2, 0, -c2]]),
           np.array([[0, 0, 0], [0, -c3, s3], [0, -s3, -c3]])]
    out = np.zeros((3, 3, 3, 3))
    for k in range(3):
        for m in range(3):
            factors = [ddF[i] if i == k == m else dF[i] if i in (k, m) else F[i] for i in range(3)]
            out[:, :, k, m] = factors[0] @ factors[1] @ factors[2]
    return out


def _corner_rates(design, J: np.ndarray, dX: np.ndarray, dJ: np.ndarray) -> tuple:
    """Delta_free' (3N-6,) and A_F' (n_q, 3N-6) of the corner constraints eq. 3.5 (module
    docstring, step 2)."""
    system, st = design.system, design.matrix.state
    M, N = system.M, system.N
    P = np.vstack([system.membrane_corners, np.zeros((1, N))])
    b = (2 * M - 1) * N                                   # B_M1 in the node order
    Gy = corner_constraint_jacobian(st.gamma, st.free, P, N)

    def corner_differences(Z):                            # (3, N, ...) -> (3(N-1), ...), corner-major
        Zc = Z[:, b:b + N - 1] - Z[:, [b + N - 1]]
        return np.moveaxis(Zc, 0, 1).reshape(3 * (N - 1), *Z.shape[2:])

    Yq = np.linalg.solve(Gy, corner_differences(J))
    dy = np.linalg.solve(Gy, corner_differences(dX))
    dgamma, dfree = dy[:3], dy[3:]
    dR = euler_R_derivatives(st.gamma)
    dR_rate = np.einsum("abkl,l->abk", euler_R_second_derivatives(st.gamma), dgamma)
    Y = (P + corner_array(st.free, N))[:, :N - 1]
    dY = corner_array(dfree, N)[:, :N - 1]
    dG = np.zeros((3, N - 1, Gy.shape[1]))
    dG[:, :, :3] = np.einsum("abk,bi->aik", dR_rate, Y) + np.einsum("abk,bi->aik", dR, dY)
    R_rate = np.einsum("abl,l->ab", dR, dgamma)
    for k, (i, c) in enumerate(free_corner_components(N)):
        dG[:, i, 3 + k] = R_rate[:, c]
    dG = np.moveaxis(dG, 0, 1).reshape(3 * (N - 1), -1)
    dYq = np.linalg.solve(Gy, corner_differences(dJ) - dG @ Yq)
    return dfree, dYq[3:].T


def corner_force_rate(membrane, solution, ddelta: np.ndarray) -> np.ndarray:
    """F' (2, N) of the plane-stress ``membrane`` (:class:`tmfem.fem.plane_stress.PlaneStressMembrane`)
    at its ``solution`` for the corner displacement rate ddelta (2, N) (module docstring, step
    3; the coupling rows scaled to the stiffness as in the membrane's own bordered solve)."""
    basis = membrane.basis
    x = np.zeros(basis.N)
    x[basis.nodal_dofs] = solution.u
    K = membrane.tangent(x)
    C = membrane.coupling
    s = float(np.abs(K.diagonal()).mean())
    A = sp.bmat([[K, s * C.T], [s * C, None]], format="csc")
    rhs = np.concatenate([np.zeros(basis.N), s * np.asarray(ddelta, dtype=float).T.ravel()])
    y = membrane.backend.factorize(A)(rhs)
    return (-s * y[basis.N:]).reshape(-1, 2).T


def design_rate(design, *, dq: np.ndarray, dbase: np.ndarray) -> DesignRate:
    """The exact rate of the ch. 3 design ``design`` (an :class:`EquilibriumDesign` of
    :func:`tmfem.equilibrium.design.design_equilibrium`) along the configuration rate dq
    (n_q,) and stage-1 base rate dbase (3, N) (module docstring).

    Raises
    ------
    InputError
        the tendon network alone has self-stress.
    """
    system, E = design.system, design.matrix
    if design.self_stress_dim:
        raise InputError(f"design rates: expected tendon forces fixed by eq. 3.16, found a tendon network "
                         f"with {design.self_stress_dim} self-stress states of its own (the design picks "
                         f"among them by a linear programme, not smoothly in the configuration)")
    J, dX, dJ = node_rates(system, dq=np.asarray(dq, dtype=float), dbase=np.asarray(dbase, dtype=float))
    # step 1: tendon columns of A(q) and tendon lengths
    c = system.tendon_connectivity
    D = system.tendon_vectors()
    L = np.linalg.norm(D, axis=0)
    n = D / L
    dD = dX[:, c[1]] - dX[:, c[0]]
    dL = np.einsum("ck,ck->k", n, dD)
    dn = (dD - n * dL) / L
    JD, dJD = J[:, c[1]] - J[:, c[0]], dJ[:, c[1]] - dJ[:, c[0]]
    dAT = np.einsum("ck,ckq->qk", dn, JD) + np.einsum("ck,ckq->qk", n, dJD)
    # step 2: corner displacements and membrane columns
    dfree, dAF = _corner_rates(design, J, dX, dJ)
    ddelta = corner_array(dfree, system.N)
    # step 3: membrane corner forces
    dF = corner_force_rate(design.membrane_model, design.membrane, ddelta[:2])
    f, df = free_components(design.corner_forces), free_components(dF)
    # step 4: tendon forces and rest lengths
    AT, AF, T = E.A_T, E.A_F, design.tendon_forces
    b = -AF @ f
    db = -(dAF @ f + AF @ df)
    dT = np.linalg.solve(AT.T @ AT, AT.T @ (db - dAT @ T) + dAT.T @ (b - AT @ T))
    EA = system.tendon_EA
    dr = EA * (dL * (T + EA) - L * dT) / (T + EA) ** 2
    return DesignRate(nodes=dX, corner_delta=ddelta, corner_forces=dF, tendon_forces=dT,
                      tendon_lengths=dL, rest_lengths=dr)
