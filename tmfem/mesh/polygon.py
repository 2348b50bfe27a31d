"""Quadrilateral mesh of a convex membrane polygon, as in dissertation 6.2.

The polygon with N corners is split into N quadrilaterals (centroid, the midpoint of the
edge before corner j, corner j, the midpoint of the edge after it); each is meshed by
gmsh with a transfinite n x n grid. The square membrane with n = 10 gives the
4 x 10 x 10 = 400 elements of 6.2.1, the triangle the 3 x 10 x 10 = 300 of 6.2.2.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from tmfem.errors import InputError


@dataclass(frozen=True)
class MembraneMesh:
    """A planar quadrilateral mesh in the floating frame O_f.

    Attributes
    ----------
    p : ndarray (2, n_nodes)
        Node coordinates (x_f, y_f).
    t : ndarray (4, n_elements)
        Counter-clockwise quadrilateral connectivity.
    corners : ndarray (N,)
        Node index of membrane corner j (j = 1..N).
    n : int
        Subdivisions per quadrilateral side.
    """

    p: np.ndarray
    t: np.ndarray
    corners: np.ndarray
    n: int

    def to_skfem(self):
        """The mesh as a :class:`skfem.MeshQuad`."""
        from skfem import MeshQuad
        return MeshQuad(self.p, self.t)


def _check_convex(corners: np.ndarray) -> None:
    N = corners.shape[1]
    e = np.roll(corners, -1, axis=1) - corners
    cross = e[0] * np.roll(e[1], -1) - e[1] * np.roll(e[0], -1)
    if not (np.all(cross > 0)):
        raise InputError(f"membrane polygon: expected {N} corners in counter-clockwise order "
                         f"forming a convex polygon, found edge turns {cross}")


def polygon_quad_mesh(corners, n: int) -> MembraneMesh:
    """Mesh a convex polygon into N quadrilaterals of n x n elements each (gmsh, transfinite).

    A mesh of at most :data:`KEPT_ELEMENTS` elements is made by gmsh once per corners and n
    and kept (the last 64), since gmsh's set-up is most of its time; a larger one is made
    anew each call, so that a run holds no large mesh it has left behind (the coarse levels
    of a mesh sequencing). Every call returns arrays of its own.

    Parameters
    ----------
    corners : array_like (2, N)
        Polygon corners, counter-clockwise.
    n : int
        Elements along each side of each of the N quadrilaterals.
    """
    corners = np.asarray(corners, dtype=float)
    if corners.ndim != 2 or corners.shape[0] != 2 or corners.shape[1] < 3:
        raise InputError(f"membrane polygon: expected corners of shape (2, N>=3), found {corners.shape}")
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise InputError(f"mesh: expected n >= 1 subdivisions, found {n!r}")
    _check_convex(corners)
    N = corners.shape[1]
    make = _kept_polygon_mesh if N * n * n <= KEPT_ELEMENTS else _gmsh_polygon_mesh
    p, t, corner_nodes = make(np.ascontiguousarray(corners).tobytes(), N, int(n))
    return MembraneMesh(p=p.copy(), t=t.copy(), corners=corner_nodes.copy(), n=int(n))


#: Largest number of elements of a membrane mesh that :func:`polygon_quad_mesh` keeps
KEPT_ELEMENTS = 1600


def _gmsh_polygon_mesh(corner_bytes: bytes, N: int, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodes p (2, n_nodes), counter-clockwise quadrilaterals t (4, n_elements) and corner
    nodes (N,) of :func:`polygon_quad_mesh` for the corners (2, N) given by their bytes."""
    import gmsh

    corners = np.frombuffer(corner_bytes, dtype=float).reshape(2, N)
    centre = corners.mean(axis=1)
    mids = 0.5 * (corners + np.roll(corners, -1, axis=1))  # mid j between corner j and j+1

    initialized_here = not gmsh.isInitialized()
    if initialized_here:
        gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("membrane")
        geo = gmsh.model.geo
        pc = geo.addPoint(*centre, 0.0)
        pk = [geo.addPoint(*corners[:, j], 0.0) for j in range(N)]
        pm = [geo.addPoint(*mids[:, j], 0.0) for j in range(N)]
        radial = [geo.addLine(pc, pm[j]) for j in range(N)]            # centre -> mid j
        half_a = [geo.addLine(pm[j - 1], pk[j]) for j in range(N)]      # mid j-1 -> corner j
        half_b = [geo.addLine(pk[j], pm[j]) for j in range(N)]          # corner j -> mid j
        surfaces = []
        for j in range(N):
            loop = geo.addCurveLoop([radial[j - 1], half_a[j], half_b[j], -radial[j]])
            surfaces.append(geo.addPlaneSurface([loop]))
        geo.synchronize()
        for c in radial + half_a + half_b:
            gmsh.model.mesh.setTransfiniteCurve(c, n + 1)
        for s in surfaces:
            gmsh.model.mesh.setTransfiniteSurface(s)
            gmsh.model.mesh.setRecombine(2, s)
        gmsh.model.mesh.generate(2)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        etypes, _, enodes = gmsh.model.mesh.getElements(2)
        corner_tags = [gmsh.model.mesh.getNodes(0, pk[j])[0][0] for j in range(N)]
        gmsh.model.remove()
    finally:
        if initialized_here:
            gmsh.finalize()
    quad = [k for k, et in enumerate(etypes) if et == 3]
    if not quad or len(etypes) != 1:
        raise RuntimeError(f"gmsh returned element types {list(etypes)}, expected only quadrilaterals (3)")
    order = np.argsort(tags)
    index = np.empty(int(tags.max()) + 1, dtype=int)
    index[tags[order]] = np.arange(tags.size)
    p = xyz.reshape(-1, 3)[order, :2].T.copy()
    t = index[np.asarray(enodes[quad[0]], dtype=np.int64).reshape(-1, 4)].T.copy()
    # orient all quadrilaterals counter-clockwise
    x, y = p[0, t], p[1, t]
    area2 = np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0)
    t[:, area2 < 0] = t[::-1, area2 < 0]
    return p, t, index[np.asarray(corner_tags, dtype=np.int64)]


_kept_polygon_mesh = lru_cache(maxsize=64)(_gmsh_polygon_mesh)
