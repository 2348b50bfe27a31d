"""The membrane-truss-cable (MTC) model of a tensegrity-membrane system (dissertation 4.4, 6.2-6.4).

Built from a :class:`~tmfem.system.System`: the membrane is the flat polygon meshed by
``polygon_quad_mesh`` (N quadrilaterals of n x n four-node total-Lagrangian membrane elements,
4.4.1); every bar is one two-node truss (assumption b of 4.4: axial deformation only, EA and
rho A of ``system.bar``); every tendon is ``k`` tension-only truss elements with ``k - 1``
internal nodes carrying its mass, reference length = rest length / k. The bar bases A_1j are
pinned (their three translations fixed) and nothing else is constrained: the top membrane
floats on the bar tops, which are the membrane corners (``attachment="point"``), or the
weighted centroids of small corner patches (``attachment="distributed"``, see
:mod:`tmfem.models.fe.topology`).

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

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.models.base import Equilibrium
from tmfem.models.fe.model import FEModel
from tmfem.models.fe.placement import Placement
from tmfem.models.fe.tendons import Tendons
from tmfem.models.mtc.dynamics import MTCDynamics
from tmfem.fem.element import State, assemble
from tmfem.fem.membrane import MembraneElement, MembraneTL
from tmfem.fem.truss import TrussElement, TrussSet, truss_internal
from tmfem.models.mtc.design import consistent_rest_lengths
from tmfem.fem.tension_field import check_law_name
from tmfem.models.fe.topology import MTCTopology, build_topology
from tmfem.solvers.backends import get_backend
from tmfem.solvers.eigen import lowest_modes
from tmfem.solvers.trust_region import trust_region_newton

#: relative tolerance of the coarser levels of a mesh-sequenced static solve
#: (:meth:`MTCModel.equilibrium`): their solution only starts the next level, whose
#: interpolation residual is orders of magnitude above it
COARSE_TOL = 1e-4


class MTCModel(FEModel, Tendons, Placement):
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
        (:func:`tmfem.models.fe.topology.build_topology`): the SBC model's predictor, not
        the dissertation's MTC model.
    tendon_law : {"cable", "fixed-rate"}
        What a change of rest length (:meth:`set_tendon_lengths`, a plant's input) does to a
        tendon. ``"cable"`` (default): a cable reeled in or out, EA fixed, so its spring rate
        follows eq. 3.9, k = EA / r, at the current rest length. ``"fixed-rate"``: the rate
        stays k = EA / r_0 of the nominal rest lengths r_0 (EA scales with r / r_0), the
        control-affine tendon of eq. 5.19 (B(x) u) that the control-oriented model uses.
    """

    name = "mtc"
    plant_type = MTCDynamics

    def __init__(self, system, *, mesh_n: int = 10, tendon_elements: int = 3,
                 attachment: str = "point", patch: float | None = None, rest_lengths=None,
                 lumped_tendon_mass: bool = False, backend="scipy", membrane_law: str = "svk",
                 rigid_bar_points: bool = False, tendon_law: str = "cable"):
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
        self.lumped_tendon_mass = lumped_tendon_mass
        self.bar_element = TrussElement(self.bars, topo.dofmap)
        self.free = topo.constraints.free
        self.dofmap = topo.dofmap
        self.backend = get_backend(backend, n_dofs=self.ndof)
        self._M = None
        self._dist = None
        self._init_tendons(rest_lengths, tendon_law)

    # ------------------------------------------------------------------ set-up
    @property
    def elements(self) -> list:
        """The element sets of the model (membrane, bars, tendons) on ``topology.dofmap``."""
        return [self.membrane_element, self.bar_element, self.tendon_element]

    # ------------------------------------------------------------------ positions
    def positions_of(self, x: np.ndarray) -> np.ndarray:
        """Node positions (3, n_nodes) of a configuration: the positions themselves."""
        return np.asarray(x, dtype=float)

    def membrane_area(self) -> float:
        """Reference area of the membrane [m^2]."""
        return self.membrane.area()

    @property
    def n_nodes(self) -> int:
        return self.topology.n_nodes

    @property
    def ndof(self) -> int:
        """Number of free degrees of freedom."""
        return int(self.free.sum())

    def interpolate_from(self, other: "MTCModel", x_other: np.ndarray) -> np.ndarray:
        """Positions (3, n_nodes) of this model from a solution of ``other`` (same system,
        another mesh or tendon subdivision): membrane nodes by linear interpolation over the
        other mesh's nodes (reference coordinates), labelled nodes copied, tendons straight.
        Used for mesh sequencing (nested iteration) of :meth:`equilibrium`."""
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
    def equilibrium(self, u=None, *, start: str = "undeformed", x0: np.ndarray | None = None,
                    tol: float = 1e-9, max_iter: int = 200, monitor=(), progress=None,
                    sequence: int | None = None) -> Equilibrium:
        """Equilibrium reached from ``start`` (6.2): Newton regularised by a mass-scaled
        Levenberg-Marquardt trust region on the strain energy (module docstring).

        Parameters
        ----------
        u : ndarray, optional
            Tendon rest lengths (the inputs, :meth:`set_tendon_lengths`); default the model's
            current ones (``u0`` unless changed).
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
            steps). Histories are concatenated; ``level_iterations`` lists the
            iterations per level.

        Returns
        -------
        Equilibrium
            ``state`` the positions (3, n_nodes); ``tangent`` the reduced T^T K T (or the
            distributed one on the free dofs) of the last iteration, which :meth:`modes`
            reuses; ``mu_history`` the trust-region mu of each step.
        """
        if u is not None:
            self.set_tendon_lengths(u)
        t0 = time.perf_counter()
        if sequence is not None and x0 is None and sequence < self.topology.mesh.n:
            n_coarse = max(int(sequence), self.topology.mesh.n // 2)
            coarse = MTCModel(self.system, mesh_n=n_coarse,
                              tendon_elements=self.topology.tendon_elements,
                              attachment=self.topology.attachment, rest_lengths=self.rest_lengths,
                              lumped_tendon_mass=self.lumped_tendon_mass, backend=self.backend,
                              membrane_law=self.membrane_law)
            rc = coarse.equilibrium(start=start, tol=max(tol, COARSE_TOL), max_iter=max_iter,
                                     monitor=monitor, progress=progress, sequence=sequence)
            x_fine = self.interpolate_from(coarse, rc.x)
            rc.tangent = None          # with the coarse model: its element arrays,
            if coarse._dist is not None:   # matrices and factorisations go before the fine level
                coarse._dist.release()
            del coarse
            fine = self.equilibrium(x0=x_fine, tol=tol, max_iter=max_iter, monitor=monitor,
                                     progress=progress)
            return Equilibrium(
                state=fine.x, u=fine.u, outputs=fine.outputs,
                iterations=rc.iterations + fine.iterations,
                residual_history=rc.residual_history + fine.residual_history[1:],
                monitor={k: np.concatenate([rc.monitor[k], fine.monitor[k][1:]]) for k in fine.monitor},
                mu_history=rc.mu_history + fine.mu_history, time=time.perf_counter() - t0,
                level_iterations=(rc.level_iterations or [rc.iterations])
                + [fine.iterations], tangent=fine.tangent)
        x = self.initial_positions(start) if x0 is None else np.asarray(x0, dtype=float)
        free = self.free
        idx = {lab: self.topology.system_node[self.system.node_index(lab)] for lab in monitor}
        hist = {lab: [x[:, n].copy()] for lab, n in idx.items()}
        dist = self.distributed
        Md = np.asarray(self.mass().diagonal())[free] if dist is None else dist.mass().diagonal()

        def record(it, xr, rn, mu, rho):
            xf = self.full(xr)
            for lab, n in idx.items():
                hist[lab].append(xf[:, n].copy())
            if callable(progress):
                progress(it, rn, mu, rho)

        xr0 = self.reduce(x)
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
            describe=lambda u: self.state_note(self.full(positions(u))), what="MTC static solve")
        x = self.full(positions(res.u))
        return Equilibrium(state=x, u=self.rest_lengths.copy(), outputs=self.named_outputs(x),
                           iterations=res.iterations, residual_history=res.residual_history,
                           monitor={k: np.array(v) for k, v in hist.items()},
                           mu_history=res.mu_history, time=time.perf_counter() - t0,
                           tangent=res.tangent)

    def _force_scale(self, x: np.ndarray) -> float:
        """1 N + the sum of |member forces| at positions x: the scale of the convergence test
        of :meth:`equilibrium`."""
        return 1.0 + float(np.sum(np.abs(truss_internal(x, self.tendons, tangent=False).N))
                           + np.sum(np.abs(truss_internal(x, self.bars, tangent=False).N)))

    # ------------------------------------------------------------------ modes
    def modes(self, *, k: int = 12, at=None, sigma: float = -1.0):
        """Lowest ``k`` natural modes about the prestressed equilibrium ``at`` (eq. 5.32).

        ``at``: an :class:`~tmfem.models.base.Equilibrium` of this model (its tangent is
        reused), or positions (3, n_nodes); default :meth:`equilibrium` from the undeformed
        membrane. ``sigma`` [rad^2/s^2] is the shift-invert shift; the default -1 sits just
        below the spectrum of deployable structures of metres and sub-hertz first modes (a
        shift far below, e.g. scaled by the stiff, light tendon nodes, makes ARPACK crawl).
        Returns a ``Modes`` of :func:`tmfem.solvers.lowest_modes` whose ``shapes`` are the
        reduced vectors; :meth:`full_shapes` maps them to all nodes.
        """
        x, tangent = self._at(at)
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
