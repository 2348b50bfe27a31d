"""The DAE of the control-oriented model (eq. 5.19) evaluated numerically, and the coordinate
partitioning of eqs. 5.23-5.28 done numerically on it: an evaluation path independent of the
symbolic elimination of :mod:`tmfem.models.com.graphs`, used to check it (tests, benchmark)
and by controllers that need the DAE's own terms (:mod:`tmfem.control.deployment.adaptive`).

zeta comes from Newton on Phi (:meth:`ControlOrientedModel.zeta`), the DAE matrices M, F, B
and the constraint Jacobians from the model's ``graphs.dae`` and ``graphs.constraints``.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError


def _constrained_state(model, z, zd, zeta):
    """At (z, z', zeta) (modal coordinates): Phi_zeta, Phi_q, zeta_q = -Phi_zeta^-1 Phi_q
    (eq. 5.23), Phi_zeta^-1, the constraint velocity term gamma = (Phi_x x')_x x' with
    zeta' = zeta_q q' (eq. 5.24), x = [z, zeta], x' and the DAE matrices M, F, B (eq. 5.19)."""
    nq = model.nq
    con = model.graphs.constraints
    q, qd = z[:nq], zd[:nq]
    _, Pz, Pq, _ = (np.asarray(a) for a in con(q, zeta, qd, np.zeros(model.layout.n)))
    lu = np.linalg.solve(Pz, np.hstack([Pq, np.eye(Pz.shape[0])]))
    zq = -lu[:, :nq]
    zetad = zq @ qd
    gamma = np.asarray(con(q, zeta, qd, zetad)[3]).ravel()
    x = np.concatenate([z, zeta])
    xd = np.concatenate([zd, zetad])
    M, F, B = (np.asarray(a) for a in model.graphs.dae(x, xd))
    return {"Phi_zeta": Pz, "Phi_q": Pq, "zeta_q": zq, "Phi_zeta_inv": lu[:, nq:],
            "gamma": gamma, "x": x, "xd": xd, "M": M, "F": F.ravel(), "B": B}


def dae_terms(model, z, zd, zeta=None) -> dict:
    """The DAE of eq. 5.19 at x = [q, eta, zeta], x' = T_z z' (modal coordinates).

    Parameters
    ----------
    model : ControlOrientedModel
        In the ``"partitioned"`` formulation (the substituted one has no DAE).
    z, zd : ndarray (nz,)
        Modal coordinates z = [q, eta] and their rates.
    zeta : ndarray, optional
        Dependent coordinates; default zeta(q) by Newton on Phi (eq. 3.5).

    Returns
    -------
    dict
        ``x``, ``xd``; ``M`` = M(x), ``F`` = F(x, x'), ``B`` = B(x) of eq. 5.19; ``Phi_x``;
        ``gamma`` = (Phi_x x')_x x', the velocity term of the constraint accelerations
        (Phi_x x'' + gamma = 0); ``T_z`` of eq. 5.25 (x' = T_z z', T_z^T Phi_x^T = 0).
    """
    if model.formulation != "partitioned":
        raise InputError(f"dae_terms: expected formulation='partitioned', found "
                         f"{model.formulation!r}")
    nq, K = model.nq, model.K
    z = np.asarray(z, dtype=float)
    zd = np.asarray(zd, dtype=float)
    zeta = model.zeta(z[:nq]) if zeta is None else np.asarray(zeta, dtype=float)
    s = _constrained_state(model, z, zd, zeta)
    nx = s["x"].size
    Phi_x = np.zeros((model.layout.n, nx))
    Phi_x[:, :nq] = s["Phi_q"]
    Phi_x[:, nq + K:] = s["Phi_zeta"]
    Tz = np.zeros((nx, nq + K))
    Tz[:nq + K] = np.eye(nq + K)
    Tz[nq + K:, :nq] = s["zeta_q"]
    return {k: s[k] for k in ("x", "xd", "M", "F", "B")} | {"Phi_x": Phi_x, "gamma": s["gamma"],
                                                           "T_z": Tz}


def _partitioned_numeric(model, z, zd, zeta):
    """M_hat, F_hat, B_hat (modal coordinates) by eqs. 5.23-5.28 evaluated numerically from
    the DAE matrices M, F, B (eq. 5.19) and the constraint Jacobians (AD):
    zeta_q = -Phi_zeta^-1 Phi_q, zeta' = zeta_q q', g = -Phi_zeta^-1 (Phi_x x')_x x', then
    M_hat = T_z^T M T_z, F_hat = T_z^T (F + M G), B_hat = T_z^T B without forming T_z."""
    nq, nz = model.nq, model.nz
    s = _constrained_state(model, z, zd, zeta)
    M, F, B, zq = s["M"], s["F"], s["B"], s["zeta_q"]
    g = -s["Phi_zeta_inv"] @ s["gamma"]
    # T_z^T A T_z without forming T_z: rows/cols of zeta map onto q through zeta_q
    Mzz, Mzc, Mcc = M[:nz, :nz], M[:nz, nz:], M[nz:, nz:]
    Mh = Mzz.copy()
    Mh[:, :nq] += Mzc @ zq
    Mh[:nq, :] += (Mzc @ zq).T
    Mh[:nq, :nq] += zq.T @ Mcc @ zq
    FG = F + M[:, nz:] @ g
    Fh = FG[:nz].copy()
    Fh[:nq] += zq.T @ FG[nz:]
    Bh = B[:nz].copy()
    Bh[:nq] += zq.T @ B[nz:]
    return Mh, Fh, Bh


def matrices_newton(model, z, zd):
    """M_hat, F_hat, B_hat of eq. 5.28 in the model's coordinates with zeta from Newton on
    Phi: the partitioning of eqs. 5.23-5.28 evaluated numerically
    (:func:`_partitioned_numeric`), or the substituted formulation's graph with that zeta --
    a check of :meth:`ControlOrientedModel.matrices` (the closed-form zeta inside one graph)."""
    zm, zdm = model.P @ np.asarray(z, dtype=float), model.P @ np.asarray(zd, dtype=float)
    zeta = model.zeta(zm[: model.nq])
    if model.formulation == "partitioned":
        Mh, Fh, Bh = _partitioned_numeric(model, zm, zdm, zeta)
    else:
        Mh, Fh, Bh = (np.asarray(a) for a in model.graphs.terms(zm, zdm, zeta))
    P = model.P
    return P.T @ Mh @ P, P.T @ Fh.ravel(), P.T @ Bh
