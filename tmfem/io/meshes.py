"""The meshio.Mesh of each result (configuration, mode shapes, series frame).

This package is the only place where meshio's row-major arrays (points (n, 3), cells
(n_cells, n_vertices)) appear; everything it receives follows the tmfem convention of
coordinates (3, n_nodes) and connectivity (n_vertices, n_cells). Floating-point data not
defined on a cell or point (a bar's rest length, a membrane stress on a tendon) is NaN,
which ParaView shows as "no value". Codes: :mod:`tmfem.io.codes`.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError
from tmfem.io.codes import KIND_CODES, membrane_corner_nodes, node_codes
from tmfem.io.fields import MembraneField, check_data
from tmfem.models.members import member_data


def to_meshio(points: np.ndarray, cells: list, *, point_data: dict, cell_data: dict):
    """A meshio.Mesh from points (3, n) and (type, connectivity (nv, nc)) blocks; data in
    meshio's layout (point data (n, ...), cell data one array per block)."""
    import meshio

    blocks = [(ctype, np.ascontiguousarray(np.asarray(conn, dtype=np.int64).T))
              for ctype, conn in cells]
    return meshio.Mesh(np.ascontiguousarray(np.asarray(points, dtype=float).T), blocks,
                       point_data=point_data, cell_data={k: list(v) for k, v in cell_data.items()})


def configuration_mesh(system, *, q=None, tendon_forces=None, rest_lengths=None,
                       membrane: MembraneField | None = None, point_data=None, bar_forces=None):
    """The meshio.Mesh of a configuration of ``system``: bars, tendons, membrane.

    The one mesh of a configuration result: :func:`tmfem.io.writer.write_configuration`
    writes it, :func:`tmfem.post.render.render_configuration` draws it (pyvista reads it
    with ``pyvista.from_meshio``).

    Parameters
    ----------
    system : System
    q : ndarray, optional
        Generalised coordinates (eqs. 3.1-3.2); default ``system.q``.
    tendon_forces : ndarray (n_tendons,), optional
        Axial tendon forces [N], aligned with ``system.tendons``.
    rest_lengths : ndarray (n_tendons,), optional
        Default ``system.rest_lengths``.
    membrane : MembraneField, optional
        Membrane mesh in its current position, written as quads with its data. Without
        it the membrane is the polygon B_M1..B_MN (one polygon cell).
    point_data : dict, optional
        Extra data on the labelled nodes, arrays (n_nodes,) or (c, n_nodes).
    bar_forces : ndarray (M N,), optional
        Axial bar forces [N] (negative in compression), stage-major order.

    Returns
    -------
    meshio.Mesh (one cell block each: bar lines, tendon lines, membrane). Cell data: ``kind``, ``member_id``,
    ``family``, ``stage``,
    ``j``, ``length``, ``axial_force``, ``force_density``, ``axial_stress``, ``slack``,
    ``rest_length``, ``strain`` and the membrane's cell data; point data: node codes
    (see the module docstring), the membrane's and ``point_data``.
    """
    X = system.nodes(q)
    n_nodes = X.shape[1]
    md = member_data(system, q=q, tendon_forces=tendon_forces, rest_lengths=rest_lengths,
                     bar_forces=bar_forces)
    nb = system.M * system.N
    cells = [("line", system.bar_connectivity), ("line", system.tendon_connectivity)]
    if membrane is not None:
        if not isinstance(membrane, MembraneField):
            raise InputError(f"membrane: expected a MembraneField, found {type(membrane).__name__}")
        points = np.concatenate([X, membrane.x], axis=1)
        cells.append(("quad", membrane.mesh.t + n_nodes))
        n_mem_cells = membrane.mesh.t.shape[1]
        n_mem_points = membrane.x.shape[1]
    else:
        points = X
        cells.append(("polygon", membrane_corner_nodes(system)[:, None]))
        n_mem_cells, n_mem_points = 1, 0

    def split(a, fill):
        m_part = np.full((n_mem_cells,) + a.shape[1:], fill, dtype=a.dtype)
        return [a[:nb], a[nb:], m_part]

    cell_data = {}
    for k, a in md.items():
        fill = -1 if np.issubdtype(a.dtype, np.integer) else np.nan
        cell_data[k] = split(a, fill)
    cell_data["kind"][2][:] = KIND_CODES["membrane"]
    cell_data["member_id"][2][:] = np.arange(n_mem_cells)
    if membrane is not None:
        for k, a in membrane.cell_data.items():
            if k in cell_data:
                raise InputError(f"membrane cell data {k!r} clashes with member data")
            a = np.asarray(a, dtype=float)
            lines = np.full((nb + len(system.tendons),) + a.shape[1:], np.nan)
            cell_data[k] = [lines[:nb], lines[nb:], a]

    pdata = {}
    codes = node_codes(system)
    for k, a in codes.items():
        pdata[k] = np.concatenate([a, np.full(n_mem_points, -1, dtype=np.int64)])
    extra = {}
    for k, v in (point_data or {}).items():
        extra[k] = check_data(f"point data {k!r}", v, n_nodes).astype(float)
    if membrane is not None:
        for k, a in membrane.point_data.items():
            a = a.astype(float)
            if k in extra:
                extra[k] = np.concatenate([extra[k], a], axis=0)
            else:
                extra[k] = np.concatenate([np.full((n_nodes,) + a.shape[1:], np.nan), a])
    for k, a in extra.items():
        if k in pdata:
            raise InputError(f"point data {k!r} clashes with the node codes")
        if a.shape[0] == n_nodes and n_mem_points:
            a = np.concatenate([a, np.full((n_mem_points,) + a.shape[1:], np.nan)])
        if a.shape[0] != points.shape[1]:
            raise InputError(f"point data {k!r}: expected {points.shape[1]} rows, "
                             f"found {a.shape[0]}")
        pdata[k] = a
    return to_meshio(points, cells, point_data=pdata, cell_data=cell_data)




def normalize_cells(cells, n_points: int) -> list:
    """Cells as (type, conn (nv, nc)) pairs from a dict or a list of pairs."""
    items = list(cells.items()) if isinstance(cells, dict) else list(cells)
    out = []
    known = {"vertex": 1, "line": 2, "triangle": 3, "quad": 4, "polygon": None}
    for item in items:
        if len(item) != 2:
            raise InputError(f"cells: expected (type, connectivity) pairs, found {item!r}")
        ctype, conn = item
        if ctype not in known:
            raise InputError(f"cells: unknown cell type {ctype!r}; expected one of {list(known)}")
        conn = np.asarray(conn, dtype=np.int64)
        if conn.ndim != 2 or (known[ctype] and conn.shape[0] != known[ctype]):
            raise InputError(f"cells {ctype!r}: expected connectivity of shape "
                             f"({known[ctype] or 'nv'}, n_cells), found {conn.shape}")
        if conn.size and (conn.min() < 0 or conn.max() >= n_points):
            raise InputError(f"cells {ctype!r}: node indices must lie in [0, {n_points}), "
                             f"found [{conn.min()}, {conn.max()}]")
        out.append((ctype, conn))
    if not out:
        raise InputError("cells: expected at least one cell block")
    return out


def block_data(point_data, cell_data, blocks, n_points: int) -> tuple[dict, dict]:
    """Point data (n,) / (c, n) and cell data (a list with one array per cell block) in
    meshio's layout, checked against ``n_points`` and the blocks' cell counts."""
    pdata = {k: check_data(f"point data {k!r}", v, n_points)
             for k, v in (point_data or {}).items()}
    cdata = {}
    for k, v in (cell_data or {}).items():
        if len(v) != len(blocks):
            raise InputError(f"cell data {k!r}: expected one array per cell block "
                             f"({len(blocks)}), found {len(v)}")
        cdata[k] = [check_data(f"cell data {k!r}", a, c.shape[1]) for a, (_, c) in zip(v, blocks)]
    return pdata, cdata


def check_modes(points, shapes, freq_hz, *, points_name: str = "points"):
    """Validated float arrays (X (3, n), S (3 n, k), f (k,)) of mode shapes about ``points``.

    Raises
    ------
    InputError
        if the shapes do not match (node-interleaved dofs, one frequency per mode) or an
        entry of ``shapes`` or ``freq_hz`` is not finite.
    """
    X = np.asarray(points, dtype=float)
    if X.ndim != 2 or X.shape[0] != 3:
        raise InputError(f"{points_name}: expected shape (3, n), found {X.shape}")
    n = X.shape[1]
    S = np.asarray(shapes, dtype=float)
    if S.ndim != 2 or S.shape[0] != 3 * n:
        raise InputError(f"shapes: expected shape ({3 * n}, k) for {n} points, found {S.shape}")
    f = np.atleast_1d(np.asarray(freq_hz, dtype=float))
    if f.shape != (S.shape[1],):
        raise InputError(f"freq_hz: expected {S.shape[1]} frequencies (one per mode), "
                         f"found shape {f.shape}")
    if not (np.all(np.isfinite(S)) and np.all(np.isfinite(f))):
        raise InputError("shapes/freq_hz: non-finite entries")
    return X, S, f


def modes_mesh(base_points, cells, shapes, freq_hz, *, point_data=None, cell_data=None):
    """The meshio.Mesh of mode shapes: point data ``mode_1`` .. ``mode_k`` (3-vectors) about
    the prestressed positions, field data ``frequency_hz`` and ``mode_k_hz``.

    Parameters
    ----------
    base_points : ndarray (3, n)
        Positions of the prestressed state about which the modes are computed.
    cells : dict or list of (type, connectivity (nv, n_cells))
    shapes : ndarray (3 n, k)
        Mode shapes, node-interleaved dofs (dof = 3 node + component).
    freq_hz : ndarray (k,)
        Natural frequencies, written as field data ``frequency_hz`` and also as the
        field arrays ``mode_k_hz`` so a ParaView user sees each mode's frequency.
    point_data, cell_data : dict, optional
        Extra data, arrays (n,) / (c, n) per point and, per cell block, a list.

    In ParaView: Warp By Vector with ``mode_k`` animates mode k.
    """
    shapes = np.asarray(shapes, dtype=float)
    X, S, f = check_modes(base_points, shapes[:, None] if shapes.ndim == 1 else shapes, freq_hz,
                          points_name="base_points")
    n = X.shape[1]
    blocks = normalize_cells(cells, n)
    extra, cdata = block_data(point_data, cell_data, blocks, n)
    pdata = {f"mode_{k + 1}": S[:, k].reshape(n, 3) for k in range(S.shape[1])}
    pdata.update(extra)
    fd = {"frequency_hz": f}
    fd.update({f"mode_{k + 1}_hz": f[k] for k in range(f.size)})
    mesh = to_meshio(X, blocks, point_data=pdata, cell_data=cdata)
    mesh.field_data.update({k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in fd.items()})
    return mesh
