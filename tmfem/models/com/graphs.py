"""The casadi graphs of the control-oriented model: the DAE of eq. 5.19, its elimination by
coordinate partitioning (eqs. 5.20-5.28), the residual and Newton matrix of the ODE 5.27
for implicit integration (eq. 5.34), the static design terms (eq. 3.16) and the outputs.

Partitioned formulation (the default). With x = [q, eta, zeta], the DAE

    M(x) x'' + F(x, x') + Phi_x^T lambda + B(x) u = 0,   Phi(q, zeta) = 0

is mapped onto z = [q, eta] by zeta_q = -Phi_zeta^-1 Phi_q (5.23), zeta' = zeta_q q' (5.24),
T_z = [I; zeta_q] and g = -Phi_zeta^-1 (Phi_x x')_x x' (5.25), so that T_z^T Phi_x^T = 0
(5.26) and

    M_hat = T_z^T M T_z,   F_hat = T_z^T (F + M G),   B_hat = T_z^T B    (5.28).

Substituted formulation (a check): zeta(q) in closed form
(:func:`tmfem.models.com.constraints.zeta_closed_form_sx`) substituted into the Lagrangian
before differentiation, Lagrange's equations then taken in z directly.

All derivatives are casadi's automatic differentiation on SX graphs. Building them takes most
of a model's set-up, so the graphs of the last :data:`GRAPHS_MEMO_SIZE` distinct inputs are kept
in memory and shared (casadi Functions are immutable): models of the same system and options
are built once per process.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import casadi as ca
import numpy as np

from tmfem.cache import MemoryMemo
from tmfem.errors import InputError
from tmfem.models.com.constraints import phi_sx, zeta_closed_form_sx
from tmfem.models.com.energies import (lagrange_terms_sx, membrane_kinetic_energy_sx,
                                       membrane_potential_sx, tendon_energy_sx)
from tmfem.models.com.kinematics import bar_kinetic_energy_sx, nodes_sx, tendon_lengths_sx


class BufferedFunction:
    """A casadi Function of one dense vector input and one dense output, evaluated through
    casadi's function buffer: ``f(x)`` copies x into a fixed input array, evaluates in place
    and returns a copy of the output array (no DM conversions; about 2.5x faster than
    ``f(x).full()`` for the 1175 outputs of the 2-3 ``fast`` graph)."""

    def __init__(self, f: ca.Function):
        if not (f.n_in() == 1 and f.n_out() == 1 and f.sparsity_in(0).is_dense()
                and f.sparsity_out(0).is_dense()):
            raise InputError(f"buffered casadi function {f.name()}: expected one dense input "
                             "and one dense output")
        self.f = f
        self._buffer = None

    def __call__(self, x) -> np.ndarray:
        if self._buffer is None:
            buf, ev = self.f.buffer()
            self._in = np.zeros(self.f.nnz_in(0))
            self._out = np.zeros(self.f.nnz_out(0))
            buf.set_arg(0, memoryview(self._in))
            buf.set_res(0, memoryview(self._out))
            self._buffer = (buf, ev)
        self._in[:] = x
        self._buffer[1]()
        return self._out.copy()


@dataclass(frozen=True)
class COMGraphs:
    """The casadi Functions of one control-oriented model (modal coordinates z = [q, eta]).

    Attributes
    ----------
    fast : casadi.Function
        [z; z'] -> [vec M_hat; F_hat; vec B_hat] (eq. 5.28) with zeta(q) in closed form inside
        the graph: one input and one output, since casadi's per-argument conversion costs more
        than evaluating small graphs. ``fast_shapes`` are the three blocks' shapes.
    fast_residual : casadi.Function
        [z; z'; z''; u] -> r = M_hat z'' + F_hat + B_hat u (eq. 5.27), the same way.
    residual : casadi.Function
        (z, z', z'', zeta, u) -> r (eq. 5.27).
    jacobians : casadi.Function
        (z, z', z'', zeta, u) -> (r, dr/dz, dr/dz', M_hat, dr/du), dr/dz the total derivative
        through zeta(q).
    newton : casadi.Function
        (z, z', z'', zeta, u, cv, ca) -> (r, dr/dz + cv dr/dz' + ca M_hat) (eq. 5.34).
    terms : casadi.Function
        (z, z', zeta) -> (M_hat, F_hat, B_hat) with zeta given (eq. 5.28).
    dae : casadi.Function or None
        (x, x') -> (M, F, B) of the DAE 5.19, x = [q, eta, zeta] (partitioned formulation).
    constraints : casadi.Function or None
        (q, zeta, q', zeta') -> (Phi, Phi_zeta, Phi_q, (Phi_x x')_x x') (eqs. 3.5, 5.23, 5.25;
        partitioned formulation).
    fast_mg : casadi.Function or None
        [z; z'] -> T_z^T M(x) G, the constraint-acceleration part of F_hat (eq. 5.28), with
        zeta(q) in closed form (partitioned formulation).
    """

    fast: ca.Function
    fast_shapes: tuple
    fast_residual: ca.Function
    residual: ca.Function
    jacobians: ca.Function
    newton: ca.Function
    terms: ca.Function
    dae: ca.Function | None
    constraints: ca.Function | None
    fast_mg: ca.Function | None = None


#: number of distinct model inputs whose graphs :func:`build_graphs` keeps (module docstring)
GRAPHS_MEMO_SIZE = 4
_graphs_memo = MemoryMemo(GRAPHS_MEMO_SIZE)

#: fields of a MembraneBasis left out of the graphs' key: the scikit-fem mesh and basis (not
#: digestible; the shapes and invariants on that mesh are in the key) and the nodal mass
#: (no term of the graphs)
_MESH_FIELDS = ("plane", "scalar_basis", "node_mass")


def build_graphs(system, membrane, layout, *, k, damping: float, prestress_scale: float,
                 delta0, formulation: str) -> COMGraphs:
    """The graphs of eqs. 5.19-5.28 and 5.34 for one model (:func:`_graphs`), shared by the
    models of equal inputs among the last :data:`GRAPHS_MEMO_SIZE` (module docstring).

    Parameters
    ----------
    system : System
    membrane : MembraneBasis
    layout : ZetaLayout
    k : ndarray (n_t,)
        Tendon spring constants EA / r (eq. 3.9), held fixed.
    damping : float
        Modal damping c_m of eq. 5.13.
    prestress_scale, delta0 :
        Membrane prestress factor and the design corner displacements (zeta's Delta part),
        :func:`tmfem.models.com.energies.membrane_potential_sx`.
    formulation : {"partitioned", "substituted"}
    """
    basis = {f.name: getattr(membrane, f.name) for f in fields(membrane) if f.name not in _MESH_FIELDS}
    options = dict(k=k, damping=damping, prestress_scale=prestress_scale, delta0=delta0,
                   formulation=formulation)
    return _graphs_memo.get((system, basis, layout, options),
                            lambda: _graphs(system, membrane, layout, **options))


def _graphs(system, membrane, layout, *, k, damping, prestress_scale, delta0, formulation) -> COMGraphs:
    """Build the graphs of eqs. 5.19-5.28 and 5.34 (parameters of :func:`build_graphs`)."""
    nq, K, nzeta, n_t = len(system.q_names), membrane.K, layout.n, len(k)
    q = ca.SX.sym("q", nq)
    qd = ca.SX.sym("qd", nq)
    eta = ca.SX.sym("eta", K)
    etad = ca.SX.sym("etad", K)
    zz = ca.SX.sym("zeta", nzeta)
    zzd = ca.SX.sym("zetad", nzeta)
    z = ca.vertcat(q, eta)
    zd = ca.vertcat(qd, etad)
    L, U_td = tendon_energy_sx(system, k, q)
    kL = ca.DM(k) * L

    def potential(zeta):
        return U_td + membrane_potential_sx(membrane, layout, zeta, eta,
                                            prestress_scale=prestress_scale, delta0=delta0)

    def kinetic(zeta, x, xd):
        return bar_kinetic_energy_sx(system, q, qd) + membrane_kinetic_energy_sx(
            system, membrane, layout, q, zeta, eta, lambda e: ca.jtimes(e, x, xd))

    dae = con = None
    if formulation == "partitioned":
        x = ca.vertcat(q, eta, zz)
        xd = ca.vertcat(qd, etad, zzd)
        M, F, B = lagrange_terms_sx(kinetic(zz, x, xd), potential(zz), kL, x, xd, etad,
                                    nq=nq, damping=damping)               # eq. 5.19
        # coordinate partitioning, eqs. 5.22-5.26
        phi = phi_sx(system, layout, q, zz)
        Pz, Pq = ca.jacobian(phi, zz), ca.jacobian(phi, q)
        # g = d/dq(zeta_q q') q' (eq. 5.25) from differentiating Phi twice along the
        # motion with the velocities held: Phi_q q'' + Phi_zeta zeta'' + (Phi_x x')_x x' = 0
        xc = ca.vertcat(q, zz)
        xcd = ca.vertcat(qd, zzd)
        acc = ca.jtimes(ca.jtimes(phi, xc, xcd), xc, xcd)
        dae = ca.Function("com_dae", [x, xd], [M, F, B])
        con = ca.Function("com_con", [q, zz, qd, zzd], [phi, Pz, Pq, acc])
        zq = -ca.solve(Pz, Pq)                                              # eq. 5.23
        Tz = ca.vertcat(ca.horzcat(ca.SX.eye(nq), ca.SX.zeros(nq, K)),
                        ca.horzcat(ca.SX.zeros(K, nq), ca.SX.eye(K)),
                        ca.horzcat(zq, ca.SX.zeros(nzeta, K)))                # eq. 5.25
        zetad_of_q = ca.mtimes(zq, qd)                                       # eq. 5.24
        g = -ca.solve(Pz, ca.substitute(acc, zzd, zetad_of_q))
        G = ca.vertcat(ca.SX.zeros(nq + K), g)
        M = ca.substitute(M, zzd, zetad_of_q)
        F = ca.substitute(F, zzd, zetad_of_q)
        Mh = ca.mtimes([Tz.T, M, Tz])                                        # eq. 5.28
        MG = ca.mtimes(Tz.T, ca.mtimes(M, G))
        Fh = ca.mtimes(Tz.T, F) + MG
        Bh = ca.mtimes(Tz.T, B)
        Mh = 0.5 * (Mh + Mh.T)
        # total derivative through zeta(q): d/dz = d/dz|zeta + d/dzeta * zq
        dzeta_dz = ca.horzcat(zq, ca.SX.zeros(nzeta, K))
    else:
        zeta_q = zeta_closed_form_sx(system, layout, q)
        Mh, Fh, Bh = lagrange_terms_sx(kinetic(zeta_q, z, zd), potential(zeta_q), kL, z, zd, etad,
                                       nq=nq, damping=damping)
        dzeta_dz = None       # zeta is an argument of the Functions below, but unused
        MG = None
    terms = ca.Function("com_terms", [z, zd, zz], [Mh, Fh, Bh],
                        ["z", "zd", "zeta"], ["M_hat", "F_hat", "B_hat"],
                        {"allow_free": True} if formulation == "substituted" else {})
    # fast path for time integration, with zeta(q) evaluated in the graph by its closed form
    # -- an exact root of Phi (eq. 3.5), equal to the Newton solution (tests)
    zcf = zeta_closed_form_sx(system, layout, q)
    outs = [ca.substitute(o, zz, zcf) for o in (Mh, Fh, Bh)] \
        if formulation == "partitioned" else [Mh, Fh, Bh]
    fast = ca.Function("com_fast", [ca.vertcat(z, zd)],
                       [ca.vertcat(*[ca.vec(ca.densify(o)) for o in outs])], {"cse": True})
    fast_mg = None if MG is None else ca.Function(
        "com_fast_mg", [ca.vertcat(z, zd)], [ca.substitute(MG, zz, zcf)], {"cse": True})
    zdd_f = ca.SX.sym("zdd", nq + K)
    u_f = ca.SX.sym("u", n_t)
    fast_r = ca.Function(
        "com_fast_r", [ca.vertcat(z, zd, zdd_f, u_f)],
        [ca.mtimes(outs[0], zdd_f) + outs[1] + ca.mtimes(outs[2], u_f)], {"cse": True})
    # residual and Newton matrix for implicit integration (Park, 5.34)
    zdd = ca.SX.sym("zdd", nq + K)
    u = ca.SX.sym("u", n_t)
    cv = ca.SX.sym("cv")
    cacc = ca.SX.sym("ca")
    r = ca.mtimes(Mh, zdd) + Fh + ca.mtimes(Bh, u)
    Kr = ca.jacobian(r, z)
    if dzeta_dz is not None:
        Kr = Kr + ca.mtimes(ca.jacobian(r, zz), dzeta_dz)
    Cr = ca.jacobian(r, zd)
    S = Kr + cv * Cr + cacc * Mh
    return COMGraphs(
        fast=fast, fast_shapes=((nq + K, nq + K), (nq + K, 1), (nq + K, n_t)), fast_residual=fast_r,
        residual=ca.Function("com_residual", [z, zd, zdd, zz, u], [r]),
        jacobians=ca.Function("com_jac", [z, zd, zdd, zz, u], [r, Kr, Cr, Mh, ca.jacobian(r, u)]),
        newton=ca.Function("com_newton", [z, zd, zdd, zz, u, cv, cacc], [r, S]),
        terms=terms, dae=dae, constraints=con, fast_mg=fast_mg)


def static_graph(system, membrane, layout, *, prestress_scale: float, delta0) -> ca.Function:
    """(q, zeta) -> (d|d|/dq, dU_m/dq, |d|): the tendon length Jacobian, the membrane
    generalised force dU_m/dq = zeta_q^T dU_m/dzeta (zeta_q of eq. 5.23) and the tendon
    lengths, the terms of the static equilibrium of eq. 3.16 with the COM's membrane energy."""
    q = ca.SX.sym("q", len(system.q_names))
    zz = ca.SX.sym("zeta", layout.n)
    eta = ca.SX.sym("eta", membrane.K)
    L = tendon_lengths_sx(system, q)
    Um = membrane_potential_sx(membrane, layout, zz, eta, prestress_scale=prestress_scale,
                               delta0=delta0)
    phi = phi_sx(system, layout, q, zz)
    zq = -ca.solve(ca.jacobian(phi, zz), ca.jacobian(phi, q))
    gm = ca.gradient(Um, q) + ca.mtimes(zq.T, ca.gradient(Um, zz))
    return ca.Function("com_static", [q, zz], [ca.jacobian(L, q), gm, L])


def output_graph(system, layout, W_out: np.ndarray, K: int) -> ca.Function:
    """z -> [w at the output points; tendon lengths; vec(node coordinates)] (modal z):
    w = W_out[:, 1:] [Delta(q); eta] (eq. 5.1, ``W_out`` of
    :meth:`tmfem.models.com.membrane_modes.MembraneBasis.point_matrix`), zeta(q) in closed
    form; the node coordinates in ``system.node_labels`` order (eqs. 3.1-3.2)."""
    nq = len(system.q_names)
    zs = ca.SX.sym("z", nq + K)
    zc = zeta_closed_form_sx(system, layout, zs[:nq])
    w = ca.mtimes(ca.DM(W_out[:, 1:]), ca.vertcat(zc[: layout.n_delta], zs[nq:]))
    return ca.Function("com_out", [zs], [ca.vertcat(w, tendon_lengths_sx(system, zs[:nq]),
                                                    ca.vec(nodes_sx(system, zs[:nq])))])
