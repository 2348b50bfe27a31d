"""Topology, node numbering and placement of the membrane-truss-cable model (dissertation 4.4, 6.2).

Global node numbering of an MTC model (DOF = 3 node + component):

* ``0 .. nm-1``          the membrane mesh nodes (``polygon_quad_mesh`` order);
* ``nm .. nm+ns-1``      one node per labelled system node (``system.node_labels``:
                         A_ij, B_ij, H_1j); the top-stage bar ends B_Mj are *dependent*
                         nodes: their position is a fixed weighted average of membrane
                         nodes (the attachment, see :func:`attachment_weights`);
* ``nm+ns ..``           the internal nodes of the tendons, ``k - 1`` per tendon.

The independent unknowns are all nodes but the B_Mj; the map ``x_full = T x_red`` (T sparse,
one row block per node) expresses a point attachment (B_Mj *is* membrane corner j, weight 1)
and a distributed one (B_Mj is the weighted centroid of a small corner patch, so the bar and
tendon forces at the corner spread over the patch as nodal forces w_i F: an RBE3-type link
that adds no stiffness).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.constraints import ConstraintMap
from tmfem.fem.dofmap import DofMap
from tmfem.fem.attachment import attachment_weights, default_patch_radius
from tmfem.mesh.polygon import MembraneMesh, polygon_quad_mesh
from tmfem.system.geometry import floating_frame
from tmfem.system.topology import label


@dataclass(frozen=True)
class MTCTopology:
    """Nodes, members and the attachment map of an MTC model.

    Attributes
    ----------
    mesh : MembraneMesh
    n_mesh, n_nodes : int
        Number of membrane nodes and of all (full) nodes.
    system_node : ndarray (n_labels,)
        Global node of each label of ``system.node_labels``.
    bar_conn : ndarray (2, M N)
        Global nodes (A_ij, B_ij) of each bar, in ``system.bar_connectivity`` order.
    tendon_conn : ndarray (2, n_t k)
        Element connectivity of the tendons, ``k`` elements per tendon, tendon-major.
    tendon_of_element : ndarray (n_t k,)
        Tendon index of each tendon element.
    tendon_internal : ndarray (n_t, k - 1)
        Global internal nodes of each tendon.
    fixed_nodes : ndarray (N,)
        The bar bases A_1j (pinned).
    top_nodes : ndarray (N,)
        The dependent bar-top nodes B_Mj.
    dofmap : DofMap
        Three translational dofs per node (dof = 3 node + component).
    constraints : ConstraintMap
        The attachment (dependent B_Mj) and the pinned bases; ``T = constraints.T``.
    T : csr (3 n_nodes, 3 n_red)
        Full positions from independent ones, ``x_full = T x_red``.
    red_node : ndarray (n_nodes,)
        Index of each node among the independent nodes (-1 for the B_Mj and rigid bar points).
    weights : list of (nodes, w)
        Attachment patch of each corner.
    """

    mesh: MembraneMesh
    n_mesh: int
    n_nodes: int
    system_node: np.ndarray
    bar_conn: np.ndarray
    tendon_conn: np.ndarray
    tendon_of_element: np.ndarray
    tendon_internal: np.ndarray
    fixed_nodes: np.ndarray
    top_nodes: np.ndarray
    dofmap: DofMap
    constraints: ConstraintMap
    T: sp.csr_matrix
    red_node: np.ndarray
    weights: list
    tendon_elements: int
    attachment: str

    @property
    def n_red(self) -> int:
        return int(self.T.shape[1]) // 3


def build_topology(system, *, mesh_n: int, tendon_elements: int, attachment: str = "point",
                   patch: float | None = None, rigid_bar_points: bool = False) -> MTCTopology:
    """Number the nodes and members of the MTC model of ``system`` (4.4, 6.2).

    Parameters
    ----------
    system : System
    mesh_n : int
        Elements along each side of each of the N membrane quadrilaterals.
    tendon_elements : int
        Truss elements per tendon (>= 1).
    attachment : {"point", "distributed"}
    patch : float, optional
        Patch radius of the distributed attachment [m]; default 10 % of r_mb (or of the
        polygon's circumradius).
    rigid_bar_points : bool
        Accept a 1-N(D) system with its H_1j as dependent nodes on the straight bar,
        x_H = (1 - k_H) x_A + k_H x_B (x_B itself the corner attachment): the statics of bars
        rigid in bending (the load at H_1j reaches the bar ends as a pinned rigid bar's
        reactions). Not the dissertation's MTC model (truss bars carry no point loads); the
        shell-beam-cable model's predictor (:mod:`tmfem.models.sbc.model`).
    """
    if system.deployable and not rigid_bar_points:
        raise InputError("MTC model: 1-N(D) systems (H_1j nodes along the bars) need bars "
                         "with an interior node and bending, which truss bars do not have; "
                         "expected an M-N system, found deployable=True")
    k = int(tendon_elements)
    if k < 1:
        raise InputError(f"tendon_elements: expected >= 1, found {tendon_elements!r}")
    mesh = polygon_quad_mesh(system.membrane_corners, mesh_n)
    nm = mesh.p.shape[1]
    labels = system.node_labels
    ns = len(labels)
    M, N = system.M, system.N
    system_node = nm + np.arange(ns)
    top_nodes = np.array([system_node[system.node_index(label("B", M, j))] for j in range(1, N + 1)])
    fixed_nodes = np.array([system_node[system.node_index(label("A", 1, j))] for j in range(1, N + 1)])
    bar_conn = system_node[system.bar_connectivity]
    tc = system_node[system.tendon_connectivity]                   # (2, n_t)
    n_t = tc.shape[1]
    internal = nm + ns + np.arange(n_t * (k - 1)).reshape(n_t, k - 1)
    chain = np.concatenate([tc[0][:, None], internal, tc[1][:, None]], axis=1)   # (n_t, k+1)
    tendon_conn = np.stack([chain[:, :-1].ravel(), chain[:, 1:].ravel()])
    tendon_of_element = np.repeat(np.arange(n_t), k)
    n_nodes = nm + ns + n_t * (k - 1)

    if patch is None:
        patch = default_patch_radius(system.membrane_corners, system.r_mb)
    weights = attachment_weights(mesh, attachment=attachment, patch=patch)
    dep = [(top_nodes[j], nodes, w) for j, (nodes, w) in enumerate(weights)]
    if system.deployable:
        kH = float(system.k_H)
        dep += [(system_node[system.node_index(label("H", 1, j + 1))],
                 np.concatenate([[fixed_nodes[j]], nodes]), np.concatenate([[1.0 - kH], kH * w]))
                for j, (nodes, w) in enumerate(weights)]

    dofmap = DofMap.translations(n_nodes)
    constraints = ConstraintMap.build(dofmap, dependent=dep, fixed_nodes=fixed_nodes)
    dependent = np.zeros(n_nodes, dtype=bool)
    dependent[[d[0] for d in dep]] = True
    red_node = np.full(n_nodes, -1, dtype=np.int64)
    red_node[~dependent] = np.arange(n_nodes - dependent.sum())
    return MTCTopology(mesh=mesh, n_mesh=nm, n_nodes=n_nodes, system_node=system_node,
                       bar_conn=bar_conn, tendon_conn=tendon_conn,
                       tendon_of_element=tendon_of_element, tendon_internal=internal,
                       fixed_nodes=fixed_nodes, top_nodes=top_nodes, dofmap=dofmap,
                       constraints=constraints, T=constraints.T, red_node=red_node,
                       weights=weights, tendon_elements=k, attachment=attachment)


# ---------------------------------------------------------------------------- frames
def membrane_placement(system, mesh: MembraneMesh, corners_3d: np.ndarray, *,
                       stretch_to_corners: bool) -> np.ndarray:
    """Positions (3, nm) of the membrane mesh nodes placed in the plane of ``corners_3d``.

    ``stretch_to_corners=False``: the undeformed membrane, rigidly placed with its centroid
    on the centroid of the corners and its x_f axis parallel to B_MN -> B_M1 (for a symmetric
    design the undeformed corners then sit a distance Delta (eq. 3.22) inside the B_Mj,
    along the radii). ``True``: the affine map (least squares) that sends the undeformed
    corners onto ``corners_3d`` (a uniform radial stretch for a symmetric design).
    """
    p = mesh.p
    pc = system.membrane_corners
    if not stretch_to_corners:
        _, R = floating_frame(corners_3d)
        c3 = corners_3d.mean(axis=1)
        c2 = pc.mean(axis=1)
        return c3[:, None] + R[:, :2] @ (p - c2[:, None])
    P = np.vstack([pc, np.ones(pc.shape[1])])                  # (3, N)
    A = np.linalg.lstsq(P.T, corners_3d.T, rcond=None)[0].T   # (3, 3): x = A [p; 1]
    return A @ np.vstack([p, np.ones(p.shape[1])])
