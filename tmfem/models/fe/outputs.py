"""The measured outputs of a finite-element model (eqs. 3.1-3.3, 5.36-5.38): the bar coordinates q
recovered from the bar end positions and the membrane deflections w_k along z_f of the floating
frame of the current membrane corners, at material points of the membrane."""
from __future__ import annotations

import numpy as np

from tmfem.fem.membrane import point_matrix
from tmfem.system.coordinates import join_q
from tmfem.system.geometry import floating_frame, wrap_angle


def q_from_positions(system, X: np.ndarray) -> np.ndarray:
    """Generalised coordinates q (eqs. 3.1-3.2) of labelled node positions X (3, n_labels).

    theta_ij = arccos(d_z / |d|), psi_ij = atan2(d_y, d_x) of the bar vector d = B_ij - A_ij
    (3.2, Fig. 3.1); x, y, z of A_ij for i >= 2.
    """
    M, N = system.M, system.N
    n = M * N
    A = X[:, :n].reshape(3, M, N)
    d = X[:, n:2 * n].reshape(3, M, N) - A
    theta = np.arccos(d[2] / np.linalg.norm(d, axis=0))
    psi = wrap_angle(np.arctan2(d[1], d[0]))
    return join_q(A, theta, psi)


def to_floating(x: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Coordinates (3, n) of points ``x`` in the floating frame of ``corners`` (eq. 3.3)."""
    o, R = floating_frame(corners)
    return R.T @ (x - o[:, None])



class MeasuredOutputs:
    """y = [q, w_k] of node positions in the placement numbering of an FE model.

    Parameters
    ----------
    system : System
    topology : MTCTopology
        The placement (:mod:`tmfem.models.fe.topology`): ``system_node``, ``n_mesh``, ``mesh``.
    points : array (2, n) or list of (x_f, y_f), optional
        Material points of the membrane (reference coordinates in O_f); default
        ``system.monitor_points``.
    """

    def __init__(self, system, topology, points=None):
        self.system, self.topology = system, topology
        pts = system.monitor_points.T if points is None else np.reshape(points, (-1, 2))
        self.points = [tuple(map(float, p)) for p in pts]
        self._P = point_matrix(topology.mesh.to_skfem(), np.asarray(self.points).T) \
            if self.points else None
        self.names = list(system.q_names) + [f"w_{i + 1}" for i in range(len(self.points))]

    def of(self, xf: np.ndarray) -> np.ndarray:
        """[q, w_k] of positions xf (3, n) in the placement numbering."""
        topo = self.topology
        q = q_from_positions(self.system, xf[:, topo.system_node])
        if self._P is None:
            return q
        xm = xf[:, :topo.n_mesh]
        w = to_floating((self._P @ xm.T).T, xm[:, topo.mesh.corners])[2]
        return np.concatenate([q, w])
