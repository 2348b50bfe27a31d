"""The layout of the generalised coordinates q of an M-N system (eqs. 3.1-3.2), in one place.

Stage 1 bars have their lower ends fixed at the base and contribute (theta_1j, psi_1j); the
bars of stages i >= 2 contribute (x_ij, y_ij, z_ij, theta_ij, psi_ij) of their lower end A_ij
and their direction:

    q = [theta_11, psi_11, ..., theta_1N, psi_1N, x_21, y_21, z_21, theta_21, psi_21, ...].
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np


def q_size(M: int, N: int) -> int:
    """Number of generalised coordinates, 2 N + 5 N (M - 1)."""
    return 2 * N + 5 * N * (M - 1)


def q_stages(n_q: int, N: int) -> int:
    """Number of stages M of a system with n_q coordinates and N bars per stage (the inverse of
    :func:`q_size`; a count that fits no M gives the nearest smaller one, which the system's
    own check of len(q) then refuses)."""
    return 1 + (int(n_q) - 2 * N) // (5 * N)


def q_index(M: int, N: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Indices into q of (x, y, z) of A_ij (3, M, N; -1 for stage 1), theta_ij and psi_ij
    (M, N each); copies of the layout computed once per (M, N), which a caller may change."""
    return tuple(a.copy() for a in _q_index(int(M), int(N)))


@lru_cache(maxsize=None)
def _q_index(M: int, N: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    xyz = -np.ones((3, M, N), dtype=int)
    th = np.empty((M, N), dtype=int)
    ps = np.empty((M, N), dtype=int)
    j = np.arange(N)
    th[0], ps[0] = 2 * j, 2 * j + 1
    for i in range(1, M):
        off = 2 * N + 5 * N * (i - 1) + 5 * j
        xyz[:, i, :] = off[None, :] + np.arange(3)[:, None]
        th[i], ps[i] = off + 3, off + 4
    return xyz, th, ps


def split_q(q, base) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lower ends A (3, M, N), declinations theta (M, N) and azimuths psi (M, N) of q, with
    the stage-1 lower ends ``base`` (3, N)."""
    q = np.asarray(q, dtype=float)
    N = base.shape[1]
    M = q_stages(q.size, N)
    xyz, th, ps = q_index(M, N)
    A = np.where(xyz >= 0, q[np.maximum(xyz, 0)], 0.0)
    A[:, 0, :] = base
    return A, q[th], q[ps]


def join_q(A, theta, psi) -> np.ndarray:
    """q of the lower ends A (3, M, N) and the angles theta, psi (M, N) (stage-1 lower ends are
    not coordinates)."""
    M, N = np.shape(theta)
    xyz, th, ps = q_index(M, N)
    q = np.empty(q_size(M, N))
    q[th], q[ps] = theta, psi
    stages = xyz >= 0
    q[xyz[stages]] = np.asarray(A)[stages]
    return q
