"""Corner attachments of the membrane: point or distributed (RBE3-type affine fit).

One construction shared by the membrane-truss-cable model (:mod:`tmfem.models.fe.topology`:
the bar top B_Mj is a dependent node) and the linear plane-stress membrane of the
equilibrium design (:class:`tmfem.fem.plane_stress.PlaneStressMembrane`: the corner
displacement is imposed on the patch). A point attachment (the corner *is* a membrane
node) is singular in a 2-D sheet: the corner force for a given corner displacement falls
like 1 / log(1/h) under refinement. A distributed one spreads the corner over a small patch
and converges (docs/guides/mtc.md, docs/validation/errata.md).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.mesh.polygon import MembraneMesh

ATTACHMENTS = ("point", "distributed")

#: default patch radius of the distributed attachment, as a fraction of the membrane radius
PATCH_FRACTION = 0.1


def default_patch_radius(corners, r_mb: float | None = None) -> float:
    """Default patch radius: ``PATCH_FRACTION`` (10 %) of r_mb, or of the circumradius of the
    corner polygon (distance centroid - corner, mean) when r_mb is not given."""
    if r_mb:
        R = float(r_mb)
    else:
        c = np.asarray(corners, dtype=float)
        R = float(np.max(np.linalg.norm(c - c.mean(axis=1, keepdims=True), axis=0)))
    return PATCH_FRACTION * R


def attachment_weights(mesh: MembraneMesh, *, attachment: str, patch: float) -> list:
    """Nodes and weights of the membrane patch each corner load is spread over.

    ``"point"``: the corner node alone (weight 1). ``"distributed"``: the membrane nodes
    within ``patch`` [m] of the corner. The bar top is the value at the corner of the affine
    map x(p) = a + B p fitted by weighted least squares to the patch nodes (weights omega_i =
    lumped nodal area times the taper 1 - r / patch): x_top = sum_i w_i x_i with
    w_i = omega_i [1, p_i] G^-1 [1, p_c], G = sum_i omega_i [1, p_i][1, p_i]^T. Hence
    sum w_i = 1 and sum w_i p_i = p_c: the link is exact for rigid motions (objective) and
    for any affine deformation of the patch, the attachment point stays at the design corner,
    and the corner force is spread over the patch as a smooth body-force density
    taper(r) (alpha + beta . p) that does not depend on the mesh. The stresses it causes stay
    bounded under refinement, unlike a point load (log-singular displacement, 1/r stress).

    Returns
    -------
    list of (nodes, w), one per corner (``mesh.corners`` order).
    """
    if attachment == "point":
        return [(np.array([c]), np.array([1.0])) for c in mesh.corners]
    if attachment != "distributed":
        raise InputError(f"attachment: expected 'point' or 'distributed', found {attachment!r}")
    if not patch > 0:
        raise InputError(f"attachment patch radius: expected > 0, found {patch!r}")
    p, t = mesh.p, mesh.t
    # lumped nodal areas (quarter of each quad's area to each of its nodes)
    x, y = p[0, t], p[1, t]
    area = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0))
    nodal = np.bincount(t.ravel(), weights=np.repeat(area[None] / 4.0, 4, axis=0).ravel(),
                        minlength=p.shape[1])
    out = []
    for c in mesh.corners:
        r = np.hypot(p[0] - p[0, c], p[1] - p[1, c])
        nodes = np.flatnonzero(r < patch)
        omega = nodal[nodes] * (1.0 - r[nodes] / patch)
        P = np.vstack([np.ones(nodes.size), p[:, nodes]])          # (3, n)
        G = (P * omega) @ P.T
        # the affine fit has 3 parameters: through 3 nodes it interpolates, and its value at
        # the corner node is that node alone, i.e. the point attachment in disguise
        if nodes.size < 4 or np.linalg.cond(G) > 1e12:
            raise InputError(f"distributed attachment: the patch of radius {patch:.4g} m holds "
                             f"{nodes.size} membrane nodes at this mesh; expected >= 4 not on a "
                             f"line (with 3 the affine fit is the point attachment): refine the "
                             f"mesh or enlarge the patch")
        # weighted least-squares affine fit of the patch, evaluated at the corner
        w = omega * (P.T @ np.linalg.solve(G, np.array([1.0, p[0, c], p[1, c]])))
        out.append((nodes, w))
    return out


def coupling_matrix(weights: list, n_nodes: int, dim: int) -> sp.csr_matrix:
    """Kinematic coupling C (dim N, dim n_nodes): corner values from nodal ones.

    Row ``dim * j + a`` gives component a of corner j as sum_i w_i x_{i,a} (node-interleaved
    columns, dof = dim * node + a). C^T maps corner forces to the nodal forces they spread
    over the patch (w_i F_j): the RBE3-type link, which adds no stiffness.
    """
    rows, cols, vals = [], [], []
    for j, (nodes, w) in enumerate(weights):
        for a in range(dim):
            rows.append(np.full(nodes.size, dim * j + a))
            cols.append(dim * nodes + a)
            vals.append(w)
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(dim * len(weights), dim * n_nodes))
