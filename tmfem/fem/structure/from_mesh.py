"""A structure from a gmsh model of shells and lines with physical groups.

:func:`structure_from_mesh` reads a ``meshio.Mesh`` (or a file meshio reads, e.g. a gmsh
``.msh`` from :func:`tmfem.mesh.frame.frame_mesh` or a user's model) whose physical groups
(``cell_sets``) name the parts:

- shell groups (4-node ``quad`` cells) become MITC4 element sets on 5-dof nodes;
- beam groups become 4-node beam elements on 6-dof nodes: third-order ``line4`` cells (gmsh
  node order: ends, then the interior nodes, turned into the order along the axis) or runs
  of three consecutive 2-node ``line`` cells (a curve meshed with 3k elements); a beam node
  that is also a shell node gets its own 6-dof node, pinned to the shell node (translations
  shared, rotations independent: a shell node has no drilling rotation to share);
- truss groups (2-node ``line`` cells) become bars or tendons on the translations of their
  nodes (3-dof nodes, or the shell/beam node they meet);
- every physical group (also of points or curves carrying no elements of their own, e.g. a
  clamped edge) becomes a named node set (:meth:`Structure.node_set`) of the nodes of its
  cells, and the element sets are kept in :attr:`Structure.element_sets`.

Geometry points without elements are dropped.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError

#: gmsh third-order line: (end, end, 1/3, 2/3) -> the beam element's order along its axis
_LINE4_ORDER = [0, 2, 3, 1]


def _cells_by_type(mesh) -> dict:
    out = {}
    for c in mesh.cells:
        out.setdefault(c.type, []).append(np.asarray(c.data, dtype=np.int64))
    return {k: np.concatenate(v) for k, v in out.items()}


def _runs_of_three(lines: np.ndarray, name: str) -> np.ndarray:
    """4-node beam elements (ne, 4) from 2-node lines (m, 2) ordered along their curves."""
    if lines.shape[0] % 3:
        raise InputError(f"structure from mesh: beam group {name!r}: expected 2-node lines in runs of 3 "
                         f"(3k elements per curve) or 4-node lines, found {lines.shape[0]} lines")
    t = lines.reshape(-1, 3, 2)
    if np.any(t[:, 0, 1] != t[:, 1, 0]) or np.any(t[:, 1, 1] != t[:, 2, 0]):
        raise InputError(f"structure from mesh: beam group {name!r}: expected consecutive lines along each "
                         f"curve in runs of 3, found a run that is not a chain")
    return np.column_stack([t[:, 0, 0], t[:, 0, 1], t[:, 1, 1], t[:, 2, 1]])


def structure_from_mesh(cls, mesh, *, shells=None, beams=None, trusses=None, orient=None, backend="scipy"):
    """The structure of a meshed model (module docstring).

    Parameters
    ----------
    mesh : meshio.Mesh or path
        Mesh with physical groups (gmsh ``cell_sets``).
    shells : dict name -> ShellSection
    beams : dict name -> dict(section=BeamSection, E=, nu=, rho=0.0, v1=None)
    trusses : dict name -> dict(EA=, rhoA=0.0, tension_only=False)
    orient : the director side of the shells (:meth:`Structure.add_shell`).
    """
    import meshio

    from tmfem.fem.beam import BeamElement, BeamSet
    from tmfem.fem.truss import TrussElement, TrussSet
    if not isinstance(mesh, meshio.Mesh):
        mesh = meshio.read(str(mesh))
    shells, beams, trusses = dict(shells or {}), dict(beams or {}), dict(trusses or {})
    sets = {k: v for k, v in mesh.cell_sets_dict.items() if not k.startswith("gmsh:")}
    wanted = list(shells) + list(beams) + list(trusses)
    missing = [k for k in wanted if k not in sets]
    if missing or len(set(wanted)) != len(wanted) or not wanted:
        raise InputError(f"structure from mesh: expected distinct physical groups from {sorted(sets)} as shells, "
                         f"beams and trusses, found {wanted} (missing {missing})")
    cells = _cells_by_type(mesh)

    def group_cells(name, kinds):
        got = {t: cells[t][np.asarray(i, dtype=np.int64)] for t, i in sets[name].items()}
        bad = sorted(set(got) - set(kinds))
        if bad or not got:
            raise InputError(f"structure from mesh: group {name!r}: expected {' or '.join(kinds)} cells, found "
                             f"{sorted(got)}")
        return got
    quads = {n: group_cells(n, ("quad",))["quad"] for n in shells}
    beam_conn = {}
    for n in beams:
        g = group_cells(n, ("line4", "line"))
        parts = []
        if "line4" in g:
            parts.append(g["line4"][:, _LINE4_ORDER])
        if "line" in g:
            parts.append(_runs_of_three(g["line"], n))
        beam_conn[n] = np.concatenate(parts)
    truss_conn = {n: group_cells(n, ("line",))["line"] for n in trusses}

    n_pts = mesh.points.shape[0]
    shell_nodes = np.zeros(n_pts, bool)
    for q in quads.values():
        shell_nodes[q.ravel()] = True
    beam_nodes = np.zeros(n_pts, bool)
    for b in beam_conn.values():
        beam_nodes[b.ravel()] = True
    used = shell_nodes | beam_nodes
    for t in truss_conn.values():
        used[t.ravel()] = True
    new = np.full(n_pts, -1, np.int64)
    new[used] = np.arange(int(used.sum()))
    counts = np.full(int(used.sum()), 3)
    counts[new[beam_nodes]] = 6
    counts[new[shell_nodes]] = 5
    shared = np.flatnonzero(shell_nodes & beam_nodes)                   # beam twins of shell nodes
    twin = np.full(n_pts, -1, np.int64)
    twin[shared] = counts.size + np.arange(shared.size)
    P = np.asarray(mesh.points, dtype=float)
    if P.ndim != 2 or P.shape[1] not in (2, 3):
        raise InputError(f"structure from mesh: expected 2-D or 3-D points, found {P.shape}")
    P = np.hstack([P, np.zeros((P.shape[0], 3 - P.shape[1]))])
    X = np.hstack([P[used].T, P[shared].T])
    s = cls(points=X, dofs=np.concatenate([counts, np.full(shared.size, 6)]), backend=backend)
    for n, sec in shells.items():
        s.element_sets[n] = s.add_shell(new[quads[n]].T, section=sec, orient=orient)
    for n, spec in beams.items():
        conn = np.where(twin[beam_conn[n]] >= 0, twin[beam_conn[n]], new[beam_conn[n]]).T
        spec = dict(spec)
        el = BeamElement(BeamSet(conn=conn, section=spec.pop("section"), E=spec.pop("E"), nu=spec.pop("nu"),
                                 rho=spec.pop("rho", 0.0), v1=spec.pop("v1", None), **spec), s.dofmap, X=s.X)
        s.add(el)
        s.element_sets[n] = el
    for n, spec in trusses.items():
        conn = new[truss_conn[n]].T
        L = np.linalg.norm(s.X[:, conn[1]] - s.X[:, conn[0]], axis=0)
        ne = conn.shape[1]
        el = TrussElement(TrussSet(conn=conn, L=L, EA=np.broadcast_to(spec["EA"], (ne,)),
                                   rhoA=np.broadcast_to(spec.get("rhoA", 0.0), (ne,)),
                                   tension_only=np.broadcast_to(spec.get("tension_only", False), (ne,))), s.dofmap)
        s.add(el)
        s.element_sets[n] = el
    for k in shared:
        s.pin(int(twin[k]), to=int(new[k]))
    for name, d in sets.items():
        nodes = np.unique(np.concatenate([cells[t][np.asarray(i, dtype=np.int64)].ravel() for t, i in d.items()]))
        nodes = new[nodes[used[nodes]]]
        if nodes.size:
            s.node_set(name, nodes)
    return s
