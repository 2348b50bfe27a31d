"""VTK files of tensegrity-membrane systems for ParaView (meshio).

This module is the only place where meshio's row-major arrays (points (n, 3), cells
(n_cells, n_vertices)) appear; everything it receives follows the tmfem convention of
coordinates (3, n_nodes) and connectivity (n_vertices, n_cells).

Codes written as integer data (VTU files hold numbers, not strings):

* cell data ``kind``: 0 bar, 1 tendon, 2 membrane (see :data:`KIND_CODES`);
* cell data ``family``: index into :data:`FAMILY_CODES` (``S V D C P R SL SU``), -1 for
  bars and membrane cells; ``stage`` and ``j`` give the indices i, j of the member label;
* point data ``node_kind``: 0 for A_ij, 1 for B_ij, 2 for H_1j, -1 for membrane mesh
  nodes; ``node_stage`` and ``node_j`` give i, j of the label, ``node_id`` its index in
  ``System.node_labels``.

Floating-point data not defined on a cell or point (a bar's rest length, a membrane
stress on a tendon) is NaN, which ParaView shows as "no value".
"""
from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tmfem.errors import BackendUnavailable, InputError
from tmfem.mesh.polygon import MembraneMesh
from tmfem.system.topology import label

KIND_CODES = {"bar": 0, "tendon": 1, "membrane": 2}
FAMILY_CODES = ("S", "V", "D", "C", "P", "R", "SL", "SU")
NODE_KIND_CODES = {"A": 0, "B": 1, "H": 2}
SUFFIXES = (".vtu", ".xdmf", ".vtk")


# ---------------------------------------------------------------------------- inputs
@dataclass(frozen=True)
class MembraneField:
    """A membrane mesh placed in space, with data for the output files.

    Attributes
    ----------
    mesh : MembraneMesh
        The flat reference mesh (2, nn) / (4, ne) in the floating frame O_f.
    x : ndarray (3, nn)
        Current node positions in the inertial frame.
    point_data : dict
        Arrays of shape (nn,) or (c, nn) (e.g. displacement (3, nn)).
    cell_data : dict
        Arrays of shape (ne,) or (c, ne) (e.g. ``von_mises``, ``sigma_p1``).
    """

    mesh: MembraneMesh
    x: np.ndarray
    point_data: dict = field(default_factory=dict)
    cell_data: dict = field(default_factory=dict)

    def __post_init__(self):
        nn = self.mesh.p.shape[1]
        ne = self.mesh.t.shape[1]
        x = np.asarray(self.x, dtype=float)
        if x.shape != (3, nn):
            raise InputError(f"membrane field: expected positions x of shape (3, {nn}), "
                             f"found {x.shape}")
        if not np.all(np.isfinite(x)):
            raise InputError("membrane field: positions x have non-finite entries")
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "point_data",
                           {k: _check_data(f"membrane point data {k!r}", v, nn)
                            for k, v in self.point_data.items()})
        object.__setattr__(self, "cell_data",
                           {k: _check_data(f"membrane cell data {k!r}", v, ne)
                            for k, v in self.cell_data.items()})


def _check_data(what: str, value, n: int) -> np.ndarray:
    """Data of shape (n,) or (c, n) -> (n,) or (n, c) (meshio's row-major layout)."""
    a = np.asarray(value)
    if a.ndim == 1 and a.shape[0] == n:
        return a
    if a.ndim == 2 and a.shape[1] == n:
        return np.ascontiguousarray(a.T)
    raise InputError(f"{what}: expected shape ({n},) or (c, {n}), found {a.shape}")


def check_path(path, *, suffixes=SUFFIXES) -> Path:
    """Validate an output path: a known suffix, not a directory; create missing parents."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise InputError(f"output file {str(path)!r}: expected a suffix in {list(suffixes)}, "
                         f"found {path.suffix or 'none'!r}")
    if path.is_dir():
        raise InputError(f"output file {str(path)!r} is a directory")
    parent = path.parent
    if parent.exists() and not parent.is_dir():
        raise InputError(f"output file {str(path)!r}: parent {str(parent)!r} is not a directory")
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"output file {str(path)!r}: cannot create directory "
                         f"{str(parent)!r} ({exc.strerror})") from None
    if not os.access(parent, os.W_OK):
        raise InputError(f"output file {str(path)!r}: directory {str(parent)!r} is not writable")
    return path


def check_dir(path) -> Path:
    """Validate an output directory before any work: not a file, creatable, writable."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"output directory {str(path)!r} is a file")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"output directory {str(path)!r}: cannot create it "
                         f"({exc.strerror})") from None
    if not os.access(path, os.W_OK):
        raise InputError(f"output directory {str(path)!r} is not writable")
    return path


# ---------------------------------------------------------------------------- labels
_LABEL = re.compile(r"^([A-Z]+)_(\d)(\d)$|^([A-Z]+)_(\d+),(\d+)$")


def _split_label(name: str) -> tuple[str, int, int]:
    """``A_12`` -> ("A", 1, 2); ``A_1,12`` -> ("A", 1, 12)."""
    m = _LABEL.match(name)
    if m is None:
        raise InputError(f"unexpected node label {name!r}")
    if m.group(1):
        return m.group(1), int(m.group(2)), int(m.group(3))
    return m.group(4), int(m.group(5)), int(m.group(6))


def node_codes(system) -> dict:
    """Integer point data identifying the labelled nodes of ``system``."""
    parts = [_split_label(s) for s in system.node_labels]
    return {"node_id": np.arange(len(parts), dtype=np.int64),
            "node_kind": np.array([NODE_KIND_CODES[p[0]] for p in parts], dtype=np.int64),
            "node_stage": np.array([p[1] for p in parts], dtype=np.int64),
            "node_j": np.array([p[2] for p in parts], dtype=np.int64)}


# ---------------------------------------------------------------------------- member data
def member_data(system, *, q=None, tendon_forces=None, rest_lengths=None,
                bar_forces=None) -> dict:
    """Per-member data of bars then tendons, each array of length M N + n_tendons.

    Force density is force / current length (eq. 3.8 uses q = f / l); stress is force /
    cross-section area. A tendon is slack when its force is <= 0; without forces, when
    its current length is below its rest length. ``strain`` is (l - l0) / l0.
    """
    nb = system.M * system.N
    nt = len(system.tendons)
    A, B = system.bar_ends(q)
    bar_len = np.linalg.norm(B - A, axis=0).T.ravel()      # stage-major: (i-1) N + j-1
    ten_len = system.tendon_lengths(q)

    def vec(name, v, n):
        if v is None:
            return None
        v = np.asarray(v, dtype=float)
        if v.shape != (n,):
            raise InputError(f"{name}: expected shape ({n},), found {v.shape}")
        if not np.all(np.isfinite(v)):
            raise InputError(f"{name}: non-finite entries {v}")
        return v

    tf = vec("tendon_forces", tendon_forces, nt)
    bf = vec("bar_forces", bar_forces, nb)
    r = rest_lengths if rest_lengths is not None else system.rest_lengths
    r = vec("rest_lengths", r, nt)
    if r is not None and np.any(r <= 0):
        raise InputError(f"rest_lengths: expected positive values, found {r}")
    nan_b, nan_t = np.full(nb, np.nan), np.full(nt, np.nan)

    force = np.concatenate([nan_b if bf is None else bf, nan_t if tf is None else tf])
    length = np.concatenate([bar_len, ten_len])
    area = np.concatenate([np.full(nb, system.bar.area),
                           [system.tendon_section(t).area for t in system.tendons]])
    if tf is not None:
        slack_t = (tf <= 0).astype(np.int64)
    elif r is not None:
        slack_t = (ten_len < r).astype(np.int64)
    else:
        slack_t = np.full(nt, -1, dtype=np.int64)
    rest = np.concatenate([nan_b, nan_t if r is None else r])
    stage_b = np.repeat(np.arange(1, system.M + 1), system.N)
    j_b = np.tile(np.arange(1, system.N + 1), system.M)
    return {
        "kind": np.concatenate([np.zeros(nb), np.ones(nt)]).astype(np.int64),
        "member_id": np.concatenate([np.arange(nb), np.arange(nt)]).astype(np.int64),
        "family": np.concatenate([np.full(nb, -1),
                                  [FAMILY_CODES.index(t.family) for t in system.tendons]]
                                 ).astype(np.int64),
        "stage": np.concatenate([stage_b, [t.stage for t in system.tendons]]).astype(np.int64),
        "j": np.concatenate([j_b, [t.j for t in system.tendons]]).astype(np.int64),
        "length": length,
        "axial_force": force,
        "force_density": force / length,
        "axial_stress": force / area,
        "slack": np.concatenate([np.full(nb, -1, dtype=np.int64), slack_t]),
        "rest_length": rest,
        "strain": (length - rest) / rest,
    }


# ---------------------------------------------------------------------------- writing
def require_h5py() -> None:
    """meshio writes ``.xdmf`` through h5py: raise BackendUnavailable when it is missing."""
    try:
        import h5py  # noqa: F401
    except ImportError:
        raise BackendUnavailable("writing .xdmf needs h5py: `pip install h5py`, "
                                 "or write .vtu") from None


def _write_mesh(path: Path, points: np.ndarray, cells: list, *, point_data: dict,
                cell_data: dict, field_data: dict | None = None) -> Path:
    """Write with meshio; ``points`` (3, n), cells as (type, (nv, nc)) pairs."""
    import meshio

    suffix = path.suffix.lower()
    blocks = []
    cdata = {k: list(v) for k, v in cell_data.items()}
    for b, (ctype, conn) in enumerate(cells):
        conn = np.asarray(conn, dtype=np.int64)
        if suffix == ".xdmf" and ctype == "polygon":
            # XDMF has no general polygon in meshio: a fan of triangles keeps the picture
            nv = conn.shape[0]
            fan = np.stack([np.repeat(conn[0], nv - 2),
                            conn[1:-1].reshape(-1, order="F"),
                            conn[2:].reshape(-1, order="F")])
            ctype, conn = "triangle", fan
            for k in cdata:
                cdata[k][b] = np.repeat(cdata[k][b], nv - 2, axis=0)
        blocks.append((ctype, np.ascontiguousarray(conn.T)))
    mesh = meshio.Mesh(np.ascontiguousarray(np.asarray(points, dtype=float).T), blocks,
                       point_data=point_data, cell_data=cdata)
    if suffix == ".xdmf":
        require_h5py()
    meshio.write(path, mesh)
    if field_data:
        if suffix != ".vtu":
            raise InputError(f"field data (e.g. frequencies) is written to .vtu files only, "
                             f"found {suffix!r}")
        _add_vtu_field_data(path, field_data)
    return path


def _add_vtu_field_data(path: Path, field_data: dict) -> None:
    """Insert a <FieldData> block (ascii Float64 arrays) into a VTU file written by meshio.

    meshio reads FieldData from VTU but does not write it; VTK and ParaView read it as
    the data set's field data.
    """
    text = path.read_text()
    arrays = []
    for name, v in field_data.items():
        v = np.atleast_1d(np.asarray(v, dtype=float)).ravel()
        vals = " ".join(repr(float(x)) for x in v)
        arrays.append(f'<DataArray type="Float64" Name="{name}" NumberOfTuples="{v.size}" '
                      f'format="ascii">{vals}</DataArray>')
    block = "<FieldData>" + "".join(arrays) + "</FieldData>"
    marker = "<UnstructuredGrid>"
    if marker not in text:
        raise RuntimeError(f"{path}: no {marker} element to attach field data to")
    path.write_text(text.replace(marker, marker + "\n" + block, 1))
    ET.parse(path)  # still well-formed


def write_configuration(path, system, *, q=None, tendon_forces=None, rest_lengths=None,
                        membrane: MembraneField | None = None, point_data=None,
                        bar_forces=None) -> Path:
    """Write a configuration of ``system`` for ParaView: bars, tendons, membrane.

    Parameters
    ----------
    path : str or Path
        ``.vtu`` (default choice), ``.xdmf`` (needs h5py) or legacy ``.vtk``.
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
    Path of the written file. Cell data: ``kind``, ``member_id``, ``family``, ``stage``,
    ``j``, ``length``, ``axial_force``, ``force_density``, ``axial_stress``, ``slack``,
    ``rest_length``, ``strain`` and the membrane's cell data; point data: node codes
    (see the module docstring), the membrane's and ``point_data``.
    """
    path = check_path(path)
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
        extra[k] = _check_data(f"point data {k!r}", v, n_nodes).astype(float)
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
    return _write_mesh(path, points, cells, point_data=pdata, cell_data=cell_data)


# ---------------------------------------------------------------------------- membrane
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


# ---------------------------------------------------------------------------- modes
def _normalise_cells(cells, n_points: int) -> list:
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


def _block_data(point_data, cell_data, blocks, n_points: int) -> tuple[dict, dict]:
    """Point data (n,) / (c, n) and cell data (a list with one array per cell block) in
    meshio's layout, checked against ``n_points`` and the blocks' cell counts."""
    pdata = {k: _check_data(f"point data {k!r}", v, n_points)
             for k, v in (point_data or {}).items()}
    cdata = {}
    for k, v in (cell_data or {}).items():
        if len(v) != len(blocks):
            raise InputError(f"cell data {k!r}: expected one array per cell block "
                             f"({len(blocks)}), found {len(v)}")
        cdata[k] = [_check_data(f"cell data {k!r}", a, c.shape[1]) for a, (_, c) in zip(v, blocks)]
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


def write_modes(path, base_points, cells, shapes, freq_hz, *, point_data=None,
                cell_data=None) -> Path:
    """Write mode shapes into one ``.vtu``: point data ``mode_1`` .. ``mode_k`` (3-vectors).

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
    path = check_path(path, suffixes=(".vtu",))
    shapes = np.asarray(shapes, dtype=float)
    X, S, f = check_modes(base_points, shapes[:, None] if shapes.ndim == 1 else shapes, freq_hz,
                          points_name="base_points")
    n = X.shape[1]
    blocks = _normalise_cells(cells, n)
    extra, cdata = _block_data(point_data, cell_data, blocks, n)
    pdata = {f"mode_{k + 1}": S[:, k].reshape(n, 3) for k in range(S.shape[1])}
    pdata.update(extra)
    fd = {"frequency_hz": f}
    fd.update({f"mode_{k + 1}_hz": f[k] for k in range(f.size)})
    return _write_mesh(path, X, blocks, point_data=pdata, cell_data=cdata, field_data=fd)


def configuration_cells(system) -> list:
    """Cells of the labelled nodes of ``system``: bars, tendons and the membrane polygon."""
    return [("line", system.bar_connectivity), ("line", system.tendon_connectivity),
            ("polygon", membrane_corner_nodes(system)[:, None])]


def membrane_corner_nodes(system) -> np.ndarray:
    """Indices of the membrane corners B_M1..B_MN in ``system.node_labels``."""
    return np.array([system.node_index(label("B", system.M, j)) for j in range(1, system.N + 1)])


# ---------------------------------------------------------------------------- series
class SeriesWriter:
    """A time series of ``.vtu`` files and the ``.pvd`` collection that lists them.

    Every :meth:`append` writes one frame file and rewrites the ``.pvd`` (atomically), so
    a run that stops early leaves a valid collection of the frames written so far.
    """

    def __init__(self, directory, *, name: str = "frame"):
        directory = Path(directory)
        if directory.exists() and not directory.is_dir():
            raise InputError(f"series directory {str(directory)!r} is a file")
        if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
            raise InputError(f"series name {name!r}: expected letters, digits, '_', '-', '.'")
        directory.mkdir(parents=True, exist_ok=True)
        self.directory = directory
        self.name = name
        self.pvd = directory / f"{name}.pvd"
        self.entries: list[tuple[float, str]] = []

    def _next(self) -> Path:
        return self.directory / f"{self.name}_{len(self.entries):05d}.vtu"

    def _commit(self, time: float, path: Path) -> Path:
        self.entries.append((float(time), path.name))
        rows = "".join(f'    <DataSet timestep="{t!r}" group="" part="0" file="{f}"/>\n'
                       for t, f in self.entries)
        text = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                f"  <Collection>\n{rows}  </Collection>\n</VTKFile>\n")
        tmp = self.pvd.with_suffix(".pvd.tmp")
        tmp.write_text(text)
        os.replace(tmp, self.pvd)
        return path

    def _check_time(self, time) -> float:
        time = float(time)
        if not np.isfinite(time):
            raise InputError(f"series time must be finite, found {time}")
        if self.entries and time <= self.entries[-1][0]:
            raise InputError(f"series times must increase: frame {len(self.entries)} at "
                             f"t={time} after t={self.entries[-1][0]}")
        return time

    def append(self, time, points, cells, *, point_data=None, cell_data=None) -> Path:
        """Write one frame: points (3, n), cells as for :func:`write_modes`."""
        time = self._check_time(time)
        X = np.asarray(points, dtype=float)
        if X.ndim != 2 or X.shape[0] != 3:
            raise InputError(f"points: expected shape (3, n), found {X.shape}")
        blocks = _normalise_cells(cells, X.shape[1])
        pdata, cdata = _block_data(point_data, cell_data, blocks, X.shape[1])
        path = _write_mesh(self._next(), X, blocks, point_data=pdata, cell_data=cdata)
        return self._commit(time, path)

    def append_configuration(self, time, system, **kwargs) -> Path:
        """Write one frame with :func:`write_configuration` (same keyword arguments)."""
        time = self._check_time(time)
        path = write_configuration(self._next(), system, **kwargs)
        return self._commit(time, path)


def write_series(directory, frames, *, name: str = "frame") -> Path:
    """Write frames one by one as they come; returns the ``.pvd`` path.

    ``frames`` is an iterable (a generator from a running simulation is fine) of
    ``(time, points (3, n), cells)`` or ``(time, points, cells, point_data)`` tuples.
    """
    w = SeriesWriter(directory, name=name)
    for fr in frames:
        if len(fr) == 3:
            w.append(fr[0], fr[1], fr[2])
        elif len(fr) == 4:
            w.append(fr[0], fr[1], fr[2], point_data=fr[3])
        else:
            raise InputError(f"series frame: expected (time, points, cells[, point_data]), "
                             f"found a tuple of {len(fr)}")
    return w.pvd


def read_pvd(path) -> list[tuple[float, Path]]:
    """Times and frame files listed in a ``.pvd`` collection."""
    path = Path(path)
    root = ET.parse(path).getroot()
    return [(float(d.attrib["timestep"]), path.parent / d.attrib["file"])
            for d in root.iter("DataSet")]
