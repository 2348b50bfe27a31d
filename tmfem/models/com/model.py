"""The control-oriented model: Lagrangian, DAE and its ODE form (eqs. 5.1-5.28).

Coordinates (eq. 5.14, 5.20): x = [q, eta, zeta] with q the bar coordinates (eqs. 3.1-3.2),
eta the K relative membrane coordinates and zeta the dependent coordinates (corner
displacements and Euler angles of O_f, eq. 5.14). The Lagrangian (eq. 5.12)

    L = T_b(q, q') + T_m(q, zeta, eta, ...) - U_td(q; u) - U_m(zeta, eta) + lambda^T Phi(q, zeta)

with the Rayleigh function R = c_m/2 |eta'|^2 (eq. 5.13 for mass-normalised modes) gives
the DAE (5.19)  M(x) x'' + F(x, x') + Phi_x^T lambda + B(x) u = 0,  Phi(q, zeta) = 0,
which coordinate partitioning (5.20-5.26) maps onto the ODE (5.27-5.28)

    M_hat = T_z^T M T_z,   F_hat = T_z^T (F + M G),   B_hat = T_z^T B.

All derivatives are taken by casadi's automatic differentiation on SX graphs.

Tendon forces follow eq. 3.8, T = k (|d| - r), with the spring constant of eq. 3.9 taken
at the design rest length, k = EA / r_design, and held fixed: the input u = r then enters
affinely (B(x) u, eq. 5.19) -- see docs/com.md.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from tmfem.errors import ConvergenceError, InfeasibleDesign, InputError, SlackTendon
from tmfem.fem.truss import linear_rest_length
from tmfem.models.com.constraints import ConstraintSolver, ZetaLayout, phi_sx
from tmfem.models.com.kinematics import (bar_kinetic_energy_sx, bars_sx, rotation_ef_sx,
                                      tendon_lengths_sx)
from tmfem.models.com.membrane_modes import build_membrane_basis
from tmfem.solvers.newton import newton
from tmfem.system.geometry import rotation_ef

def default_membrane_modes(system) -> int:
    """K of the system's ``[models.com] membrane_modes`` (the presets carry the
    dissertation's: 5 for 1-4, 4 for 2-3, 3 for 1-4(D), 5 for 1-6D), else 4."""
    return int(system.model_defaults.get("com", {}).get("membrane_modes", 4))


def _sq(v):
    return ca.dot(v, v)


@dataclass
class StaticDesign:
    """Equilibrium of the COM at the design configuration (eq. 3.16 with the COM's energies)."""

    tendon_forces: np.ndarray
    rest_lengths: np.ndarray
    residual: float


class ControlOrientedModel:
    """Control-oriented model of a tensegrity-membrane system (dissertation ch. 5).

    Parameters
    ----------
    system : System
        Geometry, materials and the design configuration ``system.q``.
    membrane_modes : int
        Number K of relative membrane modes (5 for 1-4, 4 for 2-3 in 6.4).
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
        (:func:`tmfem.models.com.membrane_modes.build_membrane_basis`, docs/wrinkling.md).
    """

    def __init__(self, system, *, membrane_modes: int = 4, mesh_n: int = 10,
                 rest_lengths="design", damping: float = 0.0, prestress_scale: float = 1.0,
                 membrane_points=None, formulation: str = "partitioned", output_points=None,
                 membrane_law: str = "svk"):
        if formulation not in ("partitioned", "substituted"):
            raise InputError(f"formulation: expected 'partitioned' or 'substituted', found {formulation!r}")
        if not (np.isfinite(damping) and damping >= 0):
            raise InputError(f"damping c_m: expected >= 0, found {damping!r}")
        if not (np.isfinite(prestress_scale) and prestress_scale > 0):
            raise InputError(f"prestress_scale: expected > 0, found {prestress_scale!r}")
        self.system = system
        self.formulation = formulation
        self.layout = ZetaLayout.for_polygon(system.N)
        self.constraints = ConstraintSolver(system, self.layout)
        self.q0 = np.asarray(system.q, dtype=float)
        self.zeta0 = self.constraints.solve(self.q0)
        self._check_membrane_stretched()
        self.membrane = build_membrane_basis(system, delta0=self.layout.delta_array(self.zeta0),
                                             n_modes=membrane_modes, mesh_n=mesh_n,
                                             prestress_scale=prestress_scale,
                                             membrane_law=membrane_law)
        self.K = self.membrane.K
        self.prestress_scale = float(prestress_scale)
        self._delta0_vec = self.zeta0[: self.layout.n_delta].copy()
        self.nq = len(system.q_names)
        self.nz = self.nq + self.K
        self.n_t = len(system.tendons)
        self.damping = float(damping)
        self.EA = system.tendon_EA
        # nominal rest lengths and spring constants (eq. 3.9)
        self.design: StaticDesign | None = None
        self._build_static()
        if isinstance(rest_lengths, str) and rest_lengths == "design":
            self.design = self._design_rest_lengths()
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
        self._build()
        # second coordinate set (5.17-5.18)
        self.membrane_points = None
        self.P = np.eye(self.nz)
        if membrane_points is not None:
            self._set_point_coordinates(membrane_points)
        pts = output_points if output_points is not None else system.monitor_points.T
        self.output_points = [tuple(map(float, p)) for p in pts]
        self._Wout = self.membrane.point_matrix(np.array(self.output_points).T, 2) \
            if self.output_points else np.zeros((0, 1 + self.layout.n_delta + self.K))
        # fast outputs: [w at the output points, all node coordinates] from z (modal)
        zs = ca.SX.sym("z", self.nz)
        zc = self._zeta_closed_form_sx(zs[: self.nq])
        w = ca.mtimes(ca.DM(self._Wout[:, 1:]), ca.vertcat(zc[: self.layout.n_delta], zs[self.nq:]))
        from tmfem.models.com.kinematics import nodes_sx
        self._outfn = ca.Function("com_out", [zs], [ca.vertcat(w, tendon_lengths_sx(system, zs[: self.nq]),
                                                              ca.vec(nodes_sx(system, zs[: self.nq])))])

    def _check_membrane_stretched(self):
        """The design must pull every corner outward (eqs. 3.21, 3.36): radial corner
        displacement > 0 relative to the membrane centroid."""
        d = self.layout.delta_array(self.zeta0)[:2]
        c = self.system.membrane_corners
        e = c - c.mean(axis=1, keepdims=True)
        e = e / np.linalg.norm(e, axis=0)
        # remove the rigid translation (corner N is the origin of O_f): mean displacement
        radial = np.sum((d - d.mean(axis=1, keepdims=True)) * e, axis=0)
        if np.any(radial <= 0):
            from tmfem.errors import SlackMembrane
            raise SlackMembrane(f"system {self.system.name!r}: expected every membrane corner "
                                "displaced outward at the design (Delta > 0, eqs. 3.21-3.22, 3.36), "
                                f"found radial corner displacements {np.round(radial, 6).tolist()} m")

    # ------------------------------------------------------------------ names
    @property
    def z_names(self) -> list[str]:
        if self.membrane_points is None:
            eta = [f"eta_{i + 1}" for i in range(self.K)]
        else:
            eta = [f"{c}r_{i + 1}" for i, (c, _, _) in enumerate(self.membrane_points)]
        return list(self.system.q_names) + eta

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

    # ------------------------------------------------------------------ energies
    def _membrane_kinetic_energy(self, q, zeta, eta, ddt):
        """Kinetic energy of the membrane in the floating frame (eqs. 5.2-5.3).

        With r_f = sum_a xibar_a P_a (P_0 = undeformed position, then the static shapes of
        Delta and the modes of eta) and Jt[a, b] = int rho P_a P_b^T dA:
        T_m = m/2 |O'|^2 + O'.(R' c + R c') + 1/2 tr(R' J R'^T) + tr(R'^T R H) + 1/2 xi'^T M_xi xi'.
        ``ddt(expr)`` is the time derivative (a casadi directional derivative).
        """
        mb = self.membrane
        nd = self.layout.n_delta
        nP = mb.shapes.shape[0]
        _, _, B = bars_sx(self.system, q)
        O = B[-1]
        Od = ddt(O)
        R = rotation_ef_sx(zeta[nd:])
        Rd = ca.reshape(ddt(ca.vec(R)), 3, 3)
        xb = ca.vertcat(1.0, zeta[:nd], eta)
        xbd = ca.vertcat(0.0, ddt(zeta[:nd]), ddt(eta))
        Jflat = ca.DM(mb.Jt.reshape(nP * nP, 9).T)           # row-major 3x3 entries
        J = ca.reshape(ca.mtimes(Jflat, ca.kron(xb, xb)), 3, 3).T
        H = ca.reshape(ca.mtimes(Jflat, ca.kron(xbd, xb)), 3, 3).T   # int r_f' r_f^T
        first = ca.DM(mb.first.T)                              # (3, nP)
        c = ca.mtimes(first, xb)
        cd = ca.mtimes(first, xbd)
        Mxi = ca.DM(np.trace(mb.Jt, axis1=2, axis2=3))
        T = 0.5 * mb.mass * _sq(Od) + ca.dot(Od, ca.mtimes(Rd, c) + ca.mtimes(R, cd))
        T += 0.5 * ca.trace(ca.mtimes(ca.mtimes(Rd, J), Rd.T))
        T += ca.trace(ca.mtimes(ca.mtimes(Rd.T, R), H))
        T += 0.5 * ca.dot(xbd, ca.mtimes(Mxi, xbd))
        return T

    def _membrane_potential(self, zeta, eta):
        """Membrane strain energy U = 1/2 Delta^T S Delta + 1/2 sum omega_i^2 eta_i^2
        (eqs. 5.4-5.6 for static shapes and fixed-corner modes, which are K-orthogonal)."""
        nd = self.layout.n_delta
        d = zeta[:nd]
        U = 0.5 * ca.dot(d, ca.mtimes(ca.DM(self.membrane.S), d))
        if self.prestress_scale != 1.0:
            # corner forces at the design scaled by s, stiffness unchanged (see docs/com.md)
            U += (self.prestress_scale - 1.0) * ca.dot(ca.DM(self.membrane.S @ self._delta0_vec), d)
        if self.K:
            U += 0.5 * ca.dot(eta, ca.DM(self.membrane.omega**2) * eta)
        return U

    def _tendon_terms(self, q):
        """Lengths and the u-independent part sum k |d|^2 / 2 of U_td (eq. 3.6); the part
        -sum k |d| u gives B(x) u and sum k u^2 / 2 is a constant."""
        L = tendon_lengths_sx(self.system, q)
        return L, 0.5 * ca.dot(ca.DM(self.k), L * L)

    # ------------------------------------------------------------------ build
    def _lagrange_terms(self, T, U, kL, x, xd, etad):
        """M, F, B of Lagrange's equations M x'' + F + B u = 0 in coordinates x = (q, eta, ...)
        (eq. 5.19 without the constraint forces; eq. 5.27 when x = z): M = T_x'x',
        F = T_x'x x' - T_x + U_x plus the modal damping on eta, B = -(k L)_x."""
        M = ca.hessian(T, xd)[0]
        F = ca.jtimes(ca.gradient(T, xd), x, xd) - ca.gradient(T, x) + ca.gradient(U, x)
        K = etad.numel()
        if K and self.damping:
            rest = x.numel() - self.nq - K
            F += ca.vertcat(ca.SX.zeros(self.nq), self.damping * etad, ca.SX.zeros(rest))
        return M, F, -ca.jacobian(kL, x).T

    def _build(self):
        nq, K, nzeta = self.nq, self.K, self.layout.n
        q = ca.SX.sym("q", nq); qd = ca.SX.sym("qd", nq)
        eta = ca.SX.sym("eta", K); etad = ca.SX.sym("etad", K)
        zz = ca.SX.sym("zeta", nzeta); zzd = ca.SX.sym("zetad", nzeta)
        z = ca.vertcat(q, eta); zd = ca.vertcat(qd, etad)
        L, U_td = self._tendon_terms(q)
        kL = ca.DM(self.k) * L
        if self.formulation == "partitioned":
            x = ca.vertcat(q, eta, zz); xd = ca.vertcat(qd, etad, zzd)
            T = bar_kinetic_energy_sx(self.system, q, qd) + \
                self._membrane_kinetic_energy(q, zz, eta, lambda e: ca.jtimes(e, x, xd))
            U = U_td + self._membrane_potential(zz, eta)
            M, F, B = self._lagrange_terms(T, U, kL, x, xd, etad)       # eq. 5.19
            # coordinate partitioning, eqs. 5.22-5.26
            phi = phi_sx(self.system, self.layout, q, zz)
            Pz, Pq = ca.jacobian(phi, zz), ca.jacobian(phi, q)
            # numeric pieces for the fast residual (DAE matrices and constraint terms)
            xcs = ca.vertcat(q, zz); xcds = ca.vertcat(qd, zzd)
            self._dae = ca.Function("com_dae", [x, xd], [M, F, B])
            self._con = ca.Function("com_con", [q, zz, qd, zzd],
                                    [phi, Pz, Pq, ca.jtimes(ca.jtimes(phi, xcs, xcds), xcs, xcds)])
            zq = -ca.solve(Pz, Pq)                                          # eq. 5.23
            Tz = ca.vertcat(ca.horzcat(ca.SX.eye(nq), ca.SX.zeros(nq, K)),
                            ca.horzcat(ca.SX.zeros(K, nq), ca.SX.eye(K)),
                            ca.horzcat(zq, ca.SX.zeros(nzeta, K)))            # eq. 5.25
            # g = d/dq(zeta_q q') q' (eq. 5.25) from differentiating Phi twice along the
            # motion with the velocities held: Phi_q q'' + Phi_zeta zeta'' + (Phi_x x')_x x' = 0
            xc = ca.vertcat(q, zz); xcd = ca.vertcat(qd, zzd)
            acc = ca.jtimes(ca.jtimes(phi, xc, xcd), xc, xcd)
            zetad_of_q = ca.mtimes(zq, qd)                                   # eq. 5.24
            g = -ca.solve(Pz, ca.substitute(acc, zzd, zetad_of_q))
            G = ca.vertcat(ca.SX.zeros(nq + K), g)
            M = ca.substitute(M, zzd, zetad_of_q)
            F = ca.substitute(F, zzd, zetad_of_q)
            Mh = ca.mtimes([Tz.T, M, Tz])                                    # eq. 5.28
            Fh = ca.mtimes(Tz.T, F + ca.mtimes(M, G))
            Bh = ca.mtimes(Tz.T, B)
            Mh = 0.5 * (Mh + Mh.T)
            # total derivative through zeta(q): d/dz = d/dz|zeta + d/dzeta * zq
            dzeta_dz = ca.horzcat(zq, ca.SX.zeros(nzeta, K))
            args = [z, zd, zz]
        else:
            zeta_q = self._zeta_closed_form_sx(q)
            x = ca.vertcat(q, eta, zeta_q)
            T = bar_kinetic_energy_sx(self.system, q, qd) + \
                self._membrane_kinetic_energy(q, zeta_q, eta, lambda e: ca.jtimes(e, z, zd))
            U = U_td + self._membrane_potential(zeta_q, eta)
            Mh, Fh, Bh = self._lagrange_terms(T, U, kL, z, zd, etad)
            dzeta_dz = None
            args = [z, zd, zz]       # zeta is ignored (kept for a common signature)
        self._terms = ca.Function("com_terms", args, [Mh, Fh, Bh],
                                  ["z", "zd", "zeta"], ["M_hat", "F_hat", "B_hat"],
                                  {"allow_free": True} if self.formulation == "substituted" else {})
        # fast path for time integration: one input [z, z'], one output [M_hat, F_hat, B_hat]
        # (casadi's per-argument conversion costs more than evaluating small graphs), with
        # zeta(q) evaluated in the graph by its closed form -- an exact root of Phi (eq. 3.5),
        # equal to the Newton solution (tests) -- instead of a Newton loop in Python.
        zcf = self._zeta_closed_form_sx(q)
        outs = [ca.substitute(o, zz, zcf) for o in (Mh, Fh, Bh)] \
            if self.formulation == "partitioned" else [Mh, Fh, Bh]
        self._fast = ca.Function("com_fast", [ca.vertcat(z, zd)],
                                 [ca.vertcat(*[ca.vec(ca.densify(o)) for o in outs])], {"cse": True})
        self._fast_shapes = [(nq + K, nq + K), (nq + K, 1), (nq + K, self.n_t)]
        zdd_f = ca.SX.sym("zdd", nq + K); u_f = ca.SX.sym("u", self.n_t)
        self._fast_r = ca.Function(
            "com_fast_r", [ca.vertcat(z, zd, zdd_f, u_f)],
            [ca.mtimes(outs[0], zdd_f) + outs[1] + ca.mtimes(outs[2], u_f)], {"cse": True})
        # residual and Newton matrix for implicit integration (Park, 5.34)
        zdd = ca.SX.sym("zdd", nq + K); u = ca.SX.sym("u", self.n_t)
        cv = ca.SX.sym("cv"); cacc = ca.SX.sym("ca")
        r = ca.mtimes(Mh, zdd) + Fh + ca.mtimes(Bh, u)
        Kr = ca.jacobian(r, z)
        if dzeta_dz is not None:
            Kr = Kr + ca.mtimes(ca.jacobian(r, zz), dzeta_dz)
        Cr = ca.jacobian(r, zd)
        S = Kr + cv * Cr + cacc * Mh
        self._resid = ca.Function("com_residual", [z, zd, zdd, zz, u], [r])
        self._newton = ca.Function("com_newton", [z, zd, zdd, zz, u, cv, cacc], [r, S])
        self._jac = ca.Function("com_jac", [z, zd, zdd, zz, u], [r, Kr, Cr, Mh, ca.jacobian(r, u)])

    def _build_static(self):
        """dL/dq and the membrane generalised force dU_m/dq = zeta_q^T dU_m/dzeta (eq. 3.16)."""
        q = ca.SX.sym("q", self.nq); zz = ca.SX.sym("zeta", self.layout.n)
        eta = ca.SX.sym("eta", self.K)
        L = tendon_lengths_sx(self.system, q)
        Um = self._membrane_potential(zz, eta)
        phi = phi_sx(self.system, self.layout, q, zz)
        zq = -ca.solve(ca.jacobian(phi, zz), ca.jacobian(phi, q))
        gm = ca.gradient(Um, q) + ca.mtimes(zq.T, ca.gradient(Um, zz))
        self._static = ca.Function("com_static", [q, zz], [ca.jacobian(L, q), gm, L])

    def _zeta_closed_form_sx(self, q):
        """zeta(q) in closed form (SX) from the definition of O_f (3.2) -- 'substituted'."""
        N = self.system.N
        _, _, B = bars_sx(self.system, q)
        BM = B[(self.system.M - 1) * N:]
        ex = BM[0] - BM[N - 1]; ex = ex / ca.norm_2(ex)
        nz = ca.cross(ex, BM[N - 2] - BM[N - 1]); ez = nz / ca.norm_2(nz)
        ey = ca.cross(ez, ex)
        R = ca.horzcat(ex, ey, ez)
        c = self.system.membrane_corners
        out = []
        for (i, comp) in self.layout.corner_components:
            rel = ca.dot(R[:, comp], BM[i] - BM[N - 1])
            out.append(rel - (float(c[comp, i]) if comp < 2 else 0.0))
        g1 = ca.atan2(R[1, 0], R[0, 0]); g2 = -ca.asin(R[2, 0]); g3 = ca.atan2(R[2, 1], R[2, 2])
        return ca.vertcat(*out, g1, g2, g3)

    # ------------------------------------------------------------------ design
    def _design_rest_lengths(self) -> StaticDesign:
        """Tendon forces making system.q an equilibrium of this model, then rest lengths.

        Static equilibrium of the q equations (eq. 3.16 with the COM's membrane energy):
        sum_t T_t d|d_t|/dq + dU_m/dq = 0, solved for the tendon forces T by least
        squares; rest lengths r = EA |d| / (EA + T) (eqs. 3.8-3.9). A small residual
        (rounded design values, e.g. r_1 = 0.4286 m of Table 6.2) is accepted up to 1e-3
        relative; :meth:`equilibrium` then finds the exact equilibrium nearby.
        """
        JL, gm, L = (np.asarray(a) for a in self._static(self.q0, self.zeta0))
        L = L.ravel(); gm = gm.ravel()
        T, *_ = np.linalg.lstsq(JL.T, -gm, rcond=None)
        res = np.linalg.norm(JL.T @ T + gm) / max(np.linalg.norm(gm), 1e-300)
        if res > 1e-3:
            raise InfeasibleDesign(f"system {self.system.name!r}: the design q is not an equilibrium "
                                   "of any tendon forces (eq. 3.16): relative residual "
                                   f"{res:.3e}, expected <= 1e-3")
        if np.any(T <= 0):
            bad = [f"{t.name}={f:.4g} N" for t, f in zip(self.system.tendons, T) if f <= 0]
            raise SlackTendon(f"system {self.system.name!r}: design tendon forces must be > 0 "
                              f"(eq. 3.16), found {', '.join(bad)}")
        r = linear_rest_length(L, T, self.EA)
        return StaticDesign(tendon_forces=T, rest_lengths=r, residual=float(res))

    # ------------------------------------------------------------------ second coordinates
    def _set_point_coordinates(self, points):
        """Use K relative deflections at membrane points as coordinates (eqs. 5.17-5.18)."""
        pts = list(points)
        if len(pts) != self.K:
            raise InputError(f"membrane point coordinates: expected K = {self.K} points "
                             f"(eq. 5.17: k1 + k2 + k3 = K), found {len(pts)}")
        comp = {"u": 0, "v": 1, "w": 2}
        rows = []
        for p in pts:
            if len(p) != 3 or p[0] not in comp:
                raise InputError(f"membrane point coordinate: expected (component in u/v/w, x_f, y_f), found {p!r}")
            Pm = self.membrane.point_matrix(np.array([[p[1]], [p[2]]]), comp[p[0]])
            rows.append(Pm[0, 1 + self.layout.n_delta:])
        Tve = np.array(rows)                                                # eq. 5.17
        cond = np.linalg.cond(Tve)
        if not np.isfinite(cond) or cond > 1e8:
            raise InputError(f"membrane point coordinates (eq. 5.17): T_v_eta must be invertible; "
                             f"its condition number is {cond:.3e} (expected < 1e8): choose other "
                             "points or components")
        self.membrane_points = [(p[0], float(p[1]), float(p[2])) for p in pts]
        self.T_veta = Tve
        self.T_veta_cond = float(cond)
        P = np.eye(self.nz)
        P[self.nq:, self.nq:] = np.linalg.inv(Tve)
        self.P = P

    # ------------------------------------------------------------------ evaluation
    def zeta(self, q) -> np.ndarray:
        """zeta(q) by Newton on Phi (eq. 3.5) from its closed form (a pure function of q: the
        closed form is a root already, Newton only polishes it)."""
        return self.constraints.solve(q)

    def _to_modal(self, z, zd=None):
        z = self.P @ np.asarray(z, dtype=float)
        return z if zd is None else (z, self.P @ np.asarray(zd, dtype=float))

    def matrices(self, z, zd):
        """M_hat, F_hat, B_hat of eq. 5.28 at (z, z'), in the model's coordinates."""
        zm, zdm = self._to_modal(z, zd)
        flat = self._fast(np.concatenate([zm, zdm])).full().ravel()
        out, k = [], 0
        for shp in self._fast_shapes:
            n = shp[0] * shp[1]
            out.append(flat[k:k + n].reshape(shp, order="F")); k += n
        Mh, Fh, Bh = out
        if self.membrane_points is None:
            return Mh, Fh.ravel(), Bh
        P = self.P
        return P.T @ Mh @ P, P.T @ Fh.ravel(), P.T @ Bh

    def matrices_newton(self, z, zd):
        """M_hat, F_hat, B_hat with zeta from Newton on Phi and the partitioning of eqs.
        5.23-5.28 evaluated numerically from the DAE matrices (a check of the fast path)."""
        zm, zdm = self._to_modal(z, zd)
        zeta = self.zeta(zm[: self.nq])
        if self.formulation == "partitioned":
            Mh, Fh, Bh = self._partitioned_numeric(zm, zdm, zeta)
        else:
            Mh, Fh, Bh = (np.asarray(a) for a in self._terms(zm, zdm, zeta))
        P = self.P
        return P.T @ Mh @ P, P.T @ Fh.ravel(), P.T @ Bh

    def dae_terms(self, z, zd, zeta=None) -> dict:
        """The DAE of eq. 5.19 at x = [q, eta, zeta], x' = T_z z' (modal coordinates):
        M(x), F(x, x'), B(x), Phi_x, the velocity term gamma = (Phi_x x')_x x' of the
        constraint accelerations (Phi_x x'' + gamma = 0), and T_z of eq. 5.25."""
        if self.formulation != "partitioned":
            raise InputError(f"dae_terms: expected formulation='partitioned', found "
                             f"{self.formulation!r}")
        nq, K = self.nq, self.K
        z = np.asarray(z, dtype=float); zd = np.asarray(zd, dtype=float)
        q, qd = z[:nq], zd[:nq]
        zeta = self.zeta(q) if zeta is None else np.asarray(zeta, dtype=float)
        _, Pz, Pq, _ = (np.asarray(a) for a in self._con(q, zeta, qd, np.zeros(self.layout.n)))
        zq = -np.linalg.solve(Pz, Pq)                                      # eq. 5.23
        zetad = zq @ qd
        gamma = np.asarray(self._con(q, zeta, qd, zetad)[3]).ravel()
        x = np.concatenate([z, zeta]); xd = np.concatenate([zd, zetad])
        M, F, B = (np.asarray(a) for a in self._dae(x, xd))
        nx = x.size
        Phi_x = np.zeros((self.layout.n, nx))
        Phi_x[:, :nq] = Pq
        Phi_x[:, nq + K:] = Pz
        Tz = np.zeros((nx, nq + K))
        Tz[:nq + K] = np.eye(nq + K)
        Tz[nq + K:, :nq] = zq
        return {"x": x, "xd": xd, "M": M, "F": F.ravel(), "B": B, "Phi_x": Phi_x,
                "gamma": gamma, "T_z": Tz}

    def _partitioned_numeric(self, z, zd, zeta):
        """Eqs. 5.23-5.28 evaluated numerically from the DAE matrices M, F, B (eq. 5.19)
        and the constraint Jacobians (AD): zeta_q = -Phi_zeta^-1 Phi_q, zeta' = zeta_q q',
        g = -Phi_zeta^-1 (Phi_x x')_x x', T_z, then M_hat = T_z^T M T_z, ... (the fast path
        of the time integration; identical to the symbolic graph, see tests)."""
        nq, K = self.nq, self.K
        q, qd = z[:nq], zd[:nq]
        _, Pz, Pq, _ = self._con(q, zeta, qd, np.zeros(self.layout.n))
        Pz = np.asarray(Pz)
        lu = np.linalg.solve(Pz, np.hstack([np.asarray(Pq), np.eye(Pz.shape[0])]))
        zq = -lu[:, :nq]
        zetad = zq @ qd
        acc = np.asarray(self._con(q, zeta, qd, zetad)[3]).ravel()
        g = -lu[:, nq:] @ acc
        x = np.concatenate([z, zeta]); xd = np.concatenate([zd, zetad])
        M, F, B = (np.asarray(a) for a in self._dae(x, xd))
        F = F.ravel()
        nz = nq + K
        # T_z^T A T_z without forming T_z: rows/cols of zeta map onto q through zeta_q
        Mzz, Mzc, Mcc = M[:nz, :nz], M[:nz, nz:], M[nz:, nz:]
        Mh = Mzz.copy()
        Mh[:, :nq] += Mzc @ zq
        Mh[:nq, :] += (Mzc @ zq).T
        Mh[:nq, :nq] += zq.T @ Mcc @ zq
        FG = F + M[:, nz:] @ g
        Fh = FG[:nz].copy(); Fh[:nq] += zq.T @ FG[nz:]
        Bh = B[:nz].copy(); Bh[:nq] += zq.T @ B[nz:]
        return Mh, Fh, Bh

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
                return self._fast_r(np.concatenate([z, zd, zdd, u])).full().ravel()
            M, F, B = self.matrices(z, zd)
            return M @ zdd + F + B @ u
        zm, zdm = self._to_modal(z, zd)
        zeta = self.zeta(zm[: self.nq])
        r = np.asarray(self._resid(zm, zdm, self.P @ zdd, zeta, u)).ravel()
        return self.P.T @ r

    def jacobians(self, z, zd, zdd, t=0.0, u=None):
        """(dr/dz, dr/dz', dr/dz'') of the residual of eq. 5.27 (casadi AD), rest lengths u."""
        u = self.u0 if u is None else u
        zm, zdm = self._to_modal(z, zd)
        zeta = self.zeta(zm[: self.nq])
        _, K, C, M, _ = (np.asarray(a) for a in self._jac(zm, zdm, self.P @ zdd, zeta, u))
        P = self.P
        return P.T @ K @ P, P.T @ C @ P, P.T @ M @ P

    def newton_matrix(self, z, zd, zdd, t, cv, cacc, u=None):
        """K + cv C + cacc M of the residual of eq. 5.27, in one casadi call (eq. 5.34)."""
        u = self.u0 if u is None else u
        zm, zdm = self._to_modal(z, zd)
        zeta = self.zeta(zm[: self.nq])
        _, S = self._newton(zm, zdm, self.P @ zdd, zeta, u, cv, cacc)
        return self.P.T @ np.asarray(S) @ self.P

    def input_matrix(self, z):
        """d(residual)/du = B_hat (eq. 5.28)."""
        return self.matrices(z, np.zeros(self.nz))[2]

    def static_residual(self, z, u=None):
        """F_hat(z, 0) + B_hat(z) u: zero at an equilibrium."""
        u = self.u0 if u is None else u
        return self.residual(z, np.zeros(self.nz), np.zeros(self.nz), 0.0, u)

    def equilibrium(self, u=None, z0=None, *, tol: float = 1e-11, max_iter: int = 50) -> np.ndarray:
        """Static equilibrium z for rest lengths u by Newton on F_hat(z, 0) + B_hat u = 0
        (with line search), converged when |F_hat + B_hat u| <= tol |B_hat u| (the tendon
        forces' generalised load at the start)."""
        u = self.u0 if u is None else np.asarray(u, dtype=float)
        z = self.z0 if z0 is None else np.array(z0, dtype=float)
        zero = np.zeros(self.nz)

        def residual(zz):
            return self.static_residual(zz, u), self.jacobians(zz, zero, zero, 0.0, u)[0]
        scale = float(np.linalg.norm(self.input_matrix(z) @ u))
        try:
            return newton(residual, z, tol=tol, scale=scale, max_iter=max_iter).u
        except ConvergenceError as exc:
            raise ConvergenceError(f"COM static equilibrium: {exc}") from None

    # ------------------------------------------------------------------ outputs
    def fast_outputs(self, z, with_lengths: bool = False):
        """(w at the output points, node coordinates (3, n_nodes)[, tendon lengths]) for z."""
        v = self._outfn(self.P @ np.asarray(z, dtype=float)).full().ravel()
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
        return self._Wout @ xb


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
            (self.prestress_scale - 1.0) * (self.membrane.S @ self._delta0_vec) @ d
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
