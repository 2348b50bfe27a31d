"""The control-oriented model: Lagrangian, DAE and its ODE form (eqs. 5.1-5.28).

Coordinates (eq. 5.14, 5.20): x = [q, eta, zeta] with q the bar coordinates (eqs. 3.1-3.2),
eta the K relative membrane coordinates and zeta the dependent coordinates (corner
displacements and Euler angles of O_f, eq. 5.14). The Lagrangian (eq. 5.12)

    L = T_b(q, q') + T_m(q, zeta, eta, ...) - U_td(q; u) - U_m(zeta, eta) + lambda^T Phi(q, zeta)

with the Rayleigh function R = c_m/2 |eta'|^2 (eq. 5.13 for mass-normalised modes) gives
the DAE (5.19)  M(x) x'' + F(x, x') + Phi_x^T lambda + B(x) u = 0,  Phi(q, zeta) = 0,
which coordinate partitioning (5.20-5.26) maps onto the ODE (5.27-5.28)

    M_hat = T_z^T M T_z,   F_hat = T_z^T (F + M G),   B_hat = T_z^T B.

This module evaluates the model (M_hat, F_hat, B_hat, the residual of eq. 5.27 and its
Jacobians, equilibria, outputs); its pieces live beside it: the energies of eq. 5.12 in
:mod:`~tmfem.models.com.energies`, the casadi graphs of eqs. 5.19-5.28 and 5.34 (automatic
differentiation on SX graphs) in :mod:`~tmfem.models.com.graphs`, the design equilibrium in
:mod:`~tmfem.models.com.design`, the point coordinates of eqs. 5.17-5.18 in
:mod:`~tmfem.models.com.coordinates`, and the numeric DAE with its partitioning (the check of
the graphs) in :mod:`~tmfem.models.com.dae`.

Tendon forces follow eq. 3.8, T = k (|d| - r), with the spring constant of eq. 3.9 taken
at the design rest length, k = EA / r_design, and held fixed: the input u = r then enters
affinely (B(x) u, eq. 5.19) -- see docs/guides/com.md.
"""
from __future__ import annotations

import time

import numpy as np

from tmfem.errors import ConvergenceError, InputError
from tmfem.models.com.constraints import ConstraintSolver, ZetaLayout
from tmfem.models.com.coordinates import point_coordinates
from tmfem.models.com.design import StaticDesign, check_membrane_stretched, design_rest_lengths
from tmfem.models.com.graphs import BufferedFunction, build_graphs, output_graph, static_graph
from tmfem.models.base import Equilibrium
from tmfem.models.com import linearize as linearization
from tmfem.models.com.membrane_modes import build_membrane_basis
from tmfem.models.com import mode_count
from tmfem.models.com.mode_count import K_SEARCH, MembraneModeChoice, declared_membrane_modes
from tmfem.models.com.plant import COMPlant
from tmfem.resources import check_com_budget
from tmfem.solvers.newton import newton
from tmfem.system.geometry import rotation_ef

def default_membrane_modes(system) -> int:
    """K of the system's ``[models.com] membrane_modes`` (the presets carry the
    dissertation's: 5 for 1-4, 4 for 2-3, 3 for 1-4(D), 5 for 1-6D), else the automatic
    choice of :func:`tmfem.models.com.mode_count.membrane_mode_choice`."""
    return membrane_modes_of(system).K


def membrane_modes_of(system, K: int | None = None) -> MembraneModeChoice:
    """K and where it comes from: ``K`` when given, else the file's ``[models.com]
    membrane_modes``, else the automatic choice
    (:func:`tmfem.models.com.mode_count.membrane_modes_of` with :class:`ControlOrientedModel`)."""
    return mode_count.membrane_modes_of(system, K, model_class=ControlOrientedModel)


class ControlOrientedModel:
    """Control-oriented model of a tensegrity-membrane system (dissertation ch. 5).

    Parameters
    ----------
    system : System
        Geometry, materials and the design configuration ``system.q``.
    membrane_modes : int, optional
        Number K of relative membrane modes (5 for 1-4, 4 for 2-3 in 6.4); default
        :func:`default_membrane_modes` (the file's, else chosen against the FE model).
    mesh_n : int
        Membrane mesh: N patches of mesh_n x mesh_n bilinear quads (6.2: 10).
    rest_lengths : {"design", "system"} or array
        ``"design"``: rest lengths that make ``system.q`` an equilibrium of this model
        (tendon forces from eq. 3.16 with the COM's membrane energy, rest lengths from
        eqs. 3.8-3.9); ``"system"``: ``system.rest_lengths`` (e.g. printed values); or an
        explicit array aligned with ``system.tendons``. They are the nominal input u_0 and
        fix the spring constants k = EA / r (eq. 3.9).
    damping : float
        Modal damping coefficient c_m of eq. 5.13 [1/s] (R = c_m/2 sum eta_i'^2).
    prestress_scale : float
        Factor s on the designed membrane prestress: the corner forces at the design become
        s S Delta_0 (potential 1/2 Delta^T S Delta + (s - 1) (S Delta_0)^T Delta) and the
        transverse stiffness uses s tau^s; the in-plane stiffness S is unchanged. With the
        default rest lengths the tendon forces scale by s too. s = 1: designed prestress.
    membrane_points : list of (component, x_f, y_f), optional
        Use K membrane relative deflections at these points as coordinates instead of the
        modal coordinates (eqs. 5.17-5.18); component is ``"u"``, ``"v"`` or ``"w"``.
    formulation : {"partitioned", "substituted"}
        ``"partitioned"``: eqs. 5.20-5.28 with zeta(q) from Newton on Phi; ``"substituted"``:
        zeta(q) written in closed form from the definition of O_f and substituted into the
        Lagrangian before differentiation (an independent formulation, used as a check).
    output_points : list of (x_f, y_f), optional
        Membrane points whose transverse deflection w is an output; default:
        ``system.monitor_points`` (eqs. 5.36/5.38 for the presets ``1-4`` and ``2-3``).
    membrane_law : {"svk", "tension-field"}
        Membrane basis about the linear (eq. 5.8) or the tension-field prestress
        (:func:`tmfem.models.com.membrane_modes.build_membrane_basis`, docs/guides/wrinkling.md).
    """

    name = "com"

    def __init__(self, system, *, membrane_modes: int | None = None, mesh_n: int = 10,
                 rest_lengths="design", damping: float = 0.0, prestress_scale: float = 1.0,
                 membrane_points=None, formulation: str = "partitioned", output_points=None,
                 membrane_law: str = "svk"):
        if formulation not in ("partitioned", "substituted"):
            raise InputError(f"formulation: expected 'partitioned' or 'substituted', found {formulation!r}")
        if not (np.isfinite(damping) and damping >= 0):
            raise InputError(f"damping c_m: expected >= 0, found {damping!r}")
        if not (np.isfinite(prestress_scale) and prestress_scale > 0):
            raise InputError(f"prestress_scale: expected > 0, found {prestress_scale!r}")
        # the stages and K scale the set-up (K: given, else the file's, else the automatic
        # choice's search, which builds a model with K_SEARCH modes)
        check_com_budget(system, K=next(k for k in (membrane_modes, declared_membrane_modes(system), K_SEARCH)
                                        if k is not None))
        self.system = system
        self.mesh_n, self.membrane_law = mesh_n, membrane_law
        self.formulation = formulation
        #: K and where it comes from (:class:`tmfem.models.com.mode_count.MembraneModeChoice`)
        self.membrane_mode_choice = membrane_modes_of(system, membrane_modes)
        membrane_modes = self.membrane_mode_choice.K
        self.layout = ZetaLayout.for_polygon(system.N)
        self.constraints = ConstraintSolver(system, self.layout)
        self.q0 = np.asarray(system.q, dtype=float)
        self.zeta0 = self.constraints.solve(self.q0)
        check_membrane_stretched(system, self.layout, self.zeta0)
        self.membrane = build_membrane_basis(system, delta0=self.layout.delta_array(self.zeta0),
                                             n_modes=membrane_modes, mesh_n=mesh_n,
                                             prestress_scale=prestress_scale,
                                             membrane_law=membrane_law)
        self.K = self.membrane.K
        self.prestress_scale = float(prestress_scale)
        self.nq = len(system.q_names)
        self.nz = self.nq + self.K
        self.n_t = len(system.tendons)
        self.damping = float(damping)
        self.EA = system.tendon_EA
        # nominal rest lengths and spring constants (eq. 3.9)
        delta0 = self.zeta0[: self.layout.n_delta].copy()
        self.design: StaticDesign | None = None
        if isinstance(rest_lengths, str) and rest_lengths == "design":
            static = static_graph(system, self.membrane, self.layout,
                                  prestress_scale=self.prestress_scale, delta0=delta0)
            self.design = design_rest_lengths(system, static, self.q0, self.zeta0)
            self.u0 = self.design.rest_lengths
        elif isinstance(rest_lengths, str) and rest_lengths == "system":
            if system.rest_lengths is None:
                raise InputError(f"rest_lengths='system': expected rest lengths in system "
                                 f"{system.name!r}, found none (use rest_lengths='design')")
            self.u0 = np.asarray(system.rest_lengths, dtype=float)
        else:
            self.u0 = np.asarray(rest_lengths, dtype=float)
            if self.u0.shape != (self.n_t,) or np.any(~(self.u0 > 0)):
                raise InputError(f"rest lengths: expected {self.n_t} positive values, found {self.u0}")
        self.k = self.EA / self.u0
        #: the casadi Functions of eqs. 5.19-5.28 and 5.34 (:class:`tmfem.models.com.graphs.COMGraphs`)
        self.graphs = build_graphs(system, self.membrane, self.layout, k=self.k,
                                   damping=self.damping, prestress_scale=self.prestress_scale,
                                   delta0=delta0, formulation=formulation)
        # second coordinate set (5.17-5.18): z = P z_points maps onto the modal coordinates
        self.membrane_points = None
        self.P = np.eye(self.nz)
        if membrane_points is not None:
            self.membrane_points, self.T_veta, self.T_veta_cond = point_coordinates(
                self.membrane, membrane_points)
            self.P[self.nq:, self.nq:] = np.linalg.inv(self.T_veta)
        pts = output_points if output_points is not None else system.monitor_points.T
        self.output_points = [tuple(map(float, p)) for p in pts]
        #: point matrix of the output deflections: w = W_out [0; Delta; eta] (eq. 5.1)
        self.W_out = self.membrane.point_matrix(np.array(self.output_points).T, 2) \
            if self.output_points else np.zeros((0, 1 + self.layout.n_delta + self.K))
        self._delta0 = delta0
        # the per-step graphs, evaluated in place (BufferedFunction)
        self._fast = BufferedFunction(self.graphs.fast)
        self._fast_residual = BufferedFunction(self.graphs.fast_residual)
        self._fast_mg = BufferedFunction(self.graphs.fast_mg) if self.graphs.fast_mg is not None \
            else None
        self._outputs = BufferedFunction(output_graph(system, self.layout, self.W_out, self.K))

    # ------------------------------------------------------------------ names
    @property
    def z_names(self) -> list[str]:
        if self.membrane_points is None:
            eta = [f"eta_{i + 1}" for i in range(self.K)]
        else:
            eta = [f"{c}r_{i + 1}" for i, (c, _, _) in enumerate(self.membrane_points)]
        return list(self.system.q_names) + eta

    @property
    def perturbation_names(self) -> list[str]:
        """The initial perturbations a plant accepts: every state by name."""
        return self.state_names

    @property
    def ndof(self) -> int:
        """Number of coordinates z (n_q + K)."""
        return self.nz

    @property
    def max_modes(self) -> int:
        """The most modes :meth:`modes` can compute: one per coordinate."""
        return self.nz

    def describe(self) -> dict:
        """Size of the model, for reports."""
        return {"membrane_modes": self.K, "membrane_modes_from": self.membrane_mode_choice.source}

    def describe_text(self) -> str:
        """:meth:`describe` as text for titles: "K = 9 membrane modes (automatic)"."""
        how = {"file": "from the file", "given": "given", "automatic": "automatic"}
        src = self.membrane_mode_choice.source
        return f"K = {self.K} membrane mode{'s' if self.K != 1 else ''} ({how.get(src, src)})"

    @property
    def state_names(self) -> list[str]:
        return self.z_names + [n + "_dot" for n in self.z_names]

    @property
    def input_names(self) -> list[str]:
        return [f"r_{t.name}" for t in self.system.tendons]

    @property
    def output_names(self) -> list[str]:
        return list(self.system.q_names) + [f"w_{i + 1}" for i in range(len(self.output_points))]

    @property
    def z0(self) -> np.ndarray:
        """Design configuration in the model's coordinates (eta = 0)."""
        return np.linalg.solve(self.P, np.concatenate([self.q0, np.zeros(self.K)]))

    # ------------------------------------------------------------------ evaluation
    def zeta(self, q) -> np.ndarray:
        """zeta(q) by Newton on Phi (eq. 3.5) from its closed form (a pure function of q: the
        closed form is a root already, Newton only polishes it)."""
        return self.constraints.solve(q)

    def _to_modal(self, z, zd=None):
        z = self.P @ np.asarray(z, dtype=float)
        return z if zd is None else (z, self.P @ np.asarray(zd, dtype=float))

    def mg_term(self, z, zd) -> np.ndarray:
        """T_z^T M(x) G of F_hat (eq. 5.28) at (z, z'), modal coordinates, partitioned
        formulation: the part of F_hat from the constraint accelerations (7.4's uncertainty
        model of 1-6(D) and 2-3 ignores it)."""
        if self._fast_mg is None or self.membrane_points is not None:
            raise InputError("mg_term: expected the partitioned formulation in modal coordinates")
        return self._fast_mg(np.concatenate([z, zd]))

    def matrices(self, z, zd):
        """M_hat, F_hat, B_hat of eq. 5.28 at (z, z'), in the model's coordinates."""
        zm, zdm = self._to_modal(z, zd)
        flat = self._fast(np.concatenate([zm, zdm]))
        out, k = [], 0
        for shp in self.graphs.fast_shapes:
            n = shp[0] * shp[1]
            out.append(flat[k:k + n].reshape(shp, order="F"))
            k += n
        Mh, Fh, Bh = out
        if self.membrane_points is None:
            return Mh, Fh.ravel(), Bh
        P = self.P
        return P.T @ Mh @ P, P.T @ Fh.ravel(), P.T @ Bh

    def acceleration(self, z, zd, u=None):
        """z'' = -M_hat^-1 (F_hat + B_hat u) (eq. 5.27)."""
        u = self.u0 if u is None else np.asarray(u, dtype=float)
        M, F, B = self.matrices(z, zd)
        return -np.linalg.solve(M, F + B @ u)

    # interface of tmfem.solvers.park (residual in the model's coordinates)
    def residual(self, z, zd, zdd, t=0.0, u=None):
        """r = M_hat z'' + F_hat + B_hat u (eq. 5.27) in the model's coordinates."""
        u = self.u0 if u is None else u
        if self.formulation == "partitioned":
            if self.membrane_points is None:
                return self._fast_residual(np.concatenate([z, zd, zdd, u]))
            M, F, B = self.matrices(z, zd)
            return M @ zdd + F + B @ u
        zm, zdm = self._to_modal(z, zd)
        zeta = self.zeta(zm[: self.nq])
        r = np.asarray(self.graphs.residual(zm, zdm, self.P @ zdd, zeta, u)).ravel()
        return self.P.T @ r

    def jacobians(self, z, zd, zdd, t=0.0, u=None):
        """(dr/dz, dr/dz', dr/dz'') of the residual of eq. 5.27 (casadi AD), rest lengths u."""
        u = self.u0 if u is None else u
        zm, zdm = self._to_modal(z, zd)
        zeta = self.zeta(zm[: self.nq])
        _, K, C, M, _ = (np.asarray(a) for a in self.graphs.jacobians(zm, zdm, self.P @ zdd, zeta, u))
        P = self.P
        return P.T @ K @ P, P.T @ C @ P, P.T @ M @ P

    def newton_matrix(self, z, zd, zdd, t, cv, cacc, u=None):
        """K + cv C + cacc M of the residual of eq. 5.27, in one casadi call (eq. 5.34)."""
        u = self.u0 if u is None else u
        zm, zdm = self._to_modal(z, zd)
        zeta = self.zeta(zm[: self.nq])
        _, S = self.graphs.newton(zm, zdm, self.P @ zdd, zeta, u, cv, cacc)
        return self.P.T @ np.asarray(S) @ self.P

    def input_matrix(self, z):
        """d(residual)/du = B_hat (eq. 5.28)."""
        return self.matrices(z, np.zeros(self.nz))[2]

    def static_residual(self, z, u=None):
        """F_hat(z, 0) + B_hat(z) u: zero at an equilibrium."""
        u = self.u0 if u is None else u
        return self.residual(z, np.zeros(self.nz), np.zeros(self.nz), 0.0, u)

    def equilibrium(self, u=None, z0=None, *, tol: float = 1e-11, max_iter: int = 50,
                    monitor=(), progress=None) -> Equilibrium:
        """Static equilibrium z for rest lengths u (default ``u0``) by Newton on
        F_hat(z, 0) + B_hat u = 0 (with line search) from ``z0`` (default the design ``z0``),
        converged when |F_hat + B_hat u| <= tol |B_hat u| (the tendon forces' generalised load
        at the start). The result's ``state`` is z and its ``tangent`` dr/dz there;
        ``monitor``: node labels whose positions X(q) (eqs. 3.1-3.2) are recorded at every
        iterate; ``progress(iteration, rnorm)`` after every iterate."""
        t0 = time.perf_counter()
        u = self.u0 if u is None else np.asarray(u, dtype=float)
        z = self.z0 if z0 is None else np.array(z0, dtype=float)
        zero = np.zeros(self.nz)
        idx = {lab: self.system.node_index(lab) for lab in monitor}
        hist = {lab: [] for lab in idx}

        def residual(zz):
            return self.static_residual(zz, u), self.jacobians(zz, zero, zero, 0.0, u)[0]

        def record(it, zz, rn):
            X = self.system.nodes((self.P @ zz)[: self.nq]) if idx else None
            for lab, i in idx.items():
                hist[lab].append(X[:, i].copy())
            if callable(progress):
                progress(it, rn)
        scale = float(np.linalg.norm(self.input_matrix(z) @ u))
        try:
            res = newton(residual, z, tol=tol, scale=scale, max_iter=max_iter, callback=record)
        except ConvergenceError as exc:
            raise ConvergenceError(f"COM static equilibrium: {exc}") from None
        return Equilibrium(state=res.u, u=np.array(u, dtype=float), tangent=res.K,
                           outputs=dict(zip(self.output_names, self.outputs(res.u).tolist())),
                           iterations=res.iterations, residual_history=list(res.residual_history),
                           monitor={k: np.array(v) for k, v in hist.items()},
                           time=time.perf_counter() - t0)

    def _at(self, at):
        """(z, u) of ``at``: an :class:`Equilibrium`, coordinates z (at ``u0``) or None (the
        equilibrium for ``u0``)."""
        if at is None:
            at = self.equilibrium()
        if isinstance(at, Equilibrium):
            return np.asarray(at.state, dtype=float), at.u
        return np.asarray(at, dtype=float), self.u0

    def linearization(self, *, at=None) -> linearization.Linearization:
        """The second-order and state-space matrices about the equilibrium ``at`` (an
        :class:`Equilibrium`, coordinates z, or None: the equilibrium for ``u0``), eq. 5.33
        (:func:`tmfem.models.com.linearize.linearize`)."""
        z, u = self._at(at)
        return linearization.linearize(self, z_e=z, u_e=u)

    def linearize(self, *, at=None, name: str = "com"):
        """The linearisation about ``at`` (eq. 5.33) as a python-control ``StateSpace``:
        states ``state_names``, inputs ``r_<tendon>``, outputs [q, w_k]
        (:meth:`linearization`)."""
        return self.linearization(at=at).to_ss(name=name)

    def modes(self, *, k: int = 12, at=None):
        """The ``k`` lowest undamped modes about the equilibrium ``at`` (default: for ``u0``)
        of the linearisation (eq. 5.33), :meth:`Linearization.modes`."""
        return self.linearization(at=at).modes(k)

    def plant(self, *, at=None, perturb: dict | None = None) -> COMPlant:
        """Eq. 5.27 with its inputs as a simulation plant, started at the equilibrium ``at``
        (default: for ``u0``) plus ``perturb`` (by state name,
        :class:`tmfem.models.com.plant.COMPlant`)."""
        z, _ = self._at(at)
        return COMPlant(self, perturb=perturb, z_e=z)

    # ------------------------------------------------------------------ outputs
    def fast_outputs(self, z, with_lengths: bool = False):
        """(w at the output points, node coordinates (3, n_nodes)[, tendon lengths]) for z."""
        v = self._outputs(self.P @ np.asarray(z, dtype=float))
        nw = len(self.output_points)
        L = v[nw:nw + self.n_t]
        X = v[nw + self.n_t:].reshape(3, -1, order="F")
        return (v[:nw], X, L) if with_lengths else (v[:nw], X)

    def membrane_positions(self, z):
        """Membrane FE node positions (3, n_nodes) in the inertial frame (eqs. 5.1, 5.3) and
        the deflections (3, n_nodes) in O_f, for configuration z."""
        zm = self.P @ np.asarray(z, dtype=float)
        q = zm[: self.nq]
        zeta = self.zeta(q)
        nd = self.layout.n_delta
        xb = np.concatenate([[1.0], zeta[:nd], zm[self.nq:]])
        rf = np.einsum("a,aij->ij", xb, self.membrane.shapes)
        O = self.system.membrane_corners_inertial(q)[:, -1]
        return O[:, None] + rotation_ef(zeta[nd:]) @ rf, rf - self.membrane.shapes[0]

    def tendon_forces(self, z, u=None) -> np.ndarray:
        """T = k (|d| - r) (eq. 3.8 with the model's fixed k), aligned with system.tendons."""
        u = self.u0 if u is None else np.asarray(u, dtype=float)
        zm = self.P @ np.asarray(z, dtype=float)
        return self.k * (self.system.tendon_lengths(zm[: self.nq]) - u)

    def membrane_w(self, z) -> np.ndarray:
        """Transverse deflections w (O_f frame, eq. 5.1) at the output points."""
        zm = self.P @ np.asarray(z, dtype=float)
        zeta = self.zeta(zm[: self.nq])
        xb = np.concatenate([[0.0], zeta[: self.layout.n_delta], zm[self.nq:]])
        return self.W_out @ xb

    def kinetic_energy(self, z, zd) -> float:
        """z'^T M_hat(z) z' / 2 [J] (eq. 5.27)."""
        M, _, _ = self.matrices(z, zd)
        return 0.5 * float(zd @ M @ zd)

    def potential_energy(self, z, u=None) -> float:
        """U_td + U_m (eqs. 3.6, 5.4-5.6) with fixed spring constants; for energy checks."""
        u = self.u0 if u is None else np.asarray(u, dtype=float)
        zm = self.P @ np.asarray(z, dtype=float)
        q, eta = zm[: self.nq], zm[self.nq:]
        zeta = self.zeta(q)
        d = zeta[: self.layout.n_delta]
        L = self.system.tendon_lengths(q)
        Um = 0.5 * d @ self.membrane.S @ d + \
            (self.prestress_scale - 1.0) * (self.membrane.S @ self._delta0) @ d
        return float(0.5 * np.sum(self.k * (L - u) ** 2) + Um
                     + 0.5 * np.sum(self.membrane.omega**2 * eta**2))

    def to_nlsys(self, name: str = "com"):
        """The nonlinear model (eq. 5.27) as a python-control ``NonlinearIOSystem``.

        State x = [z, z'], input u = rest lengths (absolute, m), output y = [q, w at the
        output points]; the same signal names as :func:`tmfem.models.com.linearize.linearize`.
        """
        import control
        nz = self.nz

        def updfcn(t, x, u, params):
            return np.concatenate([x[nz:], self.acceleration(x[:nz], x[nz:], u)])

        def outfcn(t, x, u, params):
            return self.outputs(x[:nz])

        return control.nlsys(updfcn, outfcn, states=self.state_names, inputs=self.input_names,
                             outputs=self.output_names, name=name)

    def outputs(self, z) -> np.ndarray:
        """y = [q, w at the output points] (the output vector of the state-space models)."""
        w, _ = self.fast_outputs(z)
        return np.concatenate([(self.P @ np.asarray(z, dtype=float))[: self.nq], w])

    def summary(self) -> dict:
        """Sizes of the model (coordinates, states, inputs), membrane mass and modes."""
        return {"n_q": self.nq, "K": self.K, "n_z": self.nz, "n_states": 2 * self.nz,
                "n_zeta": self.layout.n, "n_inputs": self.n_t,
                "membrane_mass": self.membrane.mass,
                "membrane_mode_frequencies_hz": (self.membrane.omega / (2 * np.pi)).tolist(),
                "membrane_mode_kinds": list(self.membrane.mode_kind),
                "formulation": self.formulation}
