"""Frames meshed by gmsh: bars, beams and tendons as 1-D line meshes with physical groups.

:func:`frame_mesh` builds a gmsh model of straight members between given points (one
gmsh curve per member, ``elements_per_member`` elements on each by a transfinite curve, one
physical group per member family), meshes it in 1-D (first order: 2-node lines; third
order: 4-node lines, the beam element of :mod:`tmfem.fem.beam`) and returns it as a
``meshio.Mesh`` whose ``cell_sets`` are the physical groups (the gmsh file written with
``path=`` carries them too). :func:`system_frame_mesh` does it for the bars and tendons of a
:class:`tmfem.system.System` (groups ``bars`` and ``tendons_<family>``).
:meth:`tmfem.fem.structure.Structure.from_mesh` turns such a mesh (or any gmsh mesh of
quads and lines) into a structure with the groups as named node sets.
"""
from __future__ import annotations

import os
import tempfile

import numpy as np

from tmfem.errors import InputError


def frame_mesh(points, members, *, groups, elements_per_member: int = 1, order: int = 1, path=None):
    """A gmsh line mesh of a frame (module docstring).

    Parameters
    ----------
    points : array (3, n)
        Joint positions [m].
    members : array (2, m) of int
        End joints of each member.
    groups : sequence of str (m,)
        Physical group (family) of each member.
    elements_per_member : int
        Line elements on each member.
    order : 1 or 3
        2-node lines (bars, tendons) or 4-node lines (beams).
    path : str or Path, optional
        Also write the gmsh file there (``.msh``).
    """
    import gmsh
    import meshio
    X = np.asarray(points, dtype=float)
    M = np.asarray(members, dtype=np.int64)
    if X.ndim != 2 or X.shape[0] != 3:
        raise InputError(f"frame mesh: expected points of shape (3, n), found {X.shape}")
    if M.ndim != 2 or M.shape[0] != 2 or M.size == 0 or M.min() < 0 or M.max() >= X.shape[1]:
        raise InputError(f"frame mesh: expected members (2, m >= 1) of joints in [0, {X.shape[1]}), found "
                         f"shape {M.shape}")
    groups = list(groups)
    if len(groups) != M.shape[1] or not all(isinstance(g, str) and g for g in groups):
        raise InputError(f"frame mesh: expected one group name per member ({M.shape[1]}), found {len(groups)}")
    if np.any(M[0] == M[1]) or np.any(np.linalg.norm(X[:, M[1]] - X[:, M[0]], axis=0) == 0):
        raise InputError("frame mesh: expected members of non-zero length, found a member between coincident joints")
    if not (isinstance(elements_per_member, (int, np.integer)) and elements_per_member >= 1) or order not in (1, 3):
        raise InputError(f"frame mesh: expected elements_per_member >= 1 and order 1 or 3, found "
                         f"{elements_per_member!r}, {order!r}")
    own = not gmsh.isInitialized()
    if own:
        gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("tmfem_frame")
        used = np.unique(M)
        tag = {int(k): gmsh.model.geo.addPoint(*X[:, k]) for k in used}
        curves = [gmsh.model.geo.addLine(tag[int(a)], tag[int(b)]) for a, b in M.T]
        gmsh.model.geo.synchronize()
        for c in curves:
            gmsh.model.mesh.setTransfiniteCurve(c, int(elements_per_member) + 1)
        for name in dict.fromkeys(groups):
            gmsh.model.addPhysicalGroup(1, [c for c, g in zip(curves, groups) if g == name], name=name)
        gmsh.model.mesh.generate(1)
        if order == 3:
            gmsh.model.mesh.setOrder(3)
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "frame.msh") if path is None else str(path)
            gmsh.write(out)
            mesh = meshio.read(out)
        gmsh.model.remove()
    finally:
        if own:
            gmsh.finalize()
    return mesh


def system_frame_mesh(system, *, q=None, elements_per_member: int = 1, order: int = 1, path=None):
    """:func:`frame_mesh` of the bars and tendons of ``system`` at configuration ``q``
    (default its own): physical groups ``bars`` and ``tendons_<family>``."""
    bars = system.bar_connectivity
    tendons = system.tendon_connectivity
    members = np.hstack([bars, tendons])
    groups = ["bars"] * bars.shape[1] + [f"tendons_{t.family}" for t in system.tendons]
    return frame_mesh(system.nodes(q), members, groups=groups, elements_per_member=elements_per_member,
                      order=order, path=path)
