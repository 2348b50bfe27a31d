"""Files of the mode shapes of a finite-element model: ParaView (point data ``mode_k``) and a
picture of the first six."""
from __future__ import annotations


def write_mode_shapes(points, cells, shapes, freq_hz, *, vtk=None, png=None, title: str = "",
                      point_data=None) -> dict:
    """Write the mode shapes ``shapes`` (3 n, k; node-interleaved translations) about the node
    positions ``points`` (3, n) on ``cells``: a ParaView file ``vtk`` (with ``point_data`` such
    as the rotations, and the cell kinds) and a PNG ``png`` of the first six; returns the
    paths written by kind."""
    out = {}
    if vtk:
        from tmfem.io.codes import kind_cell_data
        from tmfem.io.writer import write_modes
        out["vtk"] = str(write_modes(vtk, points, cells, shapes, freq_hz, point_data=point_data,
                                     cell_data=kind_cell_data(cells)))
    if png:
        from tmfem.post.render import render_modes
        out["png"] = str(render_modes(png, points=points, cells=cells, shapes=shapes,
                                      freq_hz=freq_hz, k=min(6, len(freq_hz)), title=title))
    return out
