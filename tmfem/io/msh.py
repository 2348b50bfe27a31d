"""Membrane meshes as gmsh files (.msh, ASCII format 2.2, written and read with meshio).

The file holds the quadrilaterals (physical group 1, ``membrane``) and one vertex cell per
membrane corner (physical groups 101..100+N, ``corner_1`` .. ``corner_N``), so that a
mesh read back knows which node is corner j. Coordinates are those of the floating frame
O_f (3.2) with z = 0. ASCII keeps the committed reference meshes in ``meshes/`` readable
and byte-stable.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tmfem.errors import InputError
from tmfem.io.paths import check_path
from tmfem.io.writer import require_h5py
from tmfem.mesh.polygon import MembraneMesh

MEMBRANE_TAG = 1
CORNER_TAG0 = 100


def write_membrane_mesh(path, mesh: MembraneMesh) -> Path:
    """Write a :class:`MembraneMesh` to ``.msh`` (gmsh 2.2 ASCII), ``.vtu`` or ``.xdmf``."""
    import meshio

    path = check_path(path, suffixes=(".msh", ".vtu", ".xdmf"))
    if not isinstance(mesh, MembraneMesh):
        raise InputError(f"expected a MembraneMesh, found {type(mesh).__name__}")
    N = len(mesh.corners)
    pts = np.column_stack([mesh.p.T, np.zeros(mesh.p.shape[1])])
    cells = [("quad", np.ascontiguousarray(mesh.t.T)),
             ("vertex", np.asarray(mesh.corners, dtype=np.int64)[:, None])]
    ne = mesh.t.shape[1]
    phys = [np.full(ne, MEMBRANE_TAG), CORNER_TAG0 + np.arange(1, N + 1)]
    if path.suffix.lower() == ".msh":
        field_data = {"membrane": np.array([MEMBRANE_TAG, 2])}
        field_data.update({f"corner_{j}": np.array([CORNER_TAG0 + j, 0]) for j in range(1, N + 1)})
        m = meshio.Mesh(pts, cells, cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
                        field_data=field_data)
        meshio.write(path, m, file_format="gmsh22", binary=False)
    else:
        if path.suffix.lower() == ".xdmf":
            require_h5py()
        meshio.write(path, meshio.Mesh(pts, cells, cell_data={"group": phys}))
    return path


def read_membrane_mesh(path) -> MembraneMesh:
    """Read a membrane mesh written by :func:`write_membrane_mesh`."""
    import meshio

    path = Path(path)
    if not path.is_file():
        raise InputError(f"mesh file {str(path)!r} does not exist")
    try:
        m = meshio.read(path)
    except (Exception, SystemExit) as exc:  # meshio's gmsh reader may even sys.exit()
        raise InputError(f"mesh file {str(path)!r}: cannot read ({exc})") from None
    quads = [b.data for b in m.cells if b.type == "quad"]
    verts = [b.data for b in m.cells if b.type == "vertex"]
    if len(quads) != 1 or len(verts) != 1:
        raise InputError(f"mesh file {str(path)!r}: expected one quad block and one vertex block "
                         f"(corners), found {[b.type for b in m.cells]}")
    key = "gmsh:physical" if "gmsh:physical" in m.cell_data else "group"
    kinds = [b.type for b in m.cells]
    tags = np.asarray(m.cell_data[key][kinds.index("vertex")])
    corners = verts[0][:, 0][np.argsort(tags)]
    t = quads[0].T.astype(np.int64)
    N = corners.size
    n = int(round(np.sqrt(t.shape[1] / N)))
    if N * n * n != t.shape[1]:
        raise InputError(f"mesh file {str(path)!r}: {t.shape[1]} quads is not N n^2 for N={N}")
    if np.any(np.abs(m.points[:, 2]) > 0):
        raise InputError(f"mesh file {str(path)!r}: expected a flat mesh (z = 0), found "
                         f"|z| up to {np.abs(m.points[:, 2]).max():.3g}")
    return MembraneMesh(p=np.ascontiguousarray(m.points[:, :2].T), t=t, corners=corners, n=n)
