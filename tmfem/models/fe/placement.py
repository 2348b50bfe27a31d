"""Node positions in the placement numbering both finite-element models share
(:mod:`tmfem.models.fe.topology`: membrane mesh nodes, system nodes A_ij, B_ij (H_1j), tendon
internal nodes): independent and full positions, straight tendons, the start of the static
solve of 6.2, and a one-line note of a state for error messages."""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError
from tmfem.fem.truss import truss_internal
from tmfem.models.fe.topology import membrane_placement
from tmfem.system.topology import label


class Placement:
    """Mix-in of the finite-element models: positions in the placement numbering. The model
    provides ``system``, ``topology`` and ``tendons`` (a :class:`tmfem.fem.truss.TrussSet` on
    that numbering)."""

    def full(self, xr: np.ndarray) -> np.ndarray:
        """Full positions (3, n_nodes) from the independent ones (flat, 3 n_red)."""
        return (self.topology.T @ xr).reshape(-1, 3).T

    def reduce(self, x: np.ndarray) -> np.ndarray:
        """Independent positions (flat) of full positions (3, n_nodes)."""
        keep = self.topology.red_node >= 0
        return np.ascontiguousarray(x[:, keep].T).ravel()

    def with_straight_tendons(self, x: np.ndarray) -> np.ndarray:
        """x (3, n_nodes) with every tendon's internal nodes on its chord (evenly spaced)."""
        topo = self.topology
        k = topo.tendon_elements
        if k == 1:
            return x
        c = self.system.tendon_connectivity
        a = x[:, topo.system_node[c[0]]]
        b = x[:, topo.system_node[c[1]]]
        s = np.arange(1, k) / k
        x[:, topo.tendon_internal] = a[:, :, None] + (b - a)[:, :, None] * s[None, None, :]
        return x

    def initial_positions(self, start: str = "undeformed") -> np.ndarray:
        """Start configuration (3, n_nodes) of the static solve.

        ``"undeformed"``: the unstressed flat membrane, centred in the plane of the design
        bar tops (its corners lie Delta inside the design corners); bars and lower nodes at the
        design; the top bars reach the membrane corners. ``"design"``: the design bar
        configuration with the membrane stretched affinely onto the design corners.
        """
        topo, sysm = self.topology, self.system
        x = np.zeros((3, topo.n_nodes))
        X = sysm.nodes()
        x[:, topo.system_node] = X
        Btop = X[:, [sysm.node_index(label("B", sysm.M, j)) for j in range(1, sysm.N + 1)]]
        if start not in ("undeformed", "design"):
            raise InputError(f"start: expected 'undeformed' or 'design', found {start!r}")
        x[:, :topo.n_mesh] = membrane_placement(sysm, topo.mesh, Btop,
                                                stretch_to_corners=(start == "design"))
        x = self.full(self.reduce(x))          # the bar tops follow the attachment
        return self.with_straight_tendons(x)

    def state_note(self, x: np.ndarray) -> str:
        """Slack tendons and stretch of the membrane at node positions x (3, n) whose first
        nodes are the placement numbering, for error messages."""
        tt = truss_internal(x, self.tendons, tangent=False)
        nt = len(self.system.tendons)
        slack = np.bincount(self.topology.tendon_of_element, weights=tt.slack.astype(float),
                            minlength=nt) > 0
        names = [t.name for t, s_ in zip(self.system.tendons, slack) if s_]
        c = x[:, self.topology.mesh.corners]
        return (f"{len(names)} of {slack.size} tendons slack{': ' + ', '.join(names[:9]) if names else ''}"
                f"{' ...' if len(names) > 9 else ''}; mean corner radius "
                f"{np.linalg.norm(c - c.mean(axis=1, keepdims=True), axis=0).mean():.4f} m")
