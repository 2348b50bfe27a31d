"""The generalized LPV plant of Figure 8.1 on a grid and the LMI of eq. 5.95.

The generalized plant (eq. 5.90)

    x' = A x + B1 w + B2 u,   p = C1 x + D11 w + D12 u

is built from a gridded plant by :func:`interconnection_8_1`; :func:`lmi_matrix` is the
bounded-real LMI of eqs. 5.95-5.96 at one point, shared by the synthesis and its
verification; :func:`state_scaling` the diagonal state scaling of the synthesis coordinates.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from tmfem.control.lpv.plant import GriddedLPV
from tmfem.errors import InputError


@dataclass
class GeneralizedLPV:
    """Generalised LPV plant (eq. 5.90) on a grid: x' = A x + B1 w + B2 u, p = C1 x + D11 w + D12 u.

    Arrays have shape ``grid_shape + (rows, cols)``; ``axes``, ``parameter_names`` and
    ``rate_bounds`` as in :class:`~tmfem.control.lpv.plant.GriddedLPV`.
    """

    axes: list
    parameter_names: list
    rate_bounds: np.ndarray
    A: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    C1: np.ndarray
    D11: np.ndarray
    D12: np.ndarray
    state_names: list = field(default_factory=list)

    @property
    def grid_shape(self) -> tuple:
        return tuple(np.size(a) for a in self.axes)

    @property
    def sizes(self) -> dict:
        return {"n_x": self.A.shape[-1], "n_w": self.B1.shape[-1], "n_u": self.B2.shape[-1],
                "n_p": self.C1.shape[-2]}

    def points(self):
        plant = self._as_lpv()
        return plant.points()

    def _as_lpv(self) -> GriddedLPV:
        n = self.A.shape[-1]
        return GriddedLPV(axes=self.axes, parameter_names=self.parameter_names,
                          A=self.A, B=self.B2, C=self.C1, D=self.D12, rate_bounds=self.rate_bounds,
                          state_names=[f"x{i}" for i in range(n)],
                          input_names=[f"u{i}" for i in range(self.B2.shape[-1])],
                          output_names=[f"p{i}" for i in range(self.C1.shape[-2])])

    def rate_vertices(self) -> np.ndarray:
        return self._as_lpv().rate_vertices()

    @classmethod
    def from_matrices(cls, *, axes, parameter_names, rate_bounds, A, B1, B2, C1, D11, D12):
        """From arrays (validated: finite, consistent sizes)."""
        arrs = {k: np.asarray(v, dtype=float) for k, v in
                dict(A=A, B1=B1, B2=B2, C1=C1, D11=D11, D12=D12).items()}
        shape = tuple(np.size(a) for a in axes)
        n, nw, nu, npp = (arrs["A"].shape[-1], arrs["B1"].shape[-1], arrs["B2"].shape[-1],
                          arrs["C1"].shape[-2])
        want = dict(A=(n, n), B1=(n, nw), B2=(n, nu), C1=(npp, n), D11=(npp, nw), D12=(npp, nu))
        for k, v in arrs.items():
            if v.shape != shape + want[k] or not np.all(np.isfinite(v)):
                raise InputError(f"generalised LPV plant: {k} expected shape {shape + want[k]} with "
                                 f"finite entries, found {v.shape}")
        rb = np.asarray(rate_bounds, dtype=float).reshape(len(shape), 2)
        return cls(axes=[np.atleast_1d(np.asarray(a, dtype=float)) for a in axes],
                   parameter_names=list(parameter_names), rate_bounds=rb, **arrs)


def interconnection_8_1(plant: GriddedLPV, *, tracked, W_e: float = 0.5, W_u: float = 0.05,
                        W_d: float = 0.001) -> GeneralizedLPV:
    """The interconnection of Figure 8.1 with the integral of the tracking error (eq. 5.98).

    Plant x_z' = A x_z + B (u + W_d n_d), q = T_qx x_z (``tracked``: the output names of q;
    their rows of C, eq. 5.18). States x = [x_z; e~_q], e~_q' = e_q = q_d - q (eq. 5.98);
    exogenous w = [q_d; n_d]; regulated p = [e_r; e_u] = [W_e e_q; W_u u]. Weights are
    scalar multiples of I (8.3: W_e = 0.5 I, W_u = 0.05 I, W_d = 0.001 I).
    """
    tracked = list(tracked)
    missing = [t for t in tracked if t not in plant.output_names]
    if missing or not tracked:
        raise InputError(f"interconnection: tracked outputs must be plant outputs, found unknown "
                         f"{missing or 'none given'}")
    for nm, v in (("W_e", W_e), ("W_u", W_u), ("W_d", W_d)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"interconnection: {nm} expected > 0, found {v!r}")
    rows = [plant.output_names.index(t) for t in tracked]
    if np.any(plant.D[..., rows, :] != 0):
        raise InputError("interconnection: tracked outputs must not depend on u directly (D rows nonzero)")
    T = plant.C[..., rows, :]
    shp = plant.grid_shape
    n, m, nq = plant.nx, plant.nu, len(rows)
    Z = lambda r, c: np.zeros(shp + (r, c))            # noqa: E731
    I = lambda k: np.broadcast_to(np.eye(k), shp + (k, k))   # noqa: E731
    A = np.concatenate([np.concatenate([plant.A, Z(n, nq)], -1),
                        np.concatenate([-T, Z(nq, nq)], -1)], -2)
    B1 = np.concatenate([np.concatenate([Z(n, nq), W_d * plant.B], -1),
                         np.concatenate([I(nq), Z(nq, m)], -1)], -2)
    B2 = np.concatenate([plant.B, Z(nq, m)], -2)
    C1 = np.concatenate([np.concatenate([-W_e * T, Z(nq, nq)], -1), Z(m, n + nq)], -2)
    D11 = np.concatenate([np.concatenate([W_e * I(nq), Z(nq, m)], -1), Z(m, nq + m)], -2)
    D12 = np.concatenate([Z(nq, m), W_u * I(m)], -2)
    g = GeneralizedLPV.from_matrices(axes=plant.axes, parameter_names=plant.parameter_names,
                                     rate_bounds=plant.rate_bounds, A=A, B1=B1, B2=B2, C1=C1,
                                     D11=D11, D12=D12)
    g.state_names = list(plant.state_names) + [f"int_e_{t}" for t in tracked]
    return g


def lmi_matrix(*, A, B1, B2, C1, D11, D12, P, Q, dP, gamma) -> np.ndarray:
    """The (symmetric) matrix of eq. 5.95 with H1, F of eq. 5.96 for numeric P, Q, dP, gamma."""
    nw, npp = B1.shape[1], C1.shape[0]
    APBQ = A @ P + B2 @ Q
    H1 = APBQ + APBQ.T - dP
    F = C1 @ P + D12 @ Q
    return np.block([[H1, B1, F.T], [B1.T, -gamma * np.eye(nw), D11.T], [F, D11, -gamma * np.eye(npp)]])


def state_scaling(A: np.ndarray) -> np.ndarray:
    """The diagonal T of the state scaling x = T x_s that balances A (LAPACK gebal, scaling
    only), as the vector of its diagonal.

    Shared by the synthesis (:mod:`tmfem.control.lpv.synthesis`), the pointwise bound and the
    Kalman gains of the output feedback, where angles, positions and membrane deflections must
    have comparable magnitudes.
    """
    _, (sca, _) = sla.matrix_balance(A, permute=False, separate=True)
    return sca
