"""The mode shapes of the SBC, MTC and COM models on the displacements all three share, for
pairing their modes by shape (:mod:`tmfem.reference.mode_pairing`).

The shared vector of a mode holds the translations (x, y, z in the inertial frame, metres) of

* the labelled system nodes (``system.node_labels``: the bar ends A_ij, B_ij), then
* the membrane's mesh nodes: the two finite-element models and the COM's membrane basis
  (eq. 5.1) are built on the same quadrilateral mesh of the membrane polygon for the same
  ``mesh_n`` (:func:`tmfem.mesh.polygon.polygon_quad_mesh`), node for node.

The finite-element models give them directly: the translations of their full mode shapes
(``full_shapes``) at ``topology.system_node`` and at the first ``topology.n_mesh`` nodes.
The COM's modes are vectors of its coordinates z (q, eta); their translations are the
derivatives along the mode of the node coordinates of the rigid bars, ``system.nodes(q)``
(eqs. 3.1-3.2), and of the membrane positions (eqs. 5.1, 5.3:
:meth:`ControlOrientedModel.membrane_positions`), by central differences. The SBC model's bar
interiors, the tendons' internal nodes and the shells' rotations are not shared and not used.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError

#: largest displacement [m] of a central-difference step along a COM mode
STEP = 1e-6


def fe_shared_shapes(model, modes) -> np.ndarray:
    """(3 (n_labels + n_mesh), k): the shared translations of an FE model's ``modes``."""
    S = model.full_shapes(modes.shapes)                          # (3, n_nodes, k)
    topo = model.topology
    nodes = np.concatenate([topo.system_node, np.arange(topo.n_mesh)])
    return S[:, nodes, :].transpose(1, 0, 2).reshape(3 * nodes.size, -1)


def com_shared_shapes(model, z_e, shapes, *, mesh_nodes: int) -> np.ndarray:
    """(3 (n_labels + n_mesh), k): the shared translations of the COM's mode ``shapes``
    (columns in its coordinates z) about its equilibrium ``z_e``. ``mesh_nodes``: the FE
    models' membrane nodes (the COM's basis must have as many: the same mesh)."""
    n_mesh = model.membrane.mesh.p.shape[1]
    if n_mesh != mesh_nodes:
        raise InputError(f"shared mode shapes: expected the COM's membrane mesh to be the FE models' "
                         f"({mesh_nodes} nodes), found {n_mesh} nodes (another mesh_n)")
    z_e = np.asarray(z_e, dtype=float)

    def translations(z):
        q = (model.P @ z)[:model.nq]
        return np.concatenate([model.system.nodes(q), model.membrane_positions(z)[0]], axis=1).T.ravel()

    out = []
    for v in np.asarray(shapes, dtype=float).T:
        h = STEP / np.abs(v).max()
        out.append((translations(z_e + h * v) - translations(z_e - h * v)) / (2 * h))
    return np.array(out).T


def beam_energy_share(model, state, modes) -> np.ndarray:
    """The bars' share of each SBC mode's strain energy, phi^T K_beam phi / omega^2 (the
    beams' tangent, material and geometric, at ``state``; the shapes are M-orthonormal, so
    phi^T K phi = omega^2). Near 1: the bars bend; near 0: the bars move as rigid bodies;
    negative: rigid-bar motion that the compressed bars' geometric stiffness softens."""
    from tmfem.fem.element import assemble
    _, K_beam = assemble([model.beam], state, tangent=True)
    phi = model.constraints.T @ modes.shapes
    return np.einsum("ik,ik->k", phi, K_beam @ phi) / np.asarray(modes.omega2, dtype=float)
