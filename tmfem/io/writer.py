"""Writing the meshio.Mesh of a result: ``.vtu`` (ParaView), ``.xdmf`` (needs h5py), ``.vtk``."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tmfem.errors import BackendUnavailable, InputError
from tmfem.io.atomic import atomic_path
from tmfem.io.fields import MembraneField
from tmfem.io.meshes import configuration_mesh, modes_mesh
from tmfem.io.paths import check_path


def require_h5py() -> None:
    """meshio writes ``.xdmf`` through h5py: raise BackendUnavailable when it is missing."""
    try:
        import h5py  # noqa: F401
    except ImportError:
        raise BackendUnavailable("writing .xdmf needs h5py: `pip install h5py`, "
                                 "or write .vtu") from None


def _polygons_as_triangles(mesh):
    """The mesh with each polygon block split into a fan of triangles (XDMF has no general
    polygon in meshio); cell data repeated per triangle."""
    import meshio

    blocks, cdata = [], {k: [] for k in mesh.cell_data}
    for b, block in enumerate(mesh.cells):
        conn = block.data
        if block.type == "polygon":
            nv = conn.shape[1]
            fan = np.stack([np.repeat(conn[:, 0], nv - 2), conn[:, 1:-1].ravel(),
                            conn[:, 2:].ravel()], axis=1)
            blocks.append(("triangle", fan))
            for k in cdata:
                cdata[k].append(np.repeat(mesh.cell_data[k][b], nv - 2, axis=0))
        else:
            blocks.append((block.type, conn))
            for k in cdata:
                cdata[k].append(mesh.cell_data[k][b])
    return meshio.Mesh(mesh.points, blocks, point_data=mesh.point_data, cell_data=cdata,
                       field_data=mesh.field_data)


def write_mesh(path, mesh) -> Path:
    """Write a meshio.Mesh. Its ``field_data`` (e.g. the frequencies of a modes file) goes to
    ``.vtu`` only, written by VTK's own XML writer (meshio reads VTU field data but does not
    write it); everything else by meshio. Written atomically (:mod:`tmfem.io.atomic`),
    except ``.xdmf``, whose ``.h5`` companion file is named after it."""
    path = Path(path)
    if path.suffix.lower() == ".xdmf":
        _write_mesh(path, mesh)
        return path
    with atomic_path(path) as tmp:
        _write_mesh(tmp, mesh)
    return path


def _write_mesh(path: Path, mesh) -> None:
    suffix = path.suffix.lower()
    if mesh.field_data:
        if suffix != ".vtu":
            raise InputError(f"field data (e.g. frequencies) is written to .vtu files only, "
                             f"found {suffix!r}")
        import pyvista as pv

        grid = pv.from_meshio(mesh)
        for k, v in mesh.field_data.items():
            grid.field_data[k] = np.atleast_1d(np.asarray(v, dtype=float))
        grid.save(str(path), binary=True)
        return
    import meshio

    if suffix == ".xdmf":
        require_h5py()
        mesh = _polygons_as_triangles(mesh)
    meshio.write(path, mesh)


def write_configuration(path, system, *, q=None, tendon_forces=None, rest_lengths=None,
                        membrane: MembraneField | None = None, point_data=None,
                        bar_forces=None) -> Path:
    """Write a configuration of ``system`` for ParaView: bars, tendons, membrane.

    ``path``: ``.vtu`` (default choice), ``.xdmf`` (needs h5py) or legacy ``.vtk``; the
    other arguments and the data arrays are those of :func:`tmfem.io.meshes.configuration_mesh`.
    Returns the path written.
    """
    path = check_path(path)
    return write_mesh(path, configuration_mesh(system, q=q, tendon_forces=tendon_forces,
                                               rest_lengths=rest_lengths, membrane=membrane,
                                               point_data=point_data, bar_forces=bar_forces))


def write_modes(path, base_points, cells, shapes, freq_hz, *, point_data=None,
                cell_data=None) -> Path:
    """Write mode shapes into one ``.vtu`` (:func:`tmfem.io.meshes.modes_mesh`): point data
    ``mode_k``, field data ``frequency_hz`` and ``mode_k_hz``. In ParaView: Warp By Vector
    with ``mode_k`` animates mode k."""
    path = check_path(path, suffixes=(".vtu",))
    return write_mesh(path, modes_mesh(base_points, cells, shapes, freq_hz,
                                       point_data=point_data, cell_data=cell_data))
