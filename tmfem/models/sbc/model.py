"""The shell-beam-cable (SBC) model of a tensegrity-membrane system (dissertation 4.3, 6.2-6.4).

Built from the same :class:`~tmfem.system.System` and the same membrane mesh as the MTC model
(:mod:`tmfem.models.mtc`), on the placement, rest-length rules and start both share
(:mod:`tmfem.models.fe`), whose numbering it extends by the bars' beam nodes:

* **membrane**: MITC4 shells (:class:`tmfem.fem.mitc4.MITC4Shell`, 4.3.1) of thickness
  ``system.membrane.h`` (51 um for the presets; docs/guides/shells.md, "the thin limit");
* **bars**: four-node beams (:class:`tmfem.fem.beam.BeamElement`, 4.3.2), ``bar_elements``
  per bar (6.2: one), solid circular section of diameter ``system.bar.d``; Poisson's ratio
  :data:`BAR_NU` (the system carries none);
* **tendons**: ``k`` tension-only trusses each (the MTC model's, eqs. 4.23-4.24);
* **supports**: A_1j translations fixed, rotations free; the rigid spin of every bar about its
  axis removed by :func:`tmfem.fem.beam.spin_constraint` (mass-orthogonal: the elastic
  spectrum is unchanged);
* **attachment**: the bar top B_Mj is a dependent node whose translations follow the membrane
  corner (``point``) or the MTC model's corner patch (``distributed``); its rotations are the
  bar's own (a pin);
* **1-N(D) systems**: H_1j is a node of bar j's beam chain at k_H (two segments), where the
  SL, SU tendons end.

Statics (6.2) start from the undeformed membrane exactly as the MTC model's (flat, unstressed,
in the plane of the design bar tops; bars at the design; the bar tops moved onto the corners)
and use the same mass-scaled trust-region Newton iteration
(:func:`tmfem.solvers.trust_region.trust_region_newton`), by default after the MTC model's
own solve from that start as a predictor (:meth:`SBCModel.equilibrium`), through its ``update=`` path: the
unknown is a :class:`~tmfem.fem.element.State` and an increment adds translations and composes
the nodal rotations by the exponential map, which is the update the shell and beam tangents
differentiate. Modes about the prestressed state solve (K_T - omega^2 M) phi = 0 (eq. 5.32)
with the symmetric part of the tangent (symmetric at equilibrium) and the mass at the current
directors; repeated pairs are M-orthonormalised by the Rayleigh-Ritz step of
:func:`tmfem.solvers.eigen.lowest_modes` as in the MTC model.
"""
from __future__ import annotations

import time
import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.beam import BeamElement, BeamSection, BeamSet, spin_constraint
from tmfem.fem.constraints import ConstraintMap
from tmfem.fem.element import State, assemble, smallest_rotation
from tmfem.fem.mitc4 import MITC4Shell, ShellSection, nodal_normals
from tmfem.fem.truss import truss_internal
from tmfem.models.base import Equilibrium
from tmfem.models.fe.model import FEModel
from tmfem.models.fe.placement import Placement
from tmfem.models.fe.tendons import Tendons
from tmfem.models.fe.topology import build_topology
from tmfem.models.fe.options import sequence_of
from tmfem.models.mtc.model import MTCModel
from tmfem.models.sbc.dynamics import SBCDynamics
from tmfem.models.sbc.topology import SBCNumbering, number_sbc
from tmfem.fem.tension_field import check_law_name
from tmfem.solvers.backends import get_backend
from tmfem.solvers.eigen import lowest_modes
from tmfem.solvers.trust_region import trust_region_newton
from tmfem.system.topology import label


#: Poisson's ratio of the bars (steel; ``system.bar`` has E, rho and d only)
BAR_NU = 0.3


class SBCModel(FEModel, Tendons, Placement):
    """Shell-beam-cable model of an M-N ``System`` (module docstring).

    Parameters
    ----------
    system : System
    mesh_n : int
        Shell elements along each side of the N membrane quadrilaterals.
    tendon_elements : int
        Truss elements per tendon (6.2: 3).
    bar_elements : int
        Four-node beam elements per bar (6.2: 1); for a 1-N(D) system per segment A_1j-H_1j
        and H_1j-B_1j (H_1j is a beam node, :mod:`tmfem.models.sbc.topology`).
    attachment : {"point", "distributed"}
    patch : float, optional
        Patch radius [m] of the distributed attachment (MTC model's default).
    rest_lengths : ndarray or {"system", "design", "mtc"}, optional
        As :class:`tmfem.models.mtc.model.MTCModel` (``"mtc"``: the MTC model's consistent
        rest lengths).
    backend : str or Backend
    membrane_law : {"svk", "tension-field"}
        In-plane law of the shells' lamina (:class:`tmfem.fem.mitc4.MITC4Shell`; the MTC
        predictor takes the same).
    """

    name = "sbc"
    plant_type = SBCDynamics

    def __init__(self, system, *, mesh_n: int = 10, tendon_elements: int = 3, bar_elements: int = 1,
                 attachment: str = "point", patch: float | None = None, rest_lengths=None,
                 backend="scipy", membrane_law: str = "svk"):
        self.system = system
        self.membrane_law = check_law_name(membrane_law)
        self.mesh_n, self.patch, self.lumped_tendon_mass = mesh_n, patch, False
        mt = self.topology = build_topology(system, mesh_n=mesh_n, tendon_elements=tendon_elements,
                                            attachment=attachment, patch=patch,
                                            rigid_bar_points=system.deployable)
        points = None
        if system.deployable:
            points = np.array([self.node(label("H", 1, j)) for j in range(1, system.N + 1)])
        self.numbering: SBCNumbering = number_sbc(mt, mt.bar_conn, bar_elements=bar_elements,
                                                  bar_points=points, k_point=system.k_H)
        num = self.numbering
        dm = self.dofmap = num.dofmap
        # reference configuration: the undeformed membrane placed as in 6.2, bars at the design
        x_start = self.initial_positions("undeformed")
        X = np.zeros((3, dm.n_nodes))
        X[:, :num.n_mtc_nodes] = x_start
        X[:, mt.system_node] = system.nodes()
        X[:, num.bar_chain] = self.along_bars(X)
        self.X = X
        mem = system.membrane
        self.shell = MITC4Shell(X=X, conn=mt.mesh.t, dofmap=dm,
                                section=ShellSection(E=mem.E, nu=mem.nu, thickness=mem.h, rho=mem.rho),
                                law=self.membrane_law)
        bar = system.bar
        self.beam = BeamElement(BeamSet(conn=num.beam_conn, section=BeamSection.circle(d=bar.d),
                                        E=bar.E, nu=BAR_NU, rho=bar.rho), dm, X=X)
        self._M = self._dist = None
        spins = [spin_constraint(self.beam, nodes=chain) for chain in num.bar_chain]
        self.constraints = ConstraintMap.build(
            dm, dependent=[(mt.top_nodes[j], nodes, w) for j, (nodes, w) in enumerate(mt.weights)],
            fixed_nodes=mt.fixed_nodes, dependent_dofs=spins)
        self.free = self.constraints.free
        self.backend = get_backend(backend, n_dofs=self.ndof)        # "auto" by the free dofs
        self._init_tendons(rest_lengths, "cable")
        # start: the MTC start (bar tops on the corners), bar interiors on the chords
        x0 = X.copy()
        x0[:, :num.n_mtc_nodes] = x_start
        x0[:, num.bar_chain] = self.along_bars(x0)
        self._start = State(x=x0, R=np.broadcast_to(np.eye(3), (dm.n_nodes, 3, 3)).copy(),
                            frames=self.shell.frames)

    # ------------------------------------------------------------------ set-up
    def along_bars(self, x: np.ndarray) -> np.ndarray:
        """Positions (3, n_bars, 3 e + 1) of the bar chain nodes on the chord of each bar's
        ends in x (at the fractions ``numbering.chain_s``)."""
        ch = self.numbering.bar_chain
        s = self.numbering.chain_s
        a, b = x[:, ch[:, 0]], x[:, ch[:, -1]]
        return a[:, :, None] + (b - a)[:, :, None] * s[None, None, :]

    def consistent_rest_lengths(self, *, tol: float = 1e-10) -> dict:
        """The rule ``"mtc"``: the rest lengths for which the design configuration is an
        equilibrium of the MTC model of this mesh and attachment
        (:func:`tmfem.models.mtc.design.consistent_rest_lengths`)."""
        mtc = MTCModel(self.system, mesh_n=self.mesh_n, tendon_elements=self.topology.tendon_elements,
                       attachment=self.topology.attachment, patch=self.patch,
                       rest_lengths=np.ones(len(self.system.tendons)), backend=self.backend,
                       membrane_law=self.membrane_law)
        return mtc.consistent_rest_lengths(tol=tol)

    def predictor(self) -> MTCModel:
        """The MTC model of this mesh, attachment and current rest lengths (1-N(D) systems
        with rigid bar points, :func:`tmfem.models.fe.topology.build_topology`): the
        predictor of :meth:`equilibrium`."""
        return MTCModel(self.system, mesh_n=self.mesh_n, tendon_elements=self.topology.tendon_elements,
                        attachment=self.topology.attachment, patch=self.patch,
                        rest_lengths=self.rest_lengths.copy(), backend=self.backend,
                        rigid_bar_points=self.system.deployable, membrane_law=self.membrane_law)

    def positions_of(self, state: State) -> np.ndarray:
        """Node positions (3, n) of ``state`` in the placement numbering (membrane, system
        nodes, tendon internal nodes; without the bar interiors)."""
        return state.x[:, :self.numbering.n_mtc_nodes]

    def membrane_area(self) -> float:
        """Reference area of the membrane [m^2] (the membrane elements' quadrature on the
        same mesh)."""
        from tmfem.fem.membrane import MembraneTL
        return MembraneTL(mesh=self.topology.mesh, material=self.system.membrane).area()

    @property
    def elements(self) -> list:
        """The element sets (shell, beams, tendons) on :attr:`dofmap`."""
        return [self.shell, self.beam, self.tendon_element]

    @property
    def ndof(self) -> int:
        """Number of free (reduced) dofs."""
        return int(self.free.sum())

    def node(self, lab: str) -> int:
        """Global node of a system label (``"B_14"``)."""
        return int(self.topology.system_node[self.system.node_index(lab)])

    # ------------------------------------------------------------------ operators
    def start_state(self) -> State:
        """The start of 6.2: the undeformed membrane, bars at the design (module docstring)."""
        return State(x=self._start.x.copy(), R=self._start.R.copy(), frames=self._start.frames)

    def residual(self, state: State, *, tangent: bool = True):
        """Reduced internal force T^T f and tangent T^T K T (eqs. 4.4-4.6) at ``state``."""
        c = self.constraints
        f, K = assemble(self.elements, state, tangent=tangent)
        return c.residual(f), (c.tangent(K) if tangent else None)

    def energy(self, state: State) -> float:
        """Strain energy [J] of shells, beams and tendons (eq. 4.9)."""
        return sum(e.energy(state) for e in self.elements)

    @property
    def distributed(self):
        """The element sets assembled rank by rank on the free dofs
        (:class:`tmfem.fem.distributed.DistributedElements`: each rank evaluates its share
        of the MITC4 shells, the beams and tendons are shared by matrix entries) when the
        backend assembles distributed matrices (PETSc, on one rank or under ``mpiexec``),
        else None. The static solve and the modes then work on it."""
        if self._dist is None:
            from tmfem.fem.distributed import for_backend
            self._dist = for_backend(self.backend, self.elements, self.start_state(),
                                     self.constraints.T, self.free)
        return self._dist

    def _on_free(self, du: np.ndarray) -> np.ndarray:
        """The reduced increment (n_red,) of an increment du of the free dofs (zeros at the
        fixed ones)."""
        full = np.zeros(self.free.size)
        full[self.free] = du
        return full

    def advance(self, state: State, du: np.ndarray) -> State:
        """State after the reduced increment du: translations added, rotations by the
        exponential map (the ``update=`` of the trust-region solver)."""
        return state.advanced(self.constraints.full(du), self.dofmap)

    def mass(self, state: State | None = None) -> sp.csr_matrix:
        """Reduced mass T^T M T: shell (with rotary inertia) and beams at the directors of
        ``state`` (reference by default), consistent tendon mass."""
        return self.constraints.tangent(sum(e.mass(state) for e in self.elements))

    def member_forces(self, state: State) -> dict:
        """Tendon axial forces [N] (per tendon, mean of its elements; per element
        ``tendon_element``) and bar axial forces [N]
        (mean over each bar's Gauss points; compression negative). A bar carrying H_1j
        (1-N(D)) reports the larger compression of its two segments A-H and H-B, as
        :func:`tmfem.equilibrium.design.bar_axial_loads` does."""
        k = self.topology.tendon_elements
        N = truss_internal(state.x, self.tendons, tangent=False, dofmap=self.dofmap).N
        segments = 2 if self.system.deployable else 1
        Nb = self.beam.section_forces(state)["N"].reshape(
            self.numbering.bar_chain.shape[0], segments, -1).mean(axis=2).min(axis=1)
        return {"tendon": N.reshape(-1, k).mean(axis=1), "tendon_element": N, "bar": Nb}

    def _force_scale(self, state: State) -> float:
        f = self.member_forces(state)
        return 1.0 + float(np.sum(np.abs(f["tendon"])) + np.sum(np.abs(f["bar"])))

    # ------------------------------------------------------------------ statics
    def state_from_mtc(self, x_mtc: np.ndarray) -> State:
        """SBC state of an MTC (predictor) solution ``x_mtc`` (3, n_mtc_nodes) on the same
        numbering: positions copied, bar interiors on the chords; every shell director
        turned onto the normal of the deformed membrane and every bar's triads by the turn
        of its chord from the design, each by the smallest rotation (so the predictor carries
        no spurious transverse shear)."""
        num = self.numbering
        x = self.X.copy()
        x[:, :num.n_mtc_nodes] = x_mtc
        x[:, num.bar_chain] = self.along_bars(x)
        R = np.broadcast_to(np.eye(3), (self.dofmap.n_nodes, 3, 3)).copy()
        mesh = self.topology.mesh
        nodes = np.arange(mesh.p.shape[1])
        R[nodes] = smallest_rotation(self.shell.frames[nodes, :, 2].T,
                                     nodal_normals(x[:, nodes], mesh.t))
        ch = num.bar_chain
        turn = smallest_rotation(self.X[:, ch[:, -1]] - self.X[:, ch[:, 0]], x[:, ch[:, -1]] - x[:, ch[:, 0]])
        R[ch] = turn[:, None]
        return State(x=x, R=R, frames=self.shell.frames)

    def equilibrium(self, u=None, *, start: State | None = None, predictor: str | None = None,
                    tol: float = 1e-9, max_iter: int = 200, monitor=(), progress=None) -> Equilibrium:
        """Equilibrium reached from the undeformed membrane (6.2) or from ``start``, for the
        tendon rest lengths u (default the current ones, ``u0`` unless changed).

        ``predictor="mtc"`` (the default without ``start``): the MTC model of the same mesh and rest lengths is
        solved first from the same undeformed start (with its mesh sequencing above 20 x 20;
        1-N(D) systems with rigid bar points, :func:`build_topology`), its equilibrium
        mapped by :meth:`state_from_mtc`, and Newton's method continues on the SBC model
        (the membrane's bending stiffness and the bars' bending only correct it). ``"none"``:
        the trust-region iteration on the SBC model all the way from the undeformed membrane.
        Converged when |r_free| <= tol x (1 N + sum of |member forces|) after a pure Newton
        step (:func:`trust_region_newton`). ``monitor``: node labels recorded every iteration
        (predictor iterations first); ``progress(iteration, rnorm, mu, rho)``.
        """
        if u is not None:
            self.set_tendon_lengths(u)
        if predictor not in (None, "mtc", "none"):
            raise InputError(f"predictor: expected 'mtc' or 'none', found {predictor!r}")
        if start is not None and predictor == "mtc":
            raise InputError("predictor: does not apply with an explicit start, found "
                             "predictor='mtc'")
        predictor = predictor or ("mtc" if start is None else "none")
        t0 = time.perf_counter()
        pre = None
        if start is not None:
            s0 = start
        elif predictor == "mtc":
            pre = self.predictor().equilibrium(tol=tol, max_iter=max_iter, monitor=monitor, progress=progress,
                                       sequence=sequence_of(self.topology.mesh.n, None))
            s0 = self.state_from_mtc(pre.x)
        else:
            s0 = self.start_state()
        idx = {lab: self.node(lab) for lab in monitor}
        hist = {lab: [s0.x[:, n].copy()] for lab, n in idx.items()}
        dist = self.distributed
        if dist is None:
            Md = np.asarray(self.mass().diagonal())[self.free]
        else:       # the reference mass for its diagonal only (the modes take it at their state)
            M0 = dist.mass(self.start_state())
            Md = M0.diagonal()
            M0.destroy()

        def record(it, s, rn, mu, rho):
            for lab, n in idx.items():
                hist[lab].append(s.x[:, n].copy())
            if callable(progress):
                progress(it, rn, mu, rho)

        if dist is None:                   # unknowns: the reduced dofs, scipy matrices
            residual, energy, advance, unknowns = self.residual, self.energy, self.advance, self.free
        else:                              # unknowns: the free dofs, assembled rank by rank
            residual, energy, unknowns = dist.residual, dist.energy, np.ones(dist.N, bool)

            def advance(s, du):
                return self.advance(s, self._on_free(du))
        res = trust_region_newton(
            residual, energy, s0, free=unknowns, scale=np.maximum(Md, 1e-9 * Md.max()),
            force_scale=self._force_scale, tol=tol, max_iter=max_iter, backend=self.backend,
            callback=record, newton_first=start is not None or pre is not None, update=advance,
            describe=lambda s: self.state_note(s.x),
            what="SBC static solve")
        mon = {k: np.array(v) for k, v in hist.items()}
        rh = res.residual_history
        if pre is not None:
            mon = {k: np.concatenate([pre.monitor[k], v[1:]]) for k, v in mon.items()}
            rh = pre.residual_history + rh[1:]
        return Equilibrium(state=res.u, u=self.rest_lengths.copy(),
                           outputs=self.named_outputs(res.u), iterations=res.iterations,
                           residual_history=rh, monitor=mon, mu_history=res.mu_history,
                           time=time.perf_counter() - t0,
                           predictor_iterations=0 if pre is None else pre.iterations,
                           level_iterations=[] if pre is None else [pre.iterations, res.iterations],
                           tangent=res.tangent)

    # ------------------------------------------------------------------ modes
    def modes(self, *, k: int = 12, at=None, sigma: float = -1.0):
        """Lowest ``k`` modes about the prestressed equilibrium ``at`` (eq. 5.32): symmetric
        part of the reduced tangent, mass at the current directors. ``at``: an
        :class:`~tmfem.models.base.Equilibrium` of this model (its tangent is reused), a
        ``State``, or None (:meth:`equilibrium`). Shapes are reduced vectors
        (:meth:`full_shapes`). With distributed assembly the symmetric part is assembled from
        the element matrices (the equilibrium's tangent is not needed)."""
        state, tangent = self._at(at)
        dist = self.distributed
        if dist is None:
            K = self.residual(state)[1] if tangent is None else tangent
            K = 0.5 * (K + K.T)
            return lowest_modes(K.tocsr(), self.mass(state), k=k, free=self.free, sigma=sigma,
                                backend=self.backend)
        _, K = dist.residual(state, symmetric=True)
        M = dist.mass(state)
        try:
            return dist.modes(K, M, k=k, sigma=sigma, backend=self.backend)
        finally:
            M.destroy()    # the mass at this state is this solve's (petsc4py frees on destroy())

    def full_shapes(self, shapes: np.ndarray) -> np.ndarray:
        """Translations (3, n_nodes, k) of the mode shapes from reduced vectors (n_red, k)."""
        S = self.constraints.T @ shapes
        tr = self.dofmap.translation_dofs(np.arange(self.dofmap.n_nodes))     # (n, 3)
        return S[tr].transpose(1, 0, 2)
