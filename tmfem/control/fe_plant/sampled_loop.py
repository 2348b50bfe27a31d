"""The sampled closed loop of a finite-element plant under a linear controller, linearised
(docs/guides/fe-plant.md).

A deployment integrates the FE plant M a + C v + f_int(x; u) = 0 with Park's method at the
controller's sample time dt, the input held over each step (the residual of step n -> n+1 is
evaluated at u_n, :func:`tmfem.simulation.driver.simulate`), and the controller reads the
COM-state estimate z(x), z'(x, v) (:class:`tmfem.control.fe_plant.state_estimate.COMStateEstimator`).
About an equilibrium (x_e, u_e) that loop is linear:

    M a_{n+1} + C v_{n+1} + K x_{n+1} = B u_n,         B = -d f_int / d u,
    v_{n+1} = (10 x_{n+1} - 15 x_n + 6 x_{n-1} - x_{n-2}) / (6 dt),
    a_{n+1} = (10 v_{n+1} - 15 v_n + 6 v_{n-1} - v_{n-2}) / (6 dt)     (Park, eqs. 5.34-5.35),

so with c = 10 / (6 dt), R_x = -15 x_n + 6 x_{n-1} - x_{n-2} and R_v likewise,

    (c^2 M + c C + K) x_{n+1} = B u_n - (c M + C) R_x / (6 dt) - M R_v / (6 dt),

and a linear controller u_n = F_x x_n + F_v v_n + F_xi xi_n, xi_{n+1} = xi_n + C_xi x_n closes
it. The transition matrix of [x_n, x_{n-1}, x_{n-2}, v_n, v_{n-1}, v_{n-2}, xi_n] has spectral
radius < 1 exactly when the sampled loop, as the run integrates it, is stable about that
point: this separates a closed-loop instability from a failure of Park's Newton iteration.

:func:`lpv_start_loop` builds it for the scheduled state feedback of 8.3 at the start of the
2-3 LPV deployment (gain frozen at rho_r(0)).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError


@dataclass
class LinearizedFEPlant:
    """An FE plant linearised at (x, u): mass M, damping C (None: undamped), tangent K, input
    matrix B = -d f_int / d u (free dofs) and the estimate's Jacobian C_z = dz/dx (the COM
    coordinates z of the estimate; its rates are C_z v)."""

    M: np.ndarray
    C: np.ndarray | None
    K: np.ndarray
    B: np.ndarray
    C_z: np.ndarray


def linearize_fe_plant(plant, u, *, x=None, step_u: float = 1e-7, step_x: float = 1e-6) -> LinearizedFEPlant:
    """:class:`LinearizedFEPlant` of an :class:`~tmfem.control.fe_plant.state_estimate.FEStatePlant` at
    the free-dof state x (default its start) under the rest lengths u: K the plant's tangent,
    B and C_z by central differences (steps ``step_u`` [m] in u, ``step_x`` in x; both maps
    are smooth there, so second order: ~1e-12 relative)."""
    dyn = plant.dyn
    u = np.asarray(u, dtype=float)
    if u.shape != dyn.u0.shape:
        raise InputError(f"linearised FE plant: expected {dyn.u0.size} rest lengths, found shape {u.shape}")
    x = np.asarray(plant.x0 if x is None else x, dtype=float)
    zero = np.zeros_like(x)
    K, C, M = (m.toarray() for m in dyn.jacobians(x, zero, zero, 0.0, u))

    def force(uu):
        return dyn.residual(x, zero, zero, 0.0, uu)

    B = np.column_stack([-(force(u + step_u * e) - force(u - step_u * e)) / (2 * step_u)
                         for e in np.eye(u.size)])
    est = plant.estimator
    Cm = np.column_stack([(est.modal(x + step_x * e) - est.modal(x - step_x * e)) / (2 * step_x)
                          for e in np.eye(x.size)])
    dyn.model.set_tendon_lengths(dyn.u0)
    return LinearizedFEPlant(M=M, C=C if np.any(C) else None, K=K, B=B, C_z=np.linalg.solve(est.com.P, Cm))


def park_loop(lin: LinearizedFEPlant, *, F_x, F_v, dt: float, F_xi=None, C_xi=None) -> np.ndarray:
    """Transition matrix of the linear sampled loop (module docstring) over the state
    [x_n, x_{n-1}, x_{n-2}, v_n, v_{n-1}, v_{n-2}, xi_n]: ``F_x``, ``F_v`` (nu, n) the feedback
    on the FE positions and velocities, ``F_xi`` (nu, m) on the controller states xi with
    xi_{n+1} = xi_n + ``C_xi`` x_n (m, n)."""
    if not (np.isfinite(dt) and dt > 0):
        raise InputError(f"sampled loop: expected dt > 0, found {dt!r}")
    n, nu = lin.K.shape[0], lin.B.shape[1]
    F_x, F_v = np.asarray(F_x, dtype=float), np.asarray(F_v, dtype=float)
    if F_x.shape != (nu, n) or F_v.shape != (nu, n):
        raise InputError(f"sampled loop: expected feedback matrices of shape {(nu, n)}, found "
                         f"{F_x.shape} and {F_v.shape}")
    m = 0 if F_xi is None else np.asarray(F_xi).shape[1]
    c = 10.0 / (6.0 * dt)
    Cd = np.zeros_like(lin.M) if lin.C is None else lin.C
    Si = np.linalg.inv(c * c * lin.M + c * Cd + lin.K)
    SB = Si @ lin.B
    Px = Si @ (c * lin.M + Cd) / (6.0 * dt)          # acts on R_x
    Pv = Si @ lin.M / (6.0 * dt)                     # acts on R_v
    N = 6 * n + m
    A = np.zeros((N, N))
    blk = [slice(k * n, (k + 1) * n) for k in range(6)]
    X0, X1, X2, V0, V1, V2 = blk
    rows = [(X0, SB @ F_x + 15 * Px), (X1, -6 * Px), (X2, Px), (V0, SB @ F_v + 15 * Pv), (V1, -6 * Pv), (V2, Pv)]
    if m:
        XI = slice(6 * n, N)
        rows.append((XI, SB @ np.asarray(F_xi, dtype=float)))
        A[XI, X0] = np.asarray(C_xi, dtype=float)
        A[XI, XI] = np.eye(m)
    I = np.eye(n)
    for col, b in rows:
        A[X0, col] = b
        A[V0, col] = c * b                            # v_{n+1} = c x_{n+1} + R_x / (6 dt)
    A[V0, X0] += -15 * I / (6 * dt)
    A[V0, X1] += 6 * I / (6 * dt)
    A[V0, X2] += -I / (6 * dt)
    A[X1, X0] = I
    A[X2, X1] = I
    A[V1, V0] = I
    A[V2, V1] = I
    return A


def dominant_eigenvalues(A: np.ndarray, dt: float, k: int = 6) -> list:
    """The ``k`` eigenvalues of largest modulus of a transition matrix at sample time dt:
    (modulus, frequency [Hz] of its angle, aliased into [0, 1 / (2 dt)]), largest first."""
    lam = np.linalg.eigvals(A)
    idx = np.argsort(-np.abs(lam))[:k]
    return [(float(abs(lam[i])), float(abs(np.angle(lam[i])) / (2 * np.pi * dt))) for i in idx]


def lpv_start_loop(dep, design, plant, *, dt: float) -> np.ndarray:
    """:func:`park_loop` of the LPV deployment ``dep`` (:class:`~tmfem.control.lpv.deployment.
    LPVDeployment`) on the FE ``plant`` at its start, under the state feedback of ``design``
    (:class:`~tmfem.control.lpv.controller.LPVController`) with the gain frozen at rho_r(0):
    u = u_e + K_x (x_z - x_e) + K_xi xi, x_z = [q, v, q', v'] from the linearised estimate
    (v = T_veta eta, eq. 5.17) and xi' = q_d - q advanced by forward Euler."""
    pl = dep.plant
    lin = linearize_fe_plant(plant, dep.packaged().rest_lengths)
    nq = dep.model.nq
    Cp = np.vstack([lin.C_z[:nq], dep.T_veta @ lin.C_z[nq:]])       # positions part of x_z
    G = design.gain(dep.reference_rho(0.0))
    K_x, K_xi = G[:, :pl.nx], G[:, pl.nx:]
    npos = Cp.shape[0]
    if 2 * npos != pl.nx:
        raise InputError(f"LPV start loop: expected {pl.nx // 2} position signals, found {npos}")
    return park_loop(lin, F_x=K_x[:, :npos] @ Cp, F_v=K_x[:, npos:] @ Cp, F_xi=K_xi,
                     C_xi=-dt * lin.C_z[:nq], dt=dt)
