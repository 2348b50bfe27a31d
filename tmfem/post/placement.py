"""Placing a flat membrane mesh on the bar tops of a configuration, for display (mean value
coordinates, Floater 2003)."""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError
from tmfem.io.fields import MembraneField
from tmfem.mesh.polygon import MembraneMesh


def mean_value_coordinates(corners: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Mean value coordinates (Floater 2003) of points x (2, n) in a convex polygon (2, N).

    Returns weights (N, n) that sum to 1, reproduce linear functions and equal the
    Kronecker delta at the corners.
    """
    corners = np.asarray(corners, dtype=float)
    x = np.asarray(x, dtype=float)
    d = corners[:, :, None] - x[:, None, :]                 # (2, N, n)
    r = np.hypot(d[0], d[1])                                # (N, n)
    at_corner = r < 1e-14 * max(1.0, np.abs(corners).max())
    dn = np.roll(d, -1, axis=1)
    rn = np.roll(r, -1, axis=0)
    cross = d[0] * dn[1] - d[1] * dn[0]
    dot = d[0] * dn[0] + d[1] * dn[1]
    with np.errstate(divide="ignore", invalid="ignore"):
        # tan(alpha/2) = (r r' - d.d') / (d x d'), stable for points on an edge too
        tan_half = np.where(np.abs(cross) > 0, (r * rn - dot) / cross, 0.0)
        w = (np.roll(tan_half, 1, axis=0) + tan_half) / r
    # points on an edge: linear interpolation between the edge's corners
    on_edge = (np.abs(cross) <= 1e-12 * r * rn) & (dot < 0)
    w = np.where(np.isfinite(w), w, 0.0)
    lam = w / np.where(w.sum(axis=0) == 0, 1.0, w.sum(axis=0))
    N = corners.shape[1]
    for k in range(N):                       # loops over the N corners only
        e = on_edge[k]
        if np.any(e):
            t = r[k, e] / (r[k, e] + rn[k, e])
            lam[:, e] = 0.0
            lam[k, e] = 1 - t
            lam[(k + 1) % N, e] = t
    hit = np.nonzero(at_corner)
    lam[:, hit[1]] = 0.0
    lam[hit[0], hit[1]] = 1.0
    return lam


def membrane_on_configuration(system, mesh: MembraneMesh, *, q=None,
                              point_data=None, cell_data=None) -> MembraneField:
    """Place a flat membrane mesh on the bar tops of configuration q, for display.

    The mesh is put in the floating frame O_f of the current corners (origin B_MN, x_f
    toward B_M1); the in-plane corner displacements are interpolated over the membrane
    with mean value coordinates, so the corners land exactly on B_Mj. For a regular
    membrane on a symmetric configuration this is the uniform radial stretch by Delta
    (eq. 3.22). It is a picture, not a stress analysis: pass the FE displacements when
    you have them.
    """
    ref = system.membrane_corners
    if mesh.p.shape[0] != 2:
        raise InputError(f"membrane mesh: expected 2-D points, found shape {mesh.p.shape}")
    if len(mesh.corners) != system.N:
        raise InputError(f"membrane mesh has {len(mesh.corners)} corners, system has N={system.N}")
    delta, o, R = system.corner_displacements(q)            # (3, N) in O_f, eq. 3.4
    lam = mean_value_coordinates(ref, mesh.p)              # (N, nn)
    disp = delta @ lam
    xf = np.vstack([mesh.p, np.zeros(mesh.p.shape[1])]) + disp
    x = o[:, None] + R @ xf
    return MembraneField(mesh=mesh, x=x, point_data=dict(point_data or {}),
                         cell_data=dict(cell_data or {}))
