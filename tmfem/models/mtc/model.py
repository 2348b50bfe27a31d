"""The membrane-truss-cable (MTC) model of a tensegrity-membrane system (dissertation 4.4, 6.2-6.4).

Built from a :class:`~tmfem.system.System`: the membrane is the flat polygon meshed by
``polygon_quad_mesh`` (N quadrilaterals of n x n four-node total-Lagrangian membrane elements,
4.4.1); every bar is one two-node truss (assumption b of 4.4: axial deformation only, EA and
rho A of ``system.bar``); every tendon is ``k`` tension-only truss elements with ``k - 1``
internal nodes carrying its mass, reference length = rest length / k. The bar bases A_1j are
pinned (their three translations fixed) and nothing else is constrained: the top membrane
floats on the bar tops, which are the membrane corners (``attachment="point"``), or the
weighted centroids of small corner patches (``attachment="distributed"``, see
:mod:`tmfem.models.mtc.topology`).

Statics (6.2) start from the *undeformed* membrane (flat, unstressed, placed in the plane of
the design bar tops) and let the rest lengths pull the system into equilibrium. That start is
singular twice over: an unstressed flat membrane has no transverse stiffness and the bars
pinned at their bases form a mechanism until the tendons and membrane are stressed. The
solver is Newton's method regularised by pseudo-transient continuation,

    (K_T + M / dt^2) du = -r,      dt^2 <- dt^2 |r_prev| / |r|   (switched evolution relaxation)

with a backtracking line search on |r|; as the residual falls dt grows without bound and the
iteration becomes Newton's, with its quadratic convergence (the test suite checks that the
last steps are Newton steps). Modal analysis solves (K_T - omega^2 M) phi = 0 about the
converged state (eq. 5.32).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.element import State, assemble
from tmfem.fem.membrane import MembraneElement, MembraneTL
from tmfem.fem.truss import TrussElement, TrussSet, truss_internal
from tmfem.models.mtc.design import consistent_rest_lengths, design_mesh_of, design_rest_lengths_at
from tmfem.fem.tension_field import check_law_name
from tmfem.models.mtc.topology import MTCTopology, build_topology, membrane_placement
from tmfem.solvers.backends import get_backend
from tmfem.solvers.eigen import lowest_modes
from tmfem.solvers.trust_region import trust_region_newton
from tmfem.system.topology import label


@dataclass
class StaticResult:
    """Equilibrium of an MTC model and the history of the iteration.

    Attributes
    ----------
    x : ndarray (3, n_nodes)
        Converged positions of all nodes.
    iterations : int
    residual_history : list of float
        Euclidean norm of the free residual [N] after each iteration (first = start).
    monitor : dict
        Label -> array (iterations + 1, 3) of the positions of monitored nodes.
    dt2_history : list of float
        The pseudo-time regularisation dt^2 of each step (inf once it is pure Newton).
    time : float
        Wall time [s].
    newton_iterations_tangent : list of int
        Iterations per level of a mesh-sequenced solve.
    tangent : sparse matrix or DistributedMatrix, optional
        The tangent at the equilibrium, as the last iteration assembled it (the reduced
        T^T K T, or the distributed one on the free dofs): :meth:`MTCModel.modes` reuses it.
    """

    def __repr__(self) -> str:
        return (f"StaticResult({self.x.shape[1]} nodes, {self.iterations} iterations, "
                f"|r| {self.residual_history[0]:.3g} -> {self.residual_history[-1]:.3g} N)")


    x: np.ndarray
    iterations: int
    residual_history: list
    monitor: dict
    dt2_history: list
    time: float
    newton_iterations_tangent: list = field(default_factory=list)
    tangent: object = None


class MTCModel:
    """Membrane-truss-cable model of a ``System`` (4.4, 6.2).

    Parameters
    ----------
    system : System
        An M-N system (1-N(D) systems are rejected: their H_1j nodes need bending bars).
    mesh_n : int
        Membrane elements along each side of the N quadrilaterals (10 -> 4 x 10 x 10 for 1-4).
    tendon_elements : int
        Truss elements per tendon (6.2 uses 3).
    attachment : {"point", "distributed"}
        How the bar tops hold the membrane corners.
    patch : float, optional
        Radius of the distributed attachment patch [m] (default 10 % of r_mb).
    rest_lengths : ndarray or {"system", "design", "design@n", "mtc"}, optional
        Tendon rest lengths. Default: ``system.rest_lengths`` when set, else ``"design"``:
        the ch. 3 design (``tmfem.equilibrium.design_equilibrium``, eq. 3.8) *on this model's
        membrane mesh and corner attachment*, so it changes with ``mesh_n``. ``"design@n"``
        (e.g. ``"design@10"``): the ch. 3 design on the N x n x n mesh with point corners
        (6.2 designs on n = 10), the same rest lengths whatever this model's mesh
        (:func:`tmfem.models.mtc.design.design_rest_lengths_at`). ``"mtc"``: the rest lengths
        for which the design configuration is an exact equilibrium of this model
        (:meth:`consistent_rest_lengths`).
    lumped_tendon_mass : bool
        Lumped instead of consistent truss mass for the tendons (bars always consistent: it
        gives a pinned rigid bar its exact rotary inertia m l^2 / 3).
    backend : str or Backend
        Linear-algebra backend of every factorisation and eigen solve (``"scipy"`` default;
        ``"auto"`` chooses by the free dofs; :func:`tmfem.solvers.get_backend`).
    membrane_law : {"svk", "tension-field"}
        Membrane law (:mod:`tmfem.fem.tension_field`): St.Venant-Kirchhoff (eq. 4.9, default)
        or the tension-field (wrinkling) law. The prestress is the static equilibrium of this
        model, so it passes through the same law.
    rigid_bar_points : bool
        Accept a 1-N(D) system, its H_1j on bars rigid in bending
        (:func:`tmfem.models.mtc.topology.build_topology`): the SBC model's predictor, not
        the dissertation's MTC model.
    tendon_law : {"cable", "fixed-rate"}
        What a change of rest length (:meth:`set_tendon_lengths`, a plant's input) does to a
        tendon. ``"cable"`` (default): a cable reeled in or out, EA fixed, so its spring rate
        follows eq. 3.9, k = EA / r, at the current rest length. ``"fixed-rate"``: the rate
        stays k = EA / r_0 of the nominal rest lengths r_0 (EA scales with r / r_0), the
        control-affine tendon of eq. 5.19 (B(x) u) that the control-oriented model uses.
    """

    def __init__(self, system, *, mesh_n: int = 10, tendon_elements: int = 3,
                 attachment: str = "point", patch: float | None = None, rest_lengths=None,
                 lumped_tendon_mass: bool = False, backend="scipy", membrane_law: str = "svk",
                 rigid_bar_points: bool = False, tendon_law: str = "cable"):
        if tendon_law not in ("cable", "fixed-rate"):
            raise InputError(f"tendon_law: expected 'cable' or 'fixed-rate', found {tendon_law!r}")
        self.tendon_law = tendon_law
        self.system = system
        self.membrane_law = check_law_name(membrane_law)
        self.mesh_n, self.patch = mesh_n, patch
        self.topology: MTCTopology = build_topology(system, mesh_n=mesh_n,
                                                    tendon_elements=tendon_elements,
                                                    attachment=attachment, patch=patch,
                                                    rigid_bar_points=rigid_bar_points)
        topo = self.topology
        self.membrane = MembraneTL(mesh=topo.mesh, material=system.membrane, law=self.membrane_law)
        self.membrane_element = MembraneElement(self.membrane, np.arange(topo.n_mesh), topo.dofmap)
        bar = system.bar
        nb = system.M * system.N
        self.bars = TrussSet(conn=topo.bar_conn, L=system.l.ravel().copy(),
                             EA=np.full(nb, bar.E * bar.area), rhoA=np.full(nb, bar.rho * bar.area),
                             tension_only=np.zeros(nb, dtype=bool))
        secs = [system.tendon_section(t) for t in system.tendons]
        self.tendon_EA = np.array([s.EA for s in secs])
        self.tendon_area = np.array([s.area for s in secs])
        self.tendon_rhoA = np.array([(s.rho or 0.0) * s.area for s in secs])
        self.tendon_yield = np.array([s.yield_stress if s.yield_stress else np.nan for s in secs])
        self.lumped_tendon_mass = lumped_tendon_mass
        self.bar_element = TrussElement(self.bars, topo.dofmap)
        self.free = topo.constraints.free
        self.backend = get_backend(backend, n_dofs=self.ndof)
        self._M = None
        self._dist = None
        self.rest_lengths_source = None
        if rest_lengths is None:
            rest_lengths = "system" if system.rest_lengths is not None else "design"
        self.set_rest_lengths(rest_lengths)

    # ------------------------------------------------------------------ set-up
    def set_rest_lengths(self, rest) -> None:
        """Set the tendon rest lengths: an array (one per tendon) or ``"system"``,
        ``"design"``, ``"design@n"`` or ``"mtc"`` (see the class docstring)."""
        n_t = len(self.system.tendons)
        if isinstance(rest, str):
            source = rest
            if rest == "system":
                if self.system.rest_lengths is None:
                    raise InputError(f"rest_lengths='system': expected rest lengths in system "
                                     f"{self.system.name!r}, found none (use 'design' or 'mtc')")
                r = self.system.rest_lengths
            elif rest == "design":
                r = self._design_rest_lengths()
            elif rest == "mtc":
                if self.system.deployable:
                    raise InputError("rest_lengths='mtc': does not apply to a 1-N(D) system (the "
                                     "consistent rest lengths balance truss bars without points "
                                     "H_1j); expected 'design' (eq. 3.8), 'system' or values")
                r = self.consistent_rest_lengths()["rest_lengths"]
            elif design_mesh_of(rest) is not None:
                r = design_rest_lengths_at(self.system, design_mesh_of(rest))
            else:
                raise InputError(f"rest_lengths: expected an array or one of 'system', 'design', "
                                 f"'design@n' (n >= 1), 'mtc', found {rest!r}")
        else:
            source = "given"
            r = np.asarray(rest, dtype=float)
        r = np.asarray(r, dtype=float)
        if r.shape != (n_t,) or not np.all(np.isfinite(r)) or np.any(r <= 0):
            raise InputError(f"expected {n_t} positive tendon rest lengths, found {r}")
        self.rest_lengths = r
        self.nominal_rest_lengths = r.copy()
        self.rest_lengths_source = source
        self._set_tendons(r)

    def _set_tendons(self, r) -> None:
        k = self.topology.tendon_elements
        e = self.topology.tendon_of_element
        self.tendons = TrussSet(conn=self.topology.tendon_conn, L=r[e] / k, EA=self.tendon_EA[e],
                                rhoA=self.tendon_rhoA[e], tension_only=np.ones(e.size, dtype=bool))
        self.tendon_element = TrussElement(self.tendons, self.topology.dofmap,
                                           lumped_mass=self.lumped_tendon_mass)
        self._M = None
        self._dist = None

    def set_tendon_lengths(self, u) -> None:
        """Tendon rest lengths as time-varying inputs (a plant's u): the reference lengths of
        the tendon elements become u / k in place (no re-assembly of patterns)."""
        u = np.asarray(u, dtype=float)
        if u.shape != self.rest_lengths.shape or not np.all(u > 0):
            raise InputError(f"expected {self.rest_lengths.size} positive tendon rest lengths, "
                             f"found {u}")
        if np.array_equal(u, self.rest_lengths):
            return
        self.rest_lengths = u.copy()
        e = self.topology.tendon_of_element
        self.tendons.L = u[e] / self.topology.tendon_elements
        if self.tendon_law == "fixed-rate":
            self.tendons.EA = self.tendon_EA[e] * (u / self.nominal_rest_lengths)[e]

    @property
    def elements(self) -> list:
        """The element sets of the model (membrane, bars, tendons) on ``topology.dofmap``."""
        return [self.membrane_element, self.bar_element, self.tendon_element]

    def _design_rest_lengths(self) -> np.ndarray:
        """Rest lengths of the ch. 3 design (eqs. 3.8-3.9) on this model's membrane mesh and
        corner attachment, so that the design and the model see the same corner stiffness."""
        from tmfem.equilibrium.design import design_equilibrium
        d = design_equilibrium(self.system, mesh_n=self.mesh_n,
                               attachment=self.topology.attachment, patch=self.patch,
                               backend=self.backend)
        return np.asarray(d.rest_lengths, dtype=float)

    # ------------------------------------------------------------------ positions
    @property
    def n_nodes(self) -> int:
        return self.topology.n_nodes

    @property
    def ndof(self) -> int:
        """Number of free degrees of freedom."""
        return int(self.free.sum())

    def full(self, xr: np.ndarray) -> np.ndarray:
        """Full positions (3, n_nodes) from the independent ones (flat, 3 n_red)."""
        return (self.topology.T @ xr).reshape(-1, 3).T

    def reduce(self, x: np.ndarray) -> np.ndarray:
        """Independent positions (flat) of full positions (3, n_nodes)."""
        keep = self.topology.red_node >= 0
        return np.ascontiguousarray(x[:, keep].T).ravel()

    def with_straight_tendons(self, x: np.ndarray) -> np.ndarray:
        """x (3, n_nodes) with every tendon's internal nodes on its chord (evenly spaced)."""
        topo = self.topology
        k = topo.tendon_elements
        if k == 1:
            return x
        c = self.system.tendon_connectivity
        a = x[:, topo.system_node[c[0]]]
        b = x[:, topo.system_node[c[1]]]
        s = np.arange(1, k) / k
        x[:, topo.tendon_internal] = a[:, :, None] + (b - a)[:, :, None] * s[None, None, :]
        return x

    def initial_positions(self, start: str = "undeformed") -> np.ndarray:
        """Start configuration (3, n_nodes) of the static solve.

        ``"undeformed"``: the unstressed flat membrane, centred in the plane of the design
        bar tops (its corners lie Delta inside the design corners); bars and lower nodes at the
        design; the top bars reach the membrane corners. ``"design"``: the design bar
        configuration with the membrane stretched affinely onto the design corners.
        """
        topo, sysm = self.topology, self.system
        x = np.zeros((3, topo.n_nodes))
        X = sysm.nodes()
        x[:, topo.system_node] = X
        Btop = X[:, [sysm.node_index(label("B", sysm.M, j)) for j in range(1, sysm.N + 1)]]
        if start not in ("undeformed", "design"):
            raise InputError(f"start: expected 'undeformed' or 'design', found {start!r}")
        x[:, :topo.n_mesh] = membrane_placement(sysm, topo.mesh, Btop,
                                                stretch_to_corners=(start == "design"))
        x = self.full(self.reduce(x))          # the bar tops follow the attachment
        return self.with_straight_tendons(x)

    def interpolate_from(self, other: "MTCModel", x_other: np.ndarray) -> np.ndarray:
        """Positions (3, n_nodes) of this model from a solution of ``other`` (same system,
        another mesh or tendon subdivision): membrane nodes by linear interpolation over the
        other mesh's nodes (reference coordinates), labelled nodes copied, tendons straight.
        Used for mesh sequencing (nested iteration) of :meth:`solve_static`."""
        from scipy.spatial import Delaunay, cKDTree
        if other.system is not self.system:
            raise InputError("interpolate_from: expected a model of the same system")
        ot, st = other.topology, self.topology
        c = st.mesh.p.mean(axis=1, keepdims=True)
        pts = (c + (1.0 - 1e-9) * (st.mesh.p - c)).T     # boundary points strictly inside
        # piecewise-linear interpolation on a Delaunay triangulation of the other mesh's nodes
        # (skfem's probes() falls back to a dense points x elements search on boundaries;
        # scipy.interpolate's LinearNDInterpolator is the same, at 0.5 s of imports)
        vals = x_other[:, :ot.n_mesh].T
        tri = Delaunay(ot.mesh.p.T)
        simplex = tri.find_simplex(pts)
        inside = simplex >= 0
        T = tri.transform[simplex[inside]]                       # (m, 3, 2): barycentric map
        b = np.einsum("mij,mj->mi", T[:, :2], pts[inside] - T[:, 2])
        bary = np.column_stack([b, 1.0 - b.sum(axis=1)])
        xm = np.empty((pts.shape[0], vals.shape[1]))
        xm[inside] = np.einsum("mk,mkc->mc", bary, vals[tri.simplices[simplex[inside]]])
        if not inside.all():
            xm[~inside] = vals[cKDTree(ot.mesh.p.T).query(pts[~inside])[1]]
        x = np.zeros((3, st.n_nodes))
        x[:, :st.n_mesh] = xm.T
        x[:, st.system_node] = x_other[:, ot.system_node]
        x = self.full(self.reduce(x))
        return self.with_straight_tendons(x)

    # ------------------------------------------------------------------ operators
    def internal_full(self, x: np.ndarray, *, tangent: bool = True):
        """Internal force (3 n_nodes,) and tangent of the full model at positions x (3, n_nodes)."""
        return assemble(self.elements, State(x=x), tangent=tangent)

    def residual(self, xr: np.ndarray, *, tangent: bool = True):
        """Reduced internal force T^T f and tangent T^T K T at independent positions xr."""
        c = self.topology.constraints
        f, K = self.internal_full(self.full(xr), tangent=tangent)
        return c.residual(f), (c.tangent(K) if tangent else None)

    @property
    def distributed(self):
        """The element sets assembled rank by rank on the free dofs
        (:class:`tmfem.fem.distributed.DistributedElements`) when the backend assembles
        distributed matrices (PETSc, on one rank or under ``mpiexec``), else None. The
        static solve and the modes then work on it: each rank evaluates and assembles its
        share of the membrane elements."""
        if self._dist is None:
            from tmfem.fem.distributed import for_backend
            self._dist = for_backend(self.backend, self.elements,
                                     State(x=self.initial_positions("design")),
                                     self.topology.T, self.free)
        return self._dist

    def mass(self) -> sp.csr_matrix:
        """Reduced mass matrix T^T M T (membrane consistent, bars consistent, tendons
        consistent or lumped)."""
        if self._M is None:
            self._M = self.topology.constraints.tangent(sum(e.mass() for e in self.elements))
        return self._M

    def energy(self, xr: np.ndarray) -> float:
        """Total strain energy [J] of membrane, bars and tendons at independent positions xr.

        Truss: EA L E^2 / 2 (zero when a tendon is slack); membrane: h int (lam tr(E)^2 / 2
        + mu E:E) dA (plane-stress St.Venant-Kirchhoff, the potential of eq. 4.9).
        """
        state = State(x=self.full(xr))
        return sum(e.energy(state) for e in self.elements)

    # ------------------------------------------------------------------ statics
    def solve_static(self, *, start: str = "undeformed", x0: np.ndarray | None = None,
                     tol: float = 1e-9, max_iter: int = 200, monitor=(), progress=None,
                     sequence: int | None = None) -> StaticResult:
        """Equilibrium reached from ``start`` (6.2): Newton regularised by a mass-scaled
        Levenberg-Marquardt trust region on the strain energy (module docstring).

        Parameters
        ----------
        start : {"undeformed", "design"}
        x0 : ndarray (3, n_nodes), optional
            Explicit start (overrides ``start``).
        tol : float
            Converged when |r_free| <= tol * (sum of |member forces| + 1 N) after a pure
            Newton step (mu = 0) or a step shorter than 1 nm.
        monitor : sequence of str
            Node labels (``"B_14"``) whose positions are recorded at every iteration.
        progress : callable, optional
            ``progress(iteration, rnorm, mu, rho)`` after every accepted step (the CLI's
            progress display); iterations are logged at DEBUG level in any case.
        sequence : int, optional
            Mesh sequencing (nested iteration): first solve the same system on the membrane
            mesh max(sequence, n // 2) (recursively, down to n = ``sequence``, from the same
            start), interpolate, then iterate here from that state (Newton converges in a few
            steps). Histories are concatenated; ``newton_iterations_tangent`` lists the
            iterations per level.
        """
        t0 = time.perf_counter()
        if sequence is not None and x0 is None and sequence < self.topology.mesh.n:
            n_coarse = max(int(sequence), self.topology.mesh.n // 2)
            coarse = MTCModel(self.system, mesh_n=n_coarse,
                              tendon_elements=self.topology.tendon_elements,
                              attachment=self.topology.attachment, rest_lengths=self.rest_lengths,
                              lumped_tendon_mass=self.lumped_tendon_mass, backend=self.backend,
                              membrane_law=self.membrane_law)
            rc = coarse.solve_static(start=start, tol=tol, max_iter=max_iter, monitor=monitor,
                                     progress=progress, sequence=sequence)
            x_fine = self.interpolate_from(coarse, rc.x)
            rc.tangent = None          # with the coarse model: its element arrays and
            del coarse                 # factorisations go before the fine level
            fine = self.solve_static(x0=x_fine, tol=tol, max_iter=max_iter, monitor=monitor,
                                     progress=progress)
            return StaticResult(
                x=fine.x, iterations=rc.iterations + fine.iterations,
                residual_history=rc.residual_history + fine.residual_history[1:],
                monitor={k: np.concatenate([rc.monitor[k], fine.monitor[k][1:]]) for k in fine.monitor},
                dt2_history=rc.dt2_history + fine.dt2_history, time=time.perf_counter() - t0,
                newton_iterations_tangent=(rc.newton_iterations_tangent or [rc.iterations])
                + [fine.iterations], tangent=fine.tangent)
        x = self.initial_positions(start) if x0 is None else np.asarray(x0, dtype=float)
        free = self.free
        idx = {lab: self.topology.system_node[self.system.node_index(lab)] for lab in monitor}
        hist = {lab: [x[:, n].copy()] for lab, n in idx.items()}
        Md = np.asarray(self.mass().diagonal())[free]

        def record(it, xr, rn, mu, rho):
            xf = self.full(xr)
            for lab, n in idx.items():
                hist[lab].append(xf[:, n].copy())
            if callable(progress):
                progress(it, rn, mu, rho)

        xr0 = self.reduce(x)
        dist = self.distributed
        if dist is None:                   # unknowns: all independent positions xr
            residual, energy, u0, unknowns = self.residual, self.energy, xr0, free

            def positions(u):
                return u
        else:                              # unknowns: the free ones, assembled rank by rank
            u0, unknowns = xr0[free], np.ones(dist.N, bool)

            def positions(u):
                xr = xr0.copy()
                xr[free] = u
                return xr

            def residual(u):
                return dist.residual(State(x=self.full(positions(u))))

            def energy(u):
                return dist.energy(State(x=self.full(positions(u))))

        res = trust_region_newton(
            residual, energy, u0, free=unknowns, scale=np.maximum(Md, 1e-9 * Md.max()),
            force_scale=lambda u: self._force_scale(self.full(positions(u))),
            tol=tol, max_iter=max_iter, backend=self.backend,
            callback=lambda it, u, rn, mu, rho: record(it, positions(u), rn, mu, rho),
            # from the design the tangent is already positive definite: try Newton first
            newton_first=(x0 is not None or start == "design"),
            describe=lambda u: self.state_note(positions(u)), what="MTC static solve")
        return StaticResult(x=self.full(positions(res.u)), iterations=res.iterations,
                            residual_history=res.residual_history,
                            monitor={k: np.array(v) for k, v in hist.items()},
                            dt2_history=res.mu_history, time=time.perf_counter() - t0,
                            tangent=res.tangent)

    def _force_scale(self, x: np.ndarray) -> float:
        """1 N + the sum of |member forces| at positions x: the scale of the convergence test
        of :meth:`solve_static`."""
        return 1.0 + float(np.sum(np.abs(truss_internal(x, self.tendons, tangent=False).N))
                           + np.sum(np.abs(truss_internal(x, self.bars, tangent=False).N)))

    def state_note(self, xr) -> str:
        """Slack tendons and stretch of the membrane at independent positions xr, for errors."""
        from tmfem.models.mtc.post import member_state
        x = self.full(xr)
        slack = member_state(self, x)["tendon_slack"]
        names = [t.name for t, s_ in zip(self.system.tendons, slack) if s_]
        c = x[:, self.topology.mesh.corners]
        return (f"{len(names)} of {slack.size} tendons slack{': ' + ', '.join(names[:9]) if names else ''}"
                f"{' ...' if len(names) > 9 else ''}; mean corner radius "
                f"{np.linalg.norm(c - c.mean(axis=1, keepdims=True), axis=0).mean():.4f} m")

    # ------------------------------------------------------------------ modes
    def modes(self, x: np.ndarray, *, k: int = 12, sigma: float = -1.0, tangent=None):
        """Lowest ``k`` natural modes about the prestressed state x (eq. 5.32).

        ``sigma`` [rad^2/s^2] is the shift-invert shift; the default -1 sits just below the
        spectrum of deployable structures of metres and sub-hertz first modes (a shift far
        below, e.g. scaled by the stiff, light tendon nodes, makes ARPACK crawl).
        ``tangent``: the tangent at x when already assembled (``StaticResult.tangent`` of
        the static solve that gave x), instead of assembling it again.
        Returns a ``Modes`` of :func:`tmfem.solvers.lowest_modes` whose ``shapes`` are the
        reduced vectors; :meth:`full_shapes` maps them to all nodes.
        """
        dist = self.distributed
        if dist is None:
            if tangent is None:
                tangent = self.residual(self.reduce(x))[1]
            else:
                _check_tangent(tangent, sp.issparse(tangent), "sparse", self.free.size)
            return lowest_modes(tangent, self.mass(), k=k, free=self.free, sigma=sigma,
                                backend=self.backend)
        if tangent is None:
            tangent = dist.residual(State(x=self.full(self.reduce(x))))[1]
        else:
            from tmfem.solvers.distributed import DistributedMatrix
            _check_tangent(tangent, isinstance(tangent, DistributedMatrix), "DistributedMatrix", dist.N)
        return dist.modes(tangent, dist.mass(), k=k, sigma=sigma, backend=self.backend)

    def full_shapes(self, shapes: np.ndarray) -> np.ndarray:
        """Mode shapes (3, n_nodes, k) from reduced vectors (3 n_red, k)."""
        S = self.topology.T @ shapes
        return S.reshape(self.n_nodes, 3, -1).transpose(1, 0, 2)

    # ------------------------------------------------------------------ design consistency
    def consistent_rest_lengths(self, *, tol: float = 1e-10) -> dict:
        """Rest lengths for which the design configuration is an equilibrium of this model
        (:func:`tmfem.models.mtc.design.consistent_rest_lengths`)."""
        return consistent_rest_lengths(self, tol=tol)


def _check_tangent(K, of_kind: bool, kind: str, n: int) -> None:
    """Refuse a ``tangent`` given to :meth:`MTCModel.modes` that is not the model's own
    (``of_kind``: of the matrix kind its static solve assembles; n x n)."""
    shape = tuple(getattr(K, "shape", ()))
    if not of_kind or shape != (n, n):
        raise InputError(f"modes: expected the tangent of this model's static solve ({kind} "
                         f"{n}x{n}), found {type(K).__name__} of shape {shape}")
