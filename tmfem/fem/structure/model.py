"""A general structural problem: shells (MITC4) and any other element set on one dof map.

:class:`Structure` holds nodes with 3, 5 or 6 dofs, element sets that implement the
:class:`tmfem.fem.element.Element` protocol (MITC4 shells, trusses, membranes, beams, ...),
boundary conditions on node sets, loads, and solves

- linear statics about the reference state (:meth:`Structure.solve_linear`),
- nonlinear statics by load/displacement stepping (:meth:`Structure.solve`: the load factor
  lam scales point loads, pressures and prescribed displacements together; Newton at every
  step, adaptive step halving) or by arc length (:meth:`Structure.solve_arc_length`),
- modes about any state, prestressed or loaded (:meth:`Structure.modes`, eq. 5.32),

and returns :class:`StructureState` objects that turn into a ``meshio.Mesh``
(:meth:`Structure.to_meshio`) with displacements, rotations, membrane forces, bending
moments and von Mises stresses at the bottom, middle and top surfaces for ParaView.

Rotations at 5-dof (shell) nodes are the two director rotations about the node's V_1, V_2
(eq. 4.16); the solvers update them by the exponential map (finite rotations). Shell nodes
on a symmetry plane get a reference triad whose V_1 is the plane normal, so that the
symmetry condition is "translation along the normal fixed, rotation about V_2 fixed".
See docs/guides/shells.md for a worked example.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from tmfem.errors import ConvergenceError, InputError, shorten
from tmfem.fem.beam import BeamElement
from tmfem.fem.constraints import ConstraintMap
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import State, assemble, smallest_rotation
from tmfem.fem.mitc4 import MITC4Shell, ShellPressure, ShellSection
from tmfem.fem.structure.from_mesh import structure_from_mesh
from tmfem.fem.structure.loads import BeamFollowerLoad, LineLoad, LoadCases
from tmfem.fem.structure.path import Path
from tmfem.fem.structure.reactions import Reactions, nodal_vectors
from tmfem.fem.structure.results import beam_nodal_section_forces, shell_nodal_results
from tmfem.fem.structure.supports import Supports
from tmfem.solvers import lowest_modes
from tmfem.solvers.backends import get_backend
from tmfem.solvers.continuation import follow, negative_pivots
from tmfem.solvers.newton import factorize, newton, submatrix
from tmfem.solvers.singular import SINGULAR_PIVOT_RATIO, SingularMatrix

log = logging.getLogger(__name__)

#: dof names of a node: translations, then the rotations of a 5-dof (about V_1, V_2) or a
#: 6-dof node (about x, y, z)
DOF_NAMES = {3: ("ux", "uy", "uz"), 5: ("ux", "uy", "uz", "r1", "r2"),
             6: ("ux", "uy", "uz", "rx", "ry", "rz")}
_AXES = {"x": 0, "y": 1, "z": 2}


def read_quad_mesh(mesh):
    """Points (3, n) and quadrilaterals (4, ne) of a scikit-fem ``MeshQuad`` (2-D or 3-D
    points), a ``meshio.Mesh``, a path readable by meshio, or a ``(points, quads)`` pair."""
    if isinstance(mesh, tuple) and len(mesh) == 2:
        p, t = np.asarray(mesh[0], float), np.asarray(mesh[1], np.int64)
    elif hasattr(mesh, "p") and hasattr(mesh, "t"):
        p, t = np.asarray(mesh.p, float), np.asarray(mesh.t, np.int64)
    else:
        import meshio
        if not isinstance(mesh, meshio.Mesh):
            mesh = meshio.read(str(mesh))
        quads = [c.data for c in mesh.cells if c.type == "quad"]
        if not quads:
            raise InputError(f"shell mesh: expected quad cells, found {[c.type for c in mesh.cells]}")
        p, t = np.asarray(mesh.points, float).T, np.concatenate(quads).T.astype(np.int64)
    if p.ndim != 2 or p.shape[0] not in (2, 3):
        raise InputError(f"shell mesh: expected points of shape (2 or 3, n), found {p.shape}")
    if p.shape[0] == 2:
        p = np.vstack([p, np.zeros(p.shape[1])])
    if t.ndim != 2 or t.shape[0] != 4:
        raise InputError(f"shell mesh: expected quadrilaterals of shape (4, ne), found {t.shape}")
    used = np.unique(t)
    if used.size != p.shape[1]:
        # drop unused points (a gmsh file carries geometry points without elements)
        new = np.full(p.shape[1], -1, np.int64)
        new[used] = np.arange(used.size)
        p, t = p[:, used], new[t]
    return p, t


def gmsh_quad_mesh():
    """Points (3, n) and 4-node quadrilaterals (4, ne) of the current gmsh model
    (``gmsh.model.mesh``, element type 3), for :meth:`Structure.shell`."""
    import gmsh
    tags, coords, _ = gmsh.model.mesh.getNodes()
    _, etags, enodes = gmsh.model.mesh.getElements(dim=2)
    types = gmsh.model.mesh.getElementTypes(dim=2)
    if 3 not in list(types):
        raise InputError(f"gmsh: expected 4-node quadrilaterals (type 3), found element types {list(types)}")
    nodes = np.asarray(gmsh.model.mesh.getElementsByType(3)[1], np.int64).reshape(-1, 4).T
    index = np.full(int(tags.max()) + 1, -1, np.int64)
    index[np.asarray(tags, np.int64)] = np.arange(tags.size)
    return read_quad_mesh((np.asarray(coords).reshape(-1, 3).T, index[nodes]))


def oriented_quads(X: np.ndarray, quads: np.ndarray, orient) -> np.ndarray:
    """Quads (4, ne) with the node order of every element whose normal g_1 x g_2 at its
    centre points against ``orient`` (a vector (3,) or ``orient(x, y, z) -> (3, ne)`` at the
    centres) reversed to (0, 3, 2, 1) (:meth:`Structure.add_shell`)."""
    if quads.ndim != 2 or quads.shape[0] != 4:
        raise InputError(f"shell: expected quadrilaterals of shape (4, ne), found {quads.shape}")
    xe = X[:, quads]                                                     # (3, 4, ne)
    n = np.cross((xe[:, 2] - xe[:, 0]).T, (xe[:, 3] - xe[:, 1]).T).T     # diagonals: 2 x g_1 x g_2
    want = np.asarray(orient(*xe.mean(axis=1)) if callable(orient) else orient, dtype=float)
    want = np.broadcast_to(want.reshape(3, -1), n.shape)
    dot = np.einsum("ie,ie->e", n, want)
    if np.any(np.abs(dot) <= 1e-12 * np.linalg.norm(n, axis=0) * np.linalg.norm(want, axis=0)):
        bad = np.flatnonzero(np.abs(dot) <= 1e-12 * np.linalg.norm(n, axis=0) * np.linalg.norm(want, axis=0))
        raise InputError(f"shell: expected an orient direction off the element planes, found it in the plane "
                         f"(or zero) at elements {bad[:5].tolist()}")
    out = quads.copy()
    flip = dot < 0
    out[:, flip] = quads[[0, 3, 2, 1]][:, flip]
    return out


@dataclass
class StructureState:
    """A solution: the nodal :class:`State`, its load factor and Newton iterations;
    ``reaction`` (ndof,): the generalized support reactions of the solve
    (:meth:`Structure.reactions`), ``linear``: a small-displacement solution
    (``increment``: its dofs (ndof,));
    ``negative_pivots`` of the tangent and the ``event`` ("limit point", "bifurcation") of
    the step that reached it, when the path following computed them."""

    state: State
    lam: float = 1.0
    iterations: int = 0
    residual_history: list = field(default_factory=list)
    reaction: np.ndarray | None = None
    linear: bool = False
    negative_pivots: int | None = None
    event: str | None = None
    increment: np.ndarray | None = None

    @property
    def x(self) -> np.ndarray:
        return self.state.x


class Structure:
    """Nodes, element sets, supports and loads of one structural model (module docstring).

    Parameters
    ----------
    points : ndarray (3, n_nodes)
        Reference positions [m].
    dofs : int or array_like (n_nodes,)
        Dofs per node: 3 (translations), 5 (shell) or 6 (beam).
    backend : str or Backend
        Linear-algebra backend of every solve (linear, Newton, arc length, modes; ``"scipy"``
        default, :func:`tmfem.solvers.get_backend`); its matrices are assembled as scipy
        matrices on every rank.
    """

    def __init__(self, *, points, dofs, backend="scipy"):
        self.backend = get_backend(backend)
        self.X = np.asarray(points, dtype=float)
        if self.X.ndim != 2 or self.X.shape[0] != 3 or self.X.shape[1] == 0:
            raise InputError(f"structure: expected points of shape (3, n) with n >= 1, found "
                             f"{self.X.shape}")
        if not np.all(np.isfinite(self.X)):
            bad = np.flatnonzero(~np.all(np.isfinite(self.X), axis=0))
            raise InputError(f"structure: expected finite node coordinates, found non-finite ones "
                             f"at nodes {shorten(bad.tolist())}")
        counts = np.broadcast_to(np.asarray(dofs, dtype=np.int64), (self.X.shape[1],))
        self.dofmap = DofMap(counts.copy())
        self.elements: list = []
        self.shells: list[MITC4Shell] = []
        self.frames = np.broadcast_to(np.eye(3), (self.n_nodes, 3, 3)).copy()
        self.axes = np.broadcast_to(np.eye(3), (self.n_nodes, 3, 3)).copy()
        self.supports = Supports(self.dofmap)
        self.node_sets: dict[str, np.ndarray] = {}
        self.element_sets: dict = {}
        self.loads = LoadCases(self.dofmap.ndof)
        self._cm = None

    # ------------------------------------------------------------------ building
    @classmethod
    def shell(cls, mesh, *, section: ShellSection, normals=None, orient=None, shear: str = "mitc",
              law="svk", backend="scipy") -> "Structure":
        """A shell structure from a quad mesh (scikit-fem ``MeshQuad``, ``meshio.Mesh``,
        meshio-readable path or ``(points, quads)``; flat or curved in 3-D): every node a 5-dof
        shell node, one MITC4 element set. ``normals`` (3, n): reference directors; ``orient``:
        the side the directors point to (:meth:`add_shell`); ``shear`` and ``law`` (in-plane
        lamina law, "svk" or "tension-field"): see :class:`MITC4Shell`; ``backend``: see
        :class:`Structure`."""
        p, t = read_quad_mesh(mesh)
        s = cls(points=p, dofs=5, backend=backend)
        s.add_shell(t, section=section, normals=normals, orient=orient, shear=shear, law=law)
        return s

    @classmethod
    def from_mesh(cls, mesh, *, shells=None, beams=None, trusses=None, orient=None,
                  backend="scipy") -> "Structure":
        """A structure from a mesh with physical groups (gmsh ``.msh``, ``meshio.Mesh``):
        ``shells`` {group: ShellSection}, ``beams`` {group: dict(section=, E=, nu=, rho=,
        v1=)}, ``trusses`` {group: dict(EA=, rhoA=, tension_only=)}; every physical group
        becomes a node set (:mod:`tmfem.fem.structure.from_mesh`)."""
        return structure_from_mesh(cls, mesh, shells=shells, beams=beams, trusses=trusses, orient=orient,
                                   backend=backend)

    @property
    def n_nodes(self) -> int:
        return self.X.shape[1]

    def add_shell(self, quads, *, section: ShellSection, normals=None, orient=None, shear: str = "mitc",
                  law="svk") -> MITC4Shell:
        """Add MITC4 elements on the 5-dof nodes ``quads`` (4, ne); ``law``: the in-plane
        lamina law ("svk" or "tension-field", :class:`MITC4Shell`).

        Director convention: the directors (and the normal of pressures, the top surface
        r_3 = 1 and the results frame) point to the side of the element normal g_1 x g_2,
        i.e. by the right-hand rule around the element's node order; given ``normals`` are
        turned to that side. ``orient`` chooses the side instead: a vector (3,) or a callable
        ``orient(x, y, z) -> (3, ne)`` at the element centres; every element whose normal
        points against it gets its node order reversed (0, 3, 2, 1), so that its normal and
        the directors point along ``orient`` (e.g. ``(0, 0, 1)`` for a plate, the outward
        radius for a cylinder)."""
        quads = np.asarray(quads, dtype=np.int64)
        if orient is not None:
            quads = oriented_quads(self.X, quads, orient)
        sh = MITC4Shell(X=self.X, conn=quads, section=section, dofmap=self.dofmap, normals=normals,
                        shear=shear, law=law)
        self.frames[sh.nodes] = sh.frames[sh.nodes]
        self.shells.append(sh)
        self.elements.append(sh)
        self._cm = None
        return sh

    def add(self, element) -> None:
        """Add an element set built on :attr:`dofmap` (truss, membrane, beam, ...)."""
        if getattr(element, "dofmap", None) is None or element.dofmap.ndof != self.dofmap.ndof:
            raise InputError(f"structure: expected an element set on this structure's dof map "
                             f"({self.dofmap.ndof} dofs), found {getattr(element, 'dofmap', None)}")
        self.elements.append(element)

    def node_set(self, name: str, nodes) -> np.ndarray:
        """Name a node set (indices, mask or another set's name); the name then stands for the
        nodes in every call that takes nodes (supports, loads, reaction resultants)."""
        nodes = self._nodes(nodes)
        self.node_sets[str(name)] = nodes
        return nodes

    def _nodes(self, nodes) -> np.ndarray:
        if isinstance(nodes, str):
            if nodes not in self.node_sets:
                raise InputError(f"structure: expected a node set from {sorted(self.node_sets)}, found {nodes!r}")
            return self.node_sets[nodes]
        nodes = np.asarray(nodes)
        if nodes.dtype == bool:
            if nodes.shape != (self.n_nodes,):
                raise InputError(f"structure: expected a node mask of shape ({self.n_nodes},), found {nodes.shape}")
            nodes = np.flatnonzero(nodes)
        return self.dofmap._nodes(nodes)

    def nodes_where(self, predicate) -> np.ndarray:
        """Nodes whose reference position satisfies ``predicate(x, y, z)`` (arrays -> bool)."""
        sel = np.asarray(predicate(*self.X), dtype=bool)
        nodes = np.flatnonzero(sel)
        if nodes.size == 0:
            raise InputError("structure: expected at least one node to satisfy the predicate, found none")
        return nodes

    def _names(self, n: int, dofs) -> tuple:
        names = DOF_NAMES[int(self.dofmap.counts[n])]
        if isinstance(dofs, str) and dofs == "all":
            return names
        want = (dofs,) if isinstance(dofs, str) else tuple(dofs)
        allowed = names + (("rx", "ry", "rz") if self.dofmap.counts[n] == 5 else ())
        bad = [d for d in want if d not in allowed]
        if bad:
            raise InputError(f"structure: node {n} has dofs {names}, expected names from them, found {bad}")
        return want

    def _row(self, n: int, name: str) -> tuple[str, np.ndarray]:
        """(field, coefficients) of the dof ``name`` of node n: ux uy uz and rx ry rz along the
        node's local axes (:meth:`local_frame`, default x, y, z), r1 r2 about its reference
        V_1, V_2; rx ry rz at a 5-dof node project on (V_1, V_2)."""
        A = self.axes[n]
        if name in ("ux", "uy", "uz"):
            return "u", A[:, "xyz".index(name[1])]
        if name in ("r1", "r2"):
            return "r", np.eye(2)[int(name[1]) - 1]
        d = A[:, "xyz".index(name[1])]
        if self.dofmap.counts[n] == 5:
            return "r", self.frames[n][:, :2].T @ d
        return "r", d

    def fix(self, nodes, dofs="all") -> None:
        """Fix dofs of ``nodes``: "all", a name (``ux uy uz`` translations and ``rx ry rz``
        rotations along the node's local axes, :meth:`local_frame`; ``r1 r2`` shell rotations
        about V_1, V_2) or a list of names. Adds to the node's supports (docs/guides/shells.md)."""
        label = f"fix({dofs!r})"
        for n in self._nodes(nodes):
            for name in self._names(int(n), dofs):
                f, c = self._row(int(n), name)
                self.supports.add(n, f, c, label=label)
        self._cm = None

    def symmetry(self, nodes, *, normal) -> None:
        """Symmetry plane through ``nodes`` with ``normal`` ("x", "y", "z" or a 3-vector): the
        translation along the normal is fixed and the rotation may only be about the normal
        (a shell node: the rotation about the tangent direction normal to the plane's trace
        is fixed; a 6-dof node: both rotations about axes in the plane). Adds to the node's
        supports: a node on two planes gets the conditions of both."""
        if isinstance(normal, str):
            if normal not in _AXES:
                raise InputError(f"symmetry: expected normal 'x', 'y', 'z' or a 3-vector, found {normal!r}")
            e = np.eye(3)[_AXES[normal]]
        else:
            e = np.asarray(normal, dtype=float)
            if e.shape != (3,) or np.linalg.norm(e) == 0:
                raise InputError(f"symmetry: expected normal 'x', 'y', 'z' or a 3-vector, found {normal!r}")
            e = e / np.linalg.norm(e)
        label = f"symmetry(normal={normal!r})"
        in_plane = np.linalg.svd(e[None, :])[2][1:]                  # (2, 3) orthonormal, _|_ e
        for n in self._nodes(nodes):
            c = int(self.dofmap.counts[n])
            self.supports.add(n, "u", e, label=label)
            if c == 5:
                e2 = self.frames[n][:, :2].T @ e
                if np.linalg.norm(e2) < 1e-8:
                    raise InputError(f"symmetry: node {n}: the plane normal {normal} is parallel to the "
                                     f"director; expected a plane that cuts the shell")
                self.supports.add(n, "r", np.array([-e2[1], e2[0]]), label=label)
            elif c == 6:
                for d in in_plane:
                    self.supports.add(n, "r", d, label=label)
        self._cm = None

    def local_frame(self, nodes, axes) -> None:
        """Local (skew) axes of ``nodes``: ``axes`` (3, 3) with the axes as columns, (len(nodes),
        3, 3), or a callable ``axes(x, y, z) -> (len(nodes), 3, 3)``. The dof names of later
        :meth:`fix` and :meth:`prescribe` calls at these nodes (``ux uy uz``, ``rx ry rz``) and
        the local reactions (:meth:`reactions`) refer to them; supports given before keep
        their directions."""
        nodes = self._nodes(nodes)
        A = np.asarray(axes(*self.X[:, nodes]) if callable(axes) else axes, dtype=float)
        if A.shape not in ((3, 3), (nodes.size, 3, 3)):
            raise InputError(f"local frame: expected axes of shape (3, 3) or ({nodes.size}, 3, 3), found {A.shape}")
        A = np.broadcast_to(A, (nodes.size, 3, 3))
        err = np.abs(np.einsum("nki,nkj->nij", A, A) - np.eye(3)).max(axis=(1, 2))
        if np.any(err > 1e-8) or np.any(np.linalg.det(A) < 0):
            raise InputError(f"local frame: expected orthonormal right-handed axes (columns), found "
                             f"an error of {err.max():.2e} or a reflection at node(s) "
                             f"{nodes[(err > 1e-8) | (np.linalg.det(A) < 0)][:5].tolist()}")
        self.axes[nodes] = A

    def pin(self, node: int, *, to) -> None:
        """Translation-only connection: the translations of ``node`` follow those of ``to``
        (its rotations, if any, stay free: a pin). Refused for a node that is pinned or
        supported already, or whose master is pinned."""
        self.supports.pin(int(node), [int(to)], [1.0], label=f"pin({int(node)}, to={int(to)})")
        self._cm = None

    def prescribe(self, nodes, dof: str, value) -> None:
        """Prescribed displacement [m] (or rotation [rad]) of dof ``dof`` (names as in
        :meth:`fix`) at ``nodes``, reached at load factor 1 (displacement control). ``value``:
        a number, one per node, or a callable ``value(x, y, z)`` of the reference positions.
        A dof constrained already is refused (conflicting or redundant)."""
        nodes = self._nodes(nodes)
        v = np.asarray(value(*self.X[:, nodes]) if callable(value) else value, dtype=float)
        v = np.broadcast_to(v, nodes.shape) if v.shape in ((), (1,), nodes.shape) else None
        if v is None or not np.all(np.isfinite(v)):
            raise InputError(f"prescribe: expected a finite value per node ({nodes.size}), found {value!r}")
        for n, vn in zip(nodes, v):
            (name,) = self._names(int(n), dof)
            f, c = self._row(int(n), name)
            self.supports.add(n, f, c, value=float(vn), prescribed=True, label=f"prescribe({dof!r})")
        self._cm = None

    def release(self, nodes, dofs="all") -> None:
        """Remove the supports of ``nodes``: "all" (every support, prescription and the pin of
        the node) or dof names (the supports along exactly those directions). A name with
        nothing to release is refused."""
        for n in self._nodes(nodes):
            if isinstance(dofs, str) and dofs == "all":
                self.supports.release(n)
                continue
            for name in self._names(int(n), dofs):
                f, c = self._row(int(n), name)
                if self.supports.release(n, f, c) == 0:
                    raise InputError(f"release: node {n}: expected a support along {name}, found none")
        self._cm = None

    def copy(self) -> "Structure":
        """An independent copy (supports, loads and element sets; the backend is shared)."""
        import copy as _copy
        return _copy.deepcopy(self, memo={id(self.backend): self.backend})

    def point_load(self, nodes, *, force=(0.0, 0.0, 0.0), moment=None, case: str = "default") -> None:
        """Point force [N] (3,) on each of ``nodes`` and optional moment [N m] (3,): on a 5-dof
        node its components along the node's reference V_1, V_2 (the moment follows the node's
        triad; a shell node takes no moment about its director), on a 6-dof node about x, y, z.
        ``case``: the load case (:meth:`combine`)."""
        nodes = self._nodes(nodes)
        force = np.asarray(force, dtype=float)
        if force.shape != (3,) or not np.all(np.isfinite(force)):
            raise InputError(f"point load: expected a finite force of 3 components, found {force!r}")
        c = self.loads.case(case)
        np.add.at(c.force, self.dofmap.translation_dofs(nodes).ravel(), np.tile(force, nodes.size))
        if moment is not None:
            m = np.asarray(moment, dtype=float)
            if m.shape != (3,) or not np.all(np.isfinite(m)):
                raise InputError(f"point load: expected a finite moment of 3 components, found {moment!r}")
            bad = nodes[self.dofmap.counts[nodes] == 3]
            if bad.size:
                raise InputError(f"point load: nodes {bad[:5].tolist()} have no rotations; a moment needs "
                                 f"5 or 6 dofs")
            c.moments += [(int(n), m) for n in nodes]

    def _moment_vector(self, moments) -> np.ndarray:
        """Generalized forces of point moments [(node, m)]: m . V_1, m . V_2 of the reference
        triads at 5-dof nodes (read when solving, after every add_shell), m at 6-dof nodes."""
        f = np.zeros(self.dofmap.ndof)
        for n, m in moments:
            o = self.dofmap.offset[n] + 3
            if self.dofmap.counts[n] == 5:
                f[o:o + 2] += self.frames[n][:, :2].T @ m
            else:
                f[o:o + 3] += m
        return f

    def _lines(self, where) -> np.ndarray:
        """Line elements (k, ne) of a line load: a (2, ne) or (4, ne) array, a beam element set
        (its elements), or nodes (indices, mask, set name) whose shell element edges (both ends
        in the set) carry it."""
        if isinstance(where, BeamElement):
            return where.beams.conn
        if not isinstance(where, str):
            arr = np.asarray(where)
            if arr.ndim == 2 and arr.dtype != bool:
                if arr.shape[0] not in (2, 4):
                    raise InputError(f"line load: expected lines of shape (2 or 4, ne), found {arr.shape}")
                self.dofmap.check_element_nodes(arr, int(self.dofmap.counts[arr.ravel()[0]]), element="line load",
                                                dofs="the same number of dofs")
                return arr.astype(np.int64)
        nodes = self._nodes(where)
        inside = np.zeros(self.n_nodes, bool)
        inside[nodes] = True
        edges = np.hstack([np.vstack([sh.conn[k], sh.conn[(k + 1) % 4]]) for sh in self.shells for k in range(4)]) \
            if self.shells else np.zeros((2, 0), np.int64)
        edges = edges[:, inside[edges].all(axis=0)]
        edges = np.unique(np.sort(edges, axis=0), axis=1)
        if edges.shape[1] == 0:
            raise InputError(f"line load: expected shell element edges with both nodes among the {nodes.size} "
                             f"given nodes, found none (give the lines as a (2, ne) array)")
        return edges

    def line_load(self, where, q, *, follower: bool = False, case: str = "default") -> None:
        """Line load along ``where`` (shell edges between the given nodes or a set name, a (2,
        ne) array of edges, a (4, ne) beam connectivity or a beam element set), as consistent
        nodal forces (:mod:`tmfem.fem.structure.loads`): dead, q [N/m] (3,) or q(x, y, z) ->
        (3, m) per unit reference length; or ``follower``, q [N/m] per unit current length
        along the current shell director; on beam elements, q [N/m] (3,) per unit current length of
        the axis, given in global axes in the reference configuration and turned with the
        sections (a load normal to the axis stays normal to it; :class:`BeamFollowerLoad`)."""
        lines = self._lines(where)
        if follower and lines.shape[0] == 4:
            ld = BeamFollowerLoad(lines=lines, dofmap=self.dofmap, q=q)
        else:
            ld = LineLoad(X=self.X, lines=lines, dofmap=self.dofmap, q=q, follower=follower, frames=self.frames)
        c = self.loads.case(case)
        if follower:
            c.loads.append(ld)
        else:
            c.force += ld.load(None)[0]

    def gravity(self, g=(0.0, 0.0, -9.81), *, case: str = "default") -> None:
        """Body load of every element set's mass in the acceleration field g [m/s^2] (3,):
        f = M a_g with a_g = g on every translation (consistent: f_k = int rho h_k g dV; the
        rotary inertia takes no part). Add the elements first."""
        g = np.asarray(g, dtype=float)
        if g.shape != (3,) or not np.all(np.isfinite(g)):
            raise InputError(f"gravity: expected a finite acceleration of 3 components, found {g!r}")
        if not self.elements:
            raise InputError("gravity: expected element sets (add them first), found none")
        a = np.zeros(self.dofmap.ndof)
        a[self.dofmap.translation_dofs(np.arange(self.n_nodes))] = g
        f = self.mass() @ a
        if not np.any(f):
            raise InputError("gravity: expected element sets with mass (rho > 0), found a massless model")
        self.loads.case(case).force += f

    def surface_load(self, q, *, elements=None, shell: int = 0, case: str = "default") -> None:
        """Dead distributed load q [N/m^2] (3,) per unit reference mid-surface area, as
        consistent nodal forces f_k = int h_k q dA."""
        if not self.shells:
            raise InputError("surface load: expected a shell element set, found none")
        q = np.asarray(q, dtype=float)
        if q.shape != (3,):
            raise InputError(f"surface load: expected a load of 3 components, found {q.shape}")
        sh = self.shells[shell]
        conn = sh.conn if elements is None else sh.conn[:, np.asarray(elements)]
        dA = ShellPressure(X=self.X, conn=conn, dofmap=self.dofmap, p=1.0, follower=False).nodal_areas()
        np.add.at(self.loads.case(case).force, self.dofmap.translation_dofs(conn.ravel()),
                  dA.ravel()[:, None] * q[None, :])

    def pressure(self, p, *, elements=None, shell: int = 0, follower: bool = True,
                 case: str = "default") -> ShellPressure:
        """Pressure p [Pa] on the elements of a shell set (all by default), along the element
        normal (the directors' side); ``follower`` acts on the current surface."""
        if not self.shells:
            raise InputError("pressure: expected a shell element set, found none")
        sh = self.shells[shell]
        conn = sh.conn if elements is None else sh.conn[:, np.asarray(elements)]
        pl = ShellPressure(X=self.X, conn=conn, dofmap=self.dofmap, p=p, follower=follower)
        self.loads.case(case).loads.append(pl)
        return pl

    def combine(self, **factors) -> None:
        """Load combination: the live load is sum_c factors[c] F_c over the named load cases
        (others 0), e.g. ``combine(dead=1.35, live=1.5)``; ``combine()``: every case with 1."""
        self.loads.combine(factors)

    def freeze_loads(self) -> None:
        """Make the (combined) loads defined so far a constant base load (no longer scaled by
        the load factor) and the prescribed displacements reached so far permanent: the loads
        defined next are the live load of the following :meth:`solve` (prestress, then load)."""
        self.loads.freeze(self._moment_vector)
        self.supports.freeze()
        self._cm = None

    # ------------------------------------------------------------------ equations
    @property
    def constraints(self) -> ConstraintMap:
        """The constraint map of the supports, prescriptions and pins
        (:meth:`tmfem.fem.structure.supports.Supports.build`)."""
        if self._cm is None:
            self._cm = self.supports.build()
        return self._cm[0]

    @property
    def _prescribed(self) -> np.ndarray:
        """Full prescribed displacement at load factor 1 (ndof,)."""
        if self._cm is None:
            self._cm = self.supports.build()
        return self._cm[1]

    def reference_state(self) -> State:
        """The undeformed state."""
        return State.reference(self.X, self.dofmap, frames=self.frames)

    def state_from_positions(self, x, *, lam: float = 0.0) -> StructureState:
        """A state at nodal positions x (3, n_nodes) (e.g. the equilibrium of a membrane model
        of the same mesh): every shell node's director is turned by the smallest rotation onto
        the normal of the surface through x (averaged element normals), other nodes keep their
        orientation. A start for Newton, not an equilibrium."""
        from tmfem.fem.mitc4 import nodal_normals
        x = np.asarray(x, dtype=float)
        if x.shape != self.X.shape:
            raise InputError(f"state from positions: expected shape {self.X.shape}, found {x.shape}")
        st = self.reference_state()
        R = st.R
        for sh in self.shells:
            R[sh.nodes] = smallest_rotation(self.frames[sh.nodes][:, :, 2].T,
                                            nodal_normals(x, sh.conn)[:, sh.nodes])
        return StructureState(state=State(x=x.copy(), R=R, frames=self.frames), lam=lam)

    def _load_part(self, state: State, *, live: bool, tangent: bool = True):
        """The live loads at load factor 1 (point, moment, line, body, pressure) or the base
        loads (:meth:`freeze_loads`) at ``state``, and their load stiffness d f / d u."""
        if live:
            return self.loads.live(state, self._moment_vector, tangent=tangent)
        return self.loads.base(state, tangent=tangent)

    def external(self, state: State, lam: float, *, tangent: bool = True):
        """External force F_base + lam F_live(state) and its load stiffness (base loads:
        :meth:`freeze_loads`)."""
        fb, Kb = self._load_part(state, live=False, tangent=tangent)
        fl, Kl = self._load_part(state, live=True, tangent=tangent)
        K = Kb if Kl is None else (lam * Kl if Kb is None else Kb + lam * Kl)
        return fb + lam * fl, K

    def residual(self, state: State, lam: float):
        """Reduced residual T^T (f_int - f_ext) and tangent T^T (K - K_load) T."""
        if not self.elements:
            raise InputError("structure: expected at least one element set, found none")
        cm = self.constraints
        f, K = assemble(self.elements, state)
        fe, Ke = self.external(state, lam)
        if Ke is not None:
            K = K - Ke
        return cm.residual(f - fe), cm.tangent(K)

    def advance(self, s: State, du) -> State:
        """The state after the reduced increment du (translations added, rotations by the
        exponential map): the ``update=`` of the solvers of :mod:`tmfem.solvers.newton`."""
        return s.advanced(self.constraints.full(du), self.dofmap)

    def _with_prescribed(self, s: State, dlam: float) -> State:
        if dlam == 0.0 or not np.any(self._prescribed):
            return s
        return s.advanced(dlam * self._prescribed, self.dofmap)

    def _scale(self) -> float:
        f0, _ = self.external(self.reference_state(), 1.0, tangent=False)
        fb, _ = self.external(self.reference_state(), 0.0, tangent=False)
        sc = float(np.linalg.norm(self.constraints.residual(f0 - fb)[self.constraints.free]))
        if np.any(self._prescribed):
            r, _ = self.residual(self._with_prescribed(self.reference_state(), 1.0), 0.0)
            sc = max(sc, float(np.linalg.norm(r[self.constraints.free])))
        if sc == 0.0:
            raise InputError("structure: expected loads or prescribed displacements, found none")
        return sc

    # ------------------------------------------------------------------ solvers
    def solve_linear(self) -> StructureState:
        """Linear statics about the reference state: K0 u = F (pressure on the reference
        surface, prescribed displacements at their values). Rotations are applied as finite
        rotations of the small solution (for output). Solved with Jacobi equilibration."""
        cm = self.constraints
        s0 = self.reference_state()
        r, K = self.residual(self._with_prescribed(s0, 0.0), 0.0)
        idx = np.flatnonzero(cm.free)
        f0, _ = self.external(s0, 1.0, tangent=False)
        rhs = cm.residual(f0)
        up = cm.reduce(self._prescribed) if np.any(self._prescribed) else np.zeros(cm.n_reduced)
        rhs = rhs - K @ up
        u = up.copy()
        solve = factorize(K[idx][:, idx], self.backend, equilibrate=True)
        ratio = getattr(solve, "pivot_ratio", None)       # the dense path checks it itself
        if ratio is not None and ratio <= SINGULAR_PIVOT_RATIO:
            raise SingularMatrix(f"structure: linear statics: expected supports that hold every "
                                 f"rigid-body motion and no mechanism, found a singular stiffness "
                                 f"(smallest/largest pivot {ratio:.1e} of the equilibrated matrix; "
                                 "fix, symmetry or pin more dofs)")
        u[idx] = solve(rhs[idx])
        return StructureState(state=s0.advanced(cm.full(u), self.dofmap), lam=1.0, iterations=1,
                              reaction=self._reaction(K @ u - cm.residual(f0)), linear=True,
                              increment=cm.full(u))

    #: scale of the displacement at which the stresses of a linear solution are evaluated
    _LINEAR_PROBE = 1e-6

    def _stress_state(self, st: StructureState) -> tuple[State, float]:
        """The state the stresses of ``st`` are evaluated at and the factor to multiply them
        by: a linear solution's stresses are the linear part of the strain, taken at the
        displacement scaled by 1e-6 (the Green-Lagrange terms quadratic in it vanish to
        1e-6 relative) and scaled back; a nonlinear state as it is."""
        if st.linear and st.increment is not None:
            probe = self.reference_state().advanced(self._LINEAR_PROBE * st.increment, self.dofmap)
            return probe, 1 / self._LINEAR_PROBE
        return st.state, 1.0

    def _reaction(self, r_red: np.ndarray) -> np.ndarray:
        """Generalized reactions (ndof,) from a reduced residual T^T (f_int - f_ext)."""
        cm = self.constraints
        return cm.independent(np.where(cm.free, 0.0, r_red))

    def reactions(self, st: StructureState, *, frame: str = "global") -> Reactions:
        """Support reactions of the solution ``st`` (:mod:`tmfem.fem.structure.reactions`):
        force [N] and moment [N m] per node, in global axes or (``frame="local"``) in each
        node's local axes (:meth:`local_frame`). Computed by the solve; for a state made
        otherwise, from the residual T^T (f_int - f_ext) at ``st``."""
        if frame not in ("global", "local"):
            raise InputError(f"reactions: expected frame 'global' or 'local', found {frame!r}")
        g = st.reaction
        if g is None:
            g = self._reaction(self.residual(st.state, st.lam)[0])
        at = self.reference_state() if st.linear else st.state
        f, m = nodal_vectors(g, at, self.dofmap)
        if frame == "local":
            f, m = np.einsum("nki,kn->in", self.axes, f), np.einsum("nki,kn->in", self.axes, m)
        return Reactions(force=f, moment=m, x=at.x, frame=frame)

    def applied(self, st: StructureState) -> tuple[np.ndarray, np.ndarray]:
        """Applied nodal forces [N] (3, n) and moments [N m] (3, n) at ``st`` (point loads,
        pressures on the current surface, base loads), global axes: with :meth:`reactions`
        the free-body check sum R + sum F = 0."""
        at = self.reference_state() if st.linear else st.state
        f, _ = self.external(at, 1.0 if st.linear else st.lam, tangent=False)
        return nodal_vectors(f, at, self.dofmap)

    def resultant(self, st: StructureState, nodes=None, *, about=(0.0, 0.0, 0.0)):
        """Resultant force [N] (3,) and moment [N m] (3,) about ``about`` of the reactions at
        ``nodes`` (indices, mask or a :meth:`node_set` name; default all)."""
        return self.reactions(st).resultant(None if nodes is None else self._nodes(nodes), about=about)

    def _system(self, state: State, lam: float):
        """(r, K, q) of :func:`tmfem.solvers.continuation.follow`: the reduced residual
        T^T (f_int - f_base - lam f_live), its tangent and q = T^T f_live(state)."""
        cm = self.constraints
        f, K = assemble(self.elements, state)
        fb, Kb = self._load_part(state, live=False)
        fl, Kl = self._load_part(state, live=True)
        for Kp, c in ((Kb, 1.0), (Kl, lam)):
            if Kp is not None:
                K = K - c * Kp
        return cm.residual(f - fb - lam * fl), cm.tangent(K), cm.residual(fl)

    def _stability(self, state: State, lam: float) -> int | None:
        _, K = self.residual(state, lam)
        return negative_pivots(submatrix(K, np.flatnonzero(self.constraints.free)))

    def solve(self, *, steps: int = 10, lam_end: float = 1.0, tol: float = 1e-8, max_iter: int = 30,
              line_search: bool = False, min_step: float = 1e-4, start=None, callback=None,
              equilibrate: bool = True, stability: bool = False, snap_ratio: float = 2.5,
              on_snap: str = "stop") -> Path:
        """Load control: from ``start`` (a state or a :class:`Path`, default the reference
        state at lam = 0) to ``lam_end`` in ``steps`` equal increments of the load factor,
        which scales the live loads and the prescribed displacements together; Newton at
        every step (eq. 4.6); a failed step is retried in halves down to ``min_step``.

        Newton converges when ||r|| <= tol * scale, scale = ||F(lam = 1)|| (or the reaction
        of the prescribed displacements). ``line_search`` is off by default: the residual norm
        is a poor merit function for bending-dominated shells (a linear predictor stretches
        the mid-surface), and the full Newton step converges. ``equilibrate``: Jacobi-scaled
        solves (docs/guides/shells.md, thin shells). ``stability``: count the negative pivots of the
        tangent at every converged step (a bifurcation indicator; an extra factorization).

        Snap-through: a load step that passes a limit point may still converge, on a distant
        branch (the jump of a snap-through, not a path). A step whose displacement per load
        increment, ||Dx|| / |Dlam| (nodal positions), exceeds ``snap_ratio`` times that of the
        previous step (the first step: always) is checked: Newton from its state at the
        previous load factor must return to the previous state; when it converges elsewhere,
        two equilibria at that load bound a limit point (:meth:`_snapped`). ``on_snap="stop"``
        ends the run there with the reason "limit point" (the jumped state is not part of the
        path; ``solve_arc_length(start=path)`` continues through the limit point); ``"mark"``
        keeps the jumped state with the event "snap-through" and goes on.

        Returns a :class:`Path` of every converged state (the start included) that says why
        it stopped: "completed", "limit point" (a snap-through detected, or a step failed
        below ``min_step`` with more negative pivots at the failed iterate than at the last
        converged state) or "divergence".
        """
        if not (isinstance(steps, (int, np.integer)) and steps >= 1):
            raise InputError(f"solve: expected steps >= 1, found {steps!r}")
        if on_snap not in ("stop", "mark"):
            raise InputError(f"solve: expected on_snap 'stop' or 'mark', found {on_snap!r}")
        if not (isinstance(snap_ratio, (int, float, np.number)) and np.isfinite(snap_ratio) and snap_ratio > 1):
            raise InputError(f"solve: expected snap_ratio > 1, found {snap_ratio!r}")
        controls = dict(steps=steps, lam_end=lam_end, tol=tol, max_iter=max_iter, line_search=line_search,
                        min_step=min_step, equilibrate=equilibrate, stability=stability, snap_ratio=snap_ratio,
                        on_snap=on_snap)
        scale = self._scale()
        cur = self._start(start)
        out = [cur]
        dlam = (lam_end - cur.lam) / steps
        lam = cur.lam
        flex = None                                       # ||Dx|| / |Dlam| of the last step
        reason, message = "completed", f"load factor {lam_end:g} reached"

        def equilibrium(s, at):
            return newton(lambda u: self.residual(u, at), s, free=self.constraints.free, tol=tol, scale=scale,
                          max_iter=max_iter, line_search=line_search, load_factor=at, update=self.advance,
                          equilibrate=equilibrate, backend=self.backend)
        while (lam_end - lam) * np.sign(dlam) > 1e-12 * abs(lam_end):
            d = dlam if abs(dlam) <= abs(lam_end - lam) else lam_end - lam
            target = lam + d
            try:
                res = equilibrium(self._with_prescribed(cur.state, d), target)
            except ConvergenceError as exc:
                dlam = 0.5 * d
                log.info("structure: step to lam = %g failed (%s); halving", target, exc)
                if abs(dlam) < min_step:
                    before = cur.negative_pivots if cur.negative_pivots is not None else \
                        self._stability(cur.state, cur.lam)
                    failed = getattr(exc, "u", None)
                    after = self._stability(failed, target) if isinstance(failed, State) else None
                    limit = before is not None and after is not None and after > before
                    reason = "limit point" if limit else "divergence"
                    message = (f"stuck at load factor {lam:g} on the way to {lam_end:g} (increment {abs(d):.2e} "
                               f"failed, below min_step {min_step:g})"
                               + (f"; negative pivots {before} -> {after}: continue with solve_arc_length"
                                  if limit else "") + f": {exc}")
                    log.warning("structure: load control stopped (%s): %s", reason, message)
                    break
                continue
            step = float(np.linalg.norm(res.u.x - cur.state.x)) / abs(d)
            snapped = (flex is None or step > snap_ratio * flex) and self._snapped(res.u, cur, -d, equilibrium)
            flex = step
            if snapped and on_snap == "stop":
                reason = "limit point"
                message = (f"snap-through between load factors {lam:g} and {target:g}: the step converged on a "
                           f"distant branch ({step * abs(d):.3g} of nodal displacement; Newton from there at "
                           f"{lam:g} stays on it); continue with solve_arc_length(start=path)")
                log.warning("structure: load control stopped (%s): %s", reason, message)
                break
            lam = target
            piv = self._stability(res.u, lam) if stability else None
            event = "snap-through" if snapped else (
                "bifurcation" if piv is not None and cur.negative_pivots is not None
                and piv != cur.negative_pivots else None)
            cur = StructureState(state=res.u, lam=lam, iterations=res.iterations,
                                 residual_history=res.residual_history, reaction=self._reaction(res.r),
                                 negative_pivots=piv, event=event)
            out.append(cur)
            if callback is not None:
                callback(cur)
        return Path(out, method="load", controls=controls, reason=reason, message=message)

    def _snapped(self, new: State, prev: StructureState, back: float, equilibrium) -> bool:
        """True when Newton from the converged state ``new`` at the previous load factor
        (prescribed displacements moved back by ``back``) converges to an equilibrium other
        than ``prev`` (farther from it than half the step): the load step jumped across a limit
        point. A failed check (no convergence) counts as no evidence."""
        try:
            res = equilibrium(self._with_prescribed(new, back), prev.lam)
        except ConvergenceError:
            return False
        dist = float(np.linalg.norm(res.u.x - prev.state.x))
        return dist > 0.5 * float(np.linalg.norm(new.x - prev.state.x))

    def _start(self, start) -> StructureState:
        if start is None:
            return StructureState(state=self.reference_state(), lam=0.0)
        return start[-1] if isinstance(start, Path) else start

    def _follow(self, method: str, *, start, controls: dict, **kwargs) -> Path:
        if np.any(self._prescribed):
            raise InputError(f"{method}: expected no prescribed displacements to reach (they belong "
                             f"to load control, solve()), found some; freeze_loads() makes them permanent")
        cur = self._start(start)
        cont = {}
        if isinstance(start, Path) and start.method == method:
            cont = dict(start_increment=start.increment, start_pivots=start[-1].negative_pivots)
        scale = float(np.linalg.norm(self._system(cur.state, cur.lam)[2][self.constraints.free]))
        if scale == 0.0:
            raise InputError(f"{method}: expected live loads (point, pressure, line, body), found none")
        res = follow(self._system, cur.state, lam0=cur.lam, free=self.constraints.free, method=method,
                     update=self.advance, backend=self.backend, scale=scale, **cont, **kwargs)
        states = [cur]
        for s, info in zip(res.u[1:], res.steps[1:]):
            states.append(StructureState(state=s, lam=info.lam, iterations=info.iterations,
                                         residual_history=info.residuals, negative_pivots=info.negative_pivots,
                                         event=info.event))
        if cur.negative_pivots is None:
            cur.negative_pivots = res.steps[0].negative_pivots
        return Path(states, method=method, controls=controls, reason=res.reason, message=res.message,
                    increment=res.increment, dl=res.dl)

    def solve_arc_length(self, *, dl: float, max_steps: int = 50, lam_max: float | None = None,
                         psi: float = 0.0, tol: float = 1e-8, max_iter: int = 25, target_iter: int = 5,
                         dl_min: float | None = None, dl_max: float | None = None, growth: float = 2.0,
                         cutback: float = 0.5, stability: bool = True, stop_at=(), stop=None,
                         start=None, equilibrate: bool = True, n_steps: int | None = None) -> Path:
        """Arc-length continuation (Crisfield; :mod:`tmfem.solvers.continuation`) of the live
        loads (point, line, body loads and pressures, dead or follower) from ``start`` (an
        equilibrium; default the reference state; a :class:`Path` of an arc-length run is
        continued in its direction with its arc).

        Controls: ``dl`` first arc (2-norm of the step's increment over the free dofs [m and
        rad], plus psi^2 Dlam^2 |q|^2); ``psi`` load term (0: cylindrical); ``max_steps``
        budget (``n_steps`` is its old name); ``lam_max`` target load factor; ``tol``
        residual tolerance relative to |q|; ``max_iter`` Newton iterations per step;
        ``target_iter``, ``growth``, ``cutback``, ``dl_min``, ``dl_max`` arc adaptation
        (dl (target_iter/iterations)^(1/2), limited per step to [cutback, growth] times dl
        and to [dl_min, dl_max], default [1e-4, 10] dl; a failed step is retried with
        cutback dl); ``stability`` negative pivot count per step; ``stop_at`` events that
        stop the run ("limit point", "bifurcation"); ``stop(state, lam)`` a user stop.
        Returns a :class:`Path` with every converged state and the reason it stopped.
        """
        if n_steps is not None:
            max_steps = n_steps
        controls = dict(dl=dl, max_steps=max_steps, lam_max=lam_max, psi=psi, tol=tol, max_iter=max_iter,
                        target_iter=target_iter, dl_min=dl_min, dl_max=dl_max, growth=growth, cutback=cutback,
                        stability=stability, stop_at=stop_at, stop=stop, equilibrate=equilibrate)
        if isinstance(start, Path) and start.method == "arc-length" and start.dl is not None:
            dl = start.dl
        kw = {k: v for k, v in controls.items() if k != "dl"}
        return self._follow("arc-length", start=start, controls=controls, dl=dl, **kw)

    def solve_displacement_control(self, *, node: int, dof: str, increment: float, target: float | None = None,
                                   max_steps: int = 50, tol: float = 1e-8, max_iter: int = 25,
                                   target_iter: int = 5, growth: float = 1.0, cutback: float = 0.5,
                                   stability: bool = True, stop_at=(), stop=None, start=None,
                                   equilibrate: bool = True) -> Path:
        """Displacement control (Batoz & Dhatt): the dof ``dof`` (a name of :meth:`fix`) of
        ``node`` advances by ``increment`` [m or rad] per step and the load factor of the live
        loads follows, through load maxima, up to the displacement ``target`` from the start
        (the last step lands on it) or ``max_steps`` steps. ``growth`` > 1 lets the increment
        grow after easy steps (as the arc of :meth:`solve_arc_length`); ``cutback`` halves a
        failed one. Other controls as :meth:`solve_arc_length`. Returns a :class:`Path`."""
        if target is not None and target * increment <= 0:
            raise InputError(f"displacement control: expected a target on the side of the increment "
                             f"{increment:g}, found {target!r}")
        (n,) = self._nodes([node])
        (name,) = self._names(int(n), dof)
        f, c = self._row(int(n), name)
        k = int(np.argmax(np.abs(c)))
        if abs(abs(c[k]) - 1) > 1e-12:
            raise InputError(f"displacement control: expected a dof along a global axis (or r1, r2), found {name} "
                             f"along {np.round(c, 3).tolist()} (the node's local frame)")
        full = int(self.dofmap.offset[n] + (k if f == "u" else 3 + k))
        cm = self.constraints
        red = int(cm.reduced_of[full])
        if red < 0 or not cm.free[red] or (cm.L is not None and abs(abs(cm.L[red, red]) - 1) > 1e-12):
            raise InputError(f"displacement control: expected a free dof, found {name} of node {n} constrained")
        sign = float(np.sign(cm.L[red, red])) if cm.L is not None else 1.0
        controls = dict(node=int(n), dof=dof, increment=increment, target=target, max_steps=max_steps, tol=tol,
                        max_iter=max_iter, target_iter=target_iter, growth=growth, cutback=cutback,
                        stability=stability, stop_at=stop_at, stop=stop, equilibrate=equilibrate)
        done = 0.0
        if isinstance(start, Path) and start.method == "displacement" and target is not None:
            done = float(np.sign(c[k]) * (self.displacements(start[-1]) - self.displacements(start[0]))[k, n]) \
                if f == "u" else 0.0
        return self._follow("displacement", start=start, controls=controls, dl=sign * increment,
                            control=red, u_target=None if target is None else sign * (target - done),
                            max_steps=max_steps, tol=tol, max_iter=max_iter, target_iter=target_iter,
                            dl_max=abs(increment) * max(growth, 1.0) ** 10, growth=growth, cutback=cutback,
                            stability=stability, stop_at=stop_at, stop=stop, equilibrate=equilibrate)

    def resume(self, path: Path, **changes) -> Path:
        """Continue a stopped run where it stopped, with its method and controls (``changes``
        override some, e.g. ``max_steps=`` or ``lam_max=``); returns the whole path, the
        states of ``path`` first."""
        method = {"load": self.solve, "arc-length": self.solve_arc_length,
                  "displacement": self.solve_displacement_control}[path.method]
        kw = {**path.controls, **changes}
        more = method(start=path, **kw)
        return Path(list(path) + list(more[1:]), method=more.method, controls=kw, reason=more.reason,
                    message=more.message, increment=more.increment, dl=more.dl)

    def mass(self, state: State | None = None) -> sp.csr_matrix:
        """Mass matrix (ndof, ndof): sum of the element sets' masses (shell and beam rotary
        inertia mapped with the triads of ``state``)."""
        return sum(e.mass(state) for e in self.elements)

    def modes(self, *, k: int = 6, at: StructureState | None = None):
        """Lowest k modes about ``at`` (default: the reference state) with the tangent there
        (prestress and load stiffness included, eq. 5.32; the symmetric part where a follower
        pressure makes it non-symmetric); shapes in full dofs."""
        st = at or StructureState(state=self.reference_state(), lam=0.0)
        _, K = self.residual(st.state, st.lam)
        K = 0.5 * (K + K.T).tocsr()
        cm = self.constraints
        M = cm.tangent(self.mass(st.state))
        m = lowest_modes(K, M, k=k, free=cm.free, backend=self.backend)
        m.shapes = np.asarray(cm.T @ m.shapes)
        return m

    # ------------------------------------------------------------------ results
    def displacements(self, st: StructureState) -> np.ndarray:
        """Nodal displacements (3, n_nodes)."""
        return st.state.x - self.X

    def rotation_vectors(self, st: StructureState) -> np.ndarray:
        """Nodal rotation vectors (3, n_nodes) [rad] of R (axis times angle; zero at 3-dof nodes)."""
        from scipy.spatial.transform import Rotation
        if st.state.R is None:
            return np.zeros((3, self.n_nodes))
        return Rotation.from_matrix(st.state.R).as_rotvec().T

    def stresses(self, st: StructureState) -> dict:
        """Nodal results of ``st`` (:mod:`tmfem.fem.structure.results`): for the shells the
        Gauss-point stresses extrapolated to the nodes and averaged, ``sigma_<s>`` (n, 5)
        [s11, s22, s12, s13, s23] [Pa], ``principal_<s>`` (n, 2) and ``von_mises_<s>`` (n,)
        [Pa] at s = bottom, mid, top, ``N`` [N/m], ``M`` [N m/m], ``Q`` [N/m]; for the beams
        ``beam_N``, ``beam_Q1``, ``beam_Q2`` [N], ``beam_M1``, ``beam_M2``, ``beam_T`` [N m].
        NaN at nodes outside the element sets; where two sets share a node, the last wins."""
        out = {}
        at, c = self._stress_state(st)
        for e in self.elements:
            if isinstance(e, MITC4Shell):
                part = shell_nodal_results(e, at, self.n_nodes)
            elif isinstance(e, BeamElement):
                part = {f"beam_{k}": v for k, v in beam_nodal_section_forces(e, at, self.n_nodes).items()}
            else:
                continue
            for k, v in part.items():
                v = c * v
                out[k] = v if k not in out else np.where(np.isnan(v), out[k], v)
        return out

    def to_meshio(self, st: StructureState, *, deformed: bool = False):
        """A ``meshio.Mesh`` of the shells' quads and the beams' axis segments (reference or
        deformed points). Point data: ``displacement`` [m] (from the reference configuration,
        inertial frame: a generic structure has no floating frame, so this is not the
        tensegrity membrane's ``displacement_Of`` of :data:`tmfem.io.fields.DISPLACEMENT_FIELD`),
        ``rotation`` [rad] and ``director``, ``reaction_force [N]``, ``reaction_moment [N m]``
        and the nodal results of :meth:`stresses` with their units in the name (``N [N/m]``,
        ``sigma_top [Pa]``, ``beam_M1 [N m]``, ...). Cell data of the shells (element centre):
        ``N`` (membrane forces N11 N22 N12 [N/m]), ``M`` (bending moments M11 M22 M12 [N m/m]),
        ``Q`` (shear forces [N/m]) and ``von_mises_bottom/mid/top`` [Pa] (local 2nd
        Piola-Kirchhoff stresses, frame of eq. 4.16); the beams' cells hold NaN there."""
        import meshio
        beams = [e for e in self.elements if isinstance(e, BeamElement)]
        if not self.shells and not beams:
            raise InputError("to_meshio: expected a shell or beam element set, found none")
        pts = (st.state.x if deformed else self.X).T
        u = self.displacements(st).T
        Vn = np.einsum("nij,nj->ni", st.state.R, self.frames[:, :, 2]) if st.state.R is not None else None
        keys = {"N": 3, "M": 3, "Q": 2, "von_mises_bottom": 0, "von_mises_mid": 0, "von_mises_top": 0}
        cells, cd = [], {k: [] for k in keys}
        at, c = self._stress_state(st)
        for sh in self.shells:
            cells.append(("quad", sh.conn.T))
            r = sh.stresses(at)
            cd["N"].append(c * r["N"])
            cd["M"].append(c * r["M"])
            cd["Q"].append(c * r["Qs"])
            for j, name in enumerate(("bottom", "mid", "top")):
                cd[f"von_mises_{name}"].append(c * r["von_mises"][:, j])
        for b in beams:
            seg = np.vstack([b.beams.conn[:-1].T.ravel(), b.beams.conn[1:].T.ravel()]).T
            cells.append(("line", seg))
            for k, width in keys.items():
                cd[k].append(np.full((seg.shape[0], width) if width else seg.shape[0], np.nan))
        reac = self.reactions(st)
        point_data = {"displacement": u, "rotation": self.rotation_vectors(st).T,
                      "reaction_force [N]": reac.force.T, "reaction_moment [N m]": reac.moment.T}
        if Vn is not None:
            point_data["director"] = Vn
        for k, v in self.stresses(st).items():
            point_data[f"{k} [{_UNITS[k.split('_')[0] if k.startswith(('sigma', 'principal', 'von')) else k]}]"] = v
        return meshio.Mesh(points=pts, cells=cells, point_data=point_data, cell_data=cd)


#: units of the nodal result fields of :meth:`Structure.stresses`
_UNITS = {"sigma": "Pa", "principal": "Pa", "von": "Pa", "N": "N/m", "M": "N m/m", "Q": "N/m",
          "beam_N": "N", "beam_Q1": "N", "beam_Q2": "N", "beam_M1": "N m", "beam_M2": "N m", "beam_T": "N m"}
