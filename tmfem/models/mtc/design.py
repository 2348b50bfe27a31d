"""The rest-length rule ``"mtc"`` of the finite-element models (:func:`consistent_rest_lengths`:
an independent formulation of the ch. 3 design (3.2) on the MTC model's own nonlinear
membrane; the tests compare it with the linear design). The other rules are in
:mod:`tmfem.models.fe.rest_lengths`.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from tmfem.errors import SlackMembrane, SlackTendon
from tmfem.fem.attachment import coupling_matrix
from tmfem.fem.truss import green_rest_length, linear_rest_length
from tmfem.solvers.newton import newton
from tmfem.system.topology import label


def consistent_rest_lengths(model, *, tol: float = 1e-10) -> dict:
    """Rest lengths for which the design configuration is an equilibrium of this model.

    An independent formulation of the design of 3.2: (1) the membrane alone, its corners
    held at the design bar tops B_Mj, is solved with the nonlinear membrane element;
    (2) the forces it exerts on the corners and the bar and tendon forces along the
    design member directions must balance at every free system node (A_ij, i >= 2, and
    B_ij) — a linear system for the member forces, solved by least squares; a residual
    above round-off means the design geometry is not an equilibrium; (3) the rest
    lengths follow from the truss law (:func:`green_rest_length`).
    With ``attachment="distributed"`` step (1) holds the weighted patch centroids
    sum_i w_i x_i (the attachment of :func:`tmfem.fem.attachment.attachment_weights`) at
    the bar tops by Lagrange multipliers, which are the corner forces.
    """
    topo = model.topology
    x = model.initial_positions("design")
    nm = topo.n_mesh
    corners = topo.mesh.corners
    if topo.attachment == "distributed":
        Fc = _distributed_corner_forces(model, x[:, :nm].T.ravel().copy(), tol=tol)
        return _consistent_from_corner_forces(model, Fc)
    freem = np.ones(3 * nm, dtype=bool)
    for c in corners:
        freem[3 * c:3 * c + 3] = False
    xm = x[:, :nm].T.ravel().copy()

    def residual(u):
        return model.membrane.internal(u.reshape(-1, 3).T)
    # converged when the free residual is tol times the corner reactions (at the start,
    # the affine stretch onto the design corners, which they hardly change)
    f0, _ = residual(xm)
    res = newton(residual, xm, free=freem, tol=tol, scale=np.linalg.norm(f0[~freem]) + 1e-30,
                 max_iter=50, line_search=False, backend=model.backend)
    f, _ = residual(res.u)
    Fc = -f.reshape(-1, 3)[corners].T                  # force of the membrane on corner j (3, N)
    return _consistent_from_corner_forces(model, Fc)

def _distributed_corner_forces(model, xm: np.ndarray, *, tol: float) -> np.ndarray:
    """Forces (3, N) of the membrane on the bar tops with the patch centroids held at
    their design positions: Newton on the bordered system of (x, mu),
    [f(x) + s C^T mu, s (C x - C x_0)] = 0 with tangent [[K, s C^T], [s C, 0]]
    (C: the attachment coupling; the start ``xm`` satisfies C x = B_top already; s scales
    the multiplier to the stiffness). The force on bar top j is s mu_j."""
    nm = model.topology.n_mesh
    C = coupling_matrix(model.topology.weights, nm, 3)
    b = C @ xm
    f0, K0 = model.membrane.internal(xm.reshape(-1, 3).T)
    s = float(np.abs(K0.diagonal()).mean())
    lam0 = -np.linalg.solve((C @ C.T).toarray(), C @ f0)      # least-squares multipliers

    def residual(w):
        f, K = model.membrane.internal(w[:3 * nm].reshape(-1, 3).T)
        mu = w[3 * nm:]
        r = np.concatenate([f + s * (C.T @ mu), s * (C @ w[:3 * nm] - b)])
        return r, sp.bmat([[K, s * C.T], [s * C, None]], format="csr")

    w0 = np.concatenate([xm, lam0 / s])
    res = newton(residual, w0, tol=tol, scale=np.linalg.norm(lam0) + 1e-30, max_iter=50,
                 line_search=False, backend=model.backend)
    # f_int = -s C^T mu at the solution: s mu is the force of the membrane on the bar tops
    return (s * res.u[3 * nm:]).reshape(-1, 3).T

def _consistent_from_corner_forces(model, Fc: np.ndarray) -> dict:
    """Steps (2)-(3) of :func:`consistent_rest_lengths` for the corner forces Fc (3, N)."""
    sysm = model.system
    X = sysm.nodes()
    labels = sysm.node_labels
    fixed = {sysm.node_index(label("A", 1, j)) for j in range(1, sysm.N + 1)}
    rows = [i for i in range(len(labels)) if i not in fixed]
    row_of = {n: r for r, n in enumerate(rows)}
    bc = sysm.bar_connectivity
    tc = sysm.tendon_connectivity
    nb, nt = bc.shape[1], tc.shape[1]
    A = np.zeros((3 * len(rows), nb + nt))
    for m, (a, b) in enumerate(np.concatenate([bc, tc], axis=1).T):
        e = X[:, b] - X[:, a]
        e = e / np.linalg.norm(e)
        # tension t > 0 pulls node a towards b and node b towards a
        if a in row_of:
            A[3 * row_of[a]:3 * row_of[a] + 3, m] += e
        if b in row_of:
            A[3 * row_of[b]:3 * row_of[b] + 3, m] -= e
    top = [sysm.node_index(label("B", sysm.M, j)) for j in range(1, sysm.N + 1)]
    Xtop = X[:, top]
    rhs = np.zeros(3 * len(rows))
    for j, n in enumerate(top):
        rhs[3 * row_of[n]:3 * row_of[n] + 3] -= Fc[:, j]
    sol, *_ = np.linalg.lstsq(A, rhs, rcond=None)
    res = np.linalg.norm(A @ sol - rhs) / max(np.linalg.norm(rhs), 1e-30)
    s = np.linalg.svd(A, compute_uv=False)
    bar_force, T = sol[:nb], sol[nb:]
    L = sysm.tendon_lengths()
    out = {"tendon_force": T, "bar_force": bar_force, "corner_force": Fc,
           "equilibrium_residual": float(res), "rank_deficiency": int(np.sum(s < 1e-10 * s[0]))
           + max(0, A.shape[1] - A.shape[0]), "tendon_length": L}
    if np.any(T <= 0):
        bad = [sysm.tendons[i].name for i in np.flatnonzero(T <= 0)]
        raise SlackTendon(f"the design geometry needs non-positive tendon forces in {bad}: "
                          f"{T[T <= 0]} N (expected > 0)")
    outward = Xtop - Xtop.mean(axis=1, keepdims=True)
    pull = np.einsum("ij,ij->j", Fc, outward / np.linalg.norm(outward, axis=0))
    if np.any(pull >= 0):
        raise SlackMembrane(f"the membrane does not pull the corners inwards at the design "
                            f"(Delta <= 0, eq. 3.36): outward corner force components "
                            f"{np.round(pull, 6).tolist()} N, expected < 0")
    out["rest_lengths"] = green_rest_length(L, T, model.tendon_EA)
    out["rest_lengths_linear"] = linear_rest_length(L, T, model.tendon_EA)
    return out
