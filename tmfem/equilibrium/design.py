"""Equilibrium design of a system (dissertation 3.2 last paragraph, 5.29-5.31, 6.2).

Pipeline of :func:`design_equilibrium` for the configuration q of a system:

1. corner displacements Delta from q (corner constraints, eq. 3.5);
2. membrane corner forces F from the linear plane-stress FE of the membrane
   (:mod:`tmfem.fem.plane_stress`) with those corner displacements;
3. tendon forces T from A(q) T_q = 0 (eq. 3.16) with F given: A_T T = -A_F F (least
   squares, with the equilibrium residual reported; if the tendon network alone has
   self-stress states and the minimum-norm forces are not all positive, the combination
   maximising the smallest tendon force is chosen by LP);
4. force densities T/|d|, rest lengths r = EA |d| / (T + EA) (eqs. 3.8-3.9);
5. checks: membrane stretched (Delta > 0, eq. 3.22/3.36), tendons taut (T > 0),
   equilibrium residual of eq. 3.16, maximum principal and von Mises membrane stress vs
   yield (eqs. 5.29-5.30), tendon stress vs yield, Euler buckling of bars (eq. 5.31) with
   the compressive load from the equilibrium of each bar.

:func:`forces_from_rest_lengths` is the reverse: the tendon forces that given rest lengths
imply at the design geometry (positive strain: taut; negative: slack).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from tmfem.equilibrium.general import (EquilibriumMatrix, equilibrium_matrix, free_components,
                                       null_space, positive_null_vector, symmetric_matrix)
from tmfem.equilibrium.symmetric import closed_form_1N, closed_form_1ND
from tmfem.errors import InfeasibleDesign, InputError, SlackMembrane, SlackTendon
from tmfem.fem.plane_stress import PlaneStressMembrane, PlaneStressSolution
from tmfem.fem.truss import linear_rest_length
from tmfem.system.system import rest_length_array
from tmfem.system.geometry import beta


@dataclass(frozen=True)
class Check:
    """One design condition: ``value`` compared with ``limit`` (``ok`` when satisfied)."""

    name: str
    equation: str
    value: float
    limit: float
    ok: bool
    message: str

    def to_dict(self) -> dict:
        return {"name": self.name, "equation": self.equation, "value": self.value,
                "limit": self.limit, "ok": self.ok, "message": self.message}


# the order in which failed fundamental checks become exceptions
_RAISES = (("membrane stretched", SlackMembrane), ("tendons taut", SlackTendon),
           ("equilibrium residual", InfeasibleDesign), ("membrane corners coplanar",
                                                        InfeasibleDesign))


@dataclass
class EquilibriumDesign:
    """Result of :func:`design_equilibrium` (all arrays in SI units, inertial frame).

    Attributes
    ----------
    nodes : (3, n_nodes) node coordinates in ``node_labels`` order.
    corner_delta : (3, N) corner displacements in O_f (eq. 3.4); ``Delta`` the radial one
        of eq. 3.21-3.22 for symmetric systems (else None).
    corner_forces : (2, N) forces on the membrane corners in O_f; ``F_Delta`` their mean
        radial component.
    tendon_forces, tendon_lengths, force_densities, rest_lengths, tendon_stress : (n_t,)
        (rest length NaN for a tendon with T <= 0: no rest length makes it push)
    bar_loads : (M, N) compressive bar loads (positive = compression); bar_critical: Euler.
    residual : relative equilibrium residual |A_T T + A_F F| / |A_F F| of eq. 3.16.
    checks : list of :class:`Check`.
    """

    def __repr__(self) -> str:
        """One line: the prestress and the checks (the arrays are attributes)."""
        failed = [c.name for c in self.checks if not c.ok]
        return (f"EquilibriumDesign({len(self.tendon_forces)} tendons, F_Delta={self.F_Delta:.4g} N, "
                f"T=[{self.tendon_forces.min():.4g}, {self.tendon_forces.max():.4g}] N, "
                f"residual={self.residual:.2g}, "
                + (f"failed checks {failed})" if failed else "all checks passed)"))


    system: object
    q: np.ndarray
    nodes: np.ndarray
    corner_delta: np.ndarray
    Delta: float | None
    corner_forces: np.ndarray
    F_Delta: float
    tendon_names: list
    tendon_lengths: np.ndarray
    tendon_forces: np.ndarray
    force_densities: np.ndarray
    rest_lengths: np.ndarray
    tendon_stress: np.ndarray
    bar_loads: np.ndarray
    bar_critical: np.ndarray
    membrane_max_principal: float
    membrane_max_von_mises: float
    residual: float
    self_stress_dim: int
    checks: list
    membrane: PlaneStressSolution = field(repr=False, default=None)
    membrane_model: PlaneStressMembrane = field(repr=False, default=None)
    matrix: EquilibriumMatrix = field(repr=False, default=None)
    closed_form: dict | None = None
    given_rest_lengths: dict | None = None
    symmetric_null: dict | None = None

    @property
    def ok(self) -> bool:
        return all(c.ok for c in self.checks)

    @property
    def failed(self) -> list:
        return [c for c in self.checks if not c.ok]

    def group_values(self, values) -> dict:
        """Mean of a per-tendon array over each tendon group (``S1``, ``V2``, ``SL``)."""
        groups = [t.group for t in self.system.tendons]
        out = {}
        for g in dict.fromkeys(groups):
            out[g] = float(np.mean([v for v, gg in zip(values, groups) if gg == g]))
        return out

    def to_dict(self) -> dict:
        s = self.system
        L, T = self.group_values(self.tendon_lengths), self.group_values(self.tendon_forces)
        fd, r = self.group_values(self.force_densities), self.group_values(self.rest_lengths)
        d = {
            "system": s.name, "M": s.M, "N": s.N, "deployable": s.deployable,
            "ok": self.ok,
            "nodes": {lab: self.nodes[:, k].tolist() for k, lab in enumerate(s.node_labels)},
            "q": dict(zip(s.q_names, self.q.tolist())),
            "Delta": self.Delta, "F_Delta": self.F_Delta,
            "corner_delta": self.corner_delta.tolist(),
            "corner_forces": self.corner_forces.tolist(),
            "tendons": [{"name": n, "group": t.group, "length": float(L), "force": float(T),
                         "force_density": float(fd),
                         "rest_length": float(r) if np.isfinite(r) else None,
                         "stress": float(sg)}
                        for n, t, L, T, fd, r, sg in zip(self.tendon_names, s.tendons,
                                                         self.tendon_lengths, self.tendon_forces,
                                                         self.force_densities, self.rest_lengths,
                                                         self.tendon_stress)],
            "groups": {g: {"length": L[g], "force": T[g], "force_density": fd[g],
                           "rest_length": _finite(r[g])} for g in L},
            "bar_loads": self.bar_loads.tolist(), "bar_critical": self.bar_critical.tolist(),
            "membrane_max_principal": self.membrane_max_principal,
            "membrane_max_von_mises": self.membrane_max_von_mises,
            "residual": self.residual, "self_stress_dim": self.self_stress_dim,
            "checks": [c.to_dict() for c in self.checks],
        }
        if self.closed_form is not None:
            d["closed_form"] = {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                                for k, v in self.closed_form.items()}
        if self.symmetric_null is not None:
            d["symmetric_null"] = self.symmetric_null
        if self.given_rest_lengths is not None:
            d["given_rest_lengths"] = {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                                       for k, v in self.given_rest_lengths.items()}
        return d


def _finite(v):
    return float(v) if np.isfinite(v) else None


# ---------------------------------------------------------------------------- pieces
def membrane_state(system, q=None, *, mesh_n: int = 10, model: PlaneStressMembrane | None = None,
                   attachment: str = "point", patch: float | None = None, backend="scipy",
                   membrane_law: str = "svk"):
    """Corner displacements (eq. 3.5) and the plane-stress membrane solution for them.

    ``attachment``/``patch``: corner attachment of :class:`PlaneStressMembrane` (``"point"``,
    the dissertation's model, or ``"distributed"``; default patch radius that of
    :class:`PlaneStressMembrane`, 10 % of the membrane's circumradius r_mb, as in the MTC
    model). ``backend``: the linear-algebra backend of its solves. ``membrane_law``:
    plane-stress law (``"svk"``, eq. 5.8, or ``"tension-field"``, :mod:`tmfem.fem.tension_field`).
    These are those of ``model`` when it is given; else the model of the scipy backend is
    built and factorised once per membrane and options (:func:`_shared_membrane_model`).

    Returns
    -------
    E : EquilibriumMatrix (carries the corner state), model, solution
    """
    q = system.q if q is None else np.asarray(q, dtype=float)
    E = equilibrium_matrix(system, q)
    if model is None and backend == "scipy":
        corners = np.ascontiguousarray(system.membrane_corners, dtype=float)
        model = _shared_membrane_model(corners.tobytes(), corners.shape[1], system.membrane, mesh_n,
                                      attachment, patch, membrane_law)
    elif model is None:
        model = PlaneStressMembrane(corners=system.membrane_corners, material=system.membrane,
                                    n=mesh_n, attachment=attachment, patch=patch, backend=backend,
                                    law=membrane_law)
    sol = model.solve(E.state.delta[:2])
    return E, model, sol


@lru_cache(maxsize=8)
def _shared_membrane_model(corner_bytes: bytes, N: int, material, mesh_n: int, attachment: str,
                          patch: float | None, membrane_law: str) -> PlaneStressMembrane:
    """The plane-stress membrane (scipy backend) of the corners (2, N) given by their bytes,
    made once per membrane and options and kept (the last 8): its stiffness and its
    factorisation depend on nothing else, and every design of a system in a study or an
    optimisation solves the same membrane for other corner displacements."""
    return PlaneStressMembrane(corners=np.frombuffer(corner_bytes, dtype=float).reshape(2, N),
                               material=material, n=mesh_n, attachment=attachment, patch=patch,
                               backend="scipy", law=membrane_law)


def free_forces(F: np.ndarray) -> np.ndarray:
    """The 3N-6 corner-force entries of T_q (eq. 3.17) from in-plane corner forces (2, N)."""
    return free_components(F)


def tendon_forces_for(E: EquilibriumMatrix, F: np.ndarray, *, rtol: float = 1e-9):
    """Tendon forces with A_T T = -A_F F (eq. 3.16) for given corner forces F (2, N).

    Returns
    -------
    T : ndarray (n_t,)
    residual : float, |A_T T + A_F F| / |A_F F|
    dim : int, dimension of the tendon self-stress space (null space of A_T)
    """
    b = -E.A_F @ free_forces(F)
    AT = E.A_T
    T0, *_ = np.linalg.lstsq(AT, b, rcond=None)
    nb = max(np.linalg.norm(b), 1e-300)
    Z, _ = null_space(AT, rtol)
    k = Z.shape[1]
    if k and T0.min() <= 0:
        # self-stress of the tendon network alone and the minimum-norm forces are not all
        # positive: add the self-stress that maximises the smallest tendon force (bounded)
        C = 10.0 * max(np.abs(T0).max(), 1.0)
        c = np.zeros(k + 1)
        c[-1] = -1.0
        from scipy.optimize import linprog     # 16 MB resident: only where used
        res = linprog(c, A_ub=np.hstack([-Z, np.ones((Z.shape[0], 1))]), b_ub=T0,
                      bounds=[(-C, C)] * k + [(None, None)], method="highs")
        if res.status == 0:
            T0 = T0 + Z @ res.x[:k]
    residual = float(np.linalg.norm(AT @ T0 - b) / nb)
    return T0, residual, k


def bar_axial_loads(system, q, tendon_forces: np.ndarray, corner_force_inertial: np.ndarray):
    """Compressive load of every bar from its own equilibrium (sum of the tendon and
    membrane-corner forces on it, projected on the bar axis); positive = compression.

    For a bar carrying the point H_1j (1-N(D)) the larger compression of the two segments
    A-H and H-B is returned. ``corner_force_inertial`` (3, N) is the force the membrane
    exerts on the bar ends B_Mj.
    """
    X = system.nodes(q)
    c = system.tendon_connectivity
    d = X[:, c[1]] - X[:, c[0]]
    n = d / np.linalg.norm(d, axis=0)
    f = np.zeros_like(X)
    np.add.at(f.T, c[0], (tendon_forces * n).T)       # pull on end 1 toward end 2
    np.add.at(f.T, c[1], -(tendon_forces * n).T)
    M, N = system.M, system.N
    nb = M * N
    fB = f[:, nb:2 * nb].reshape(3, M, N).copy()
    fB[:, -1, :] += corner_force_inertial
    A, B = system.bar_ends(q)
    u = (B - A) / np.linalg.norm(B - A, axis=0)
    load = -np.einsum("cmn,cmn->mn", fB, u)
    if system.deployable:
        fH = f[:, 2 * nb:].reshape(3, 1, N)
        load = np.maximum(load, -np.einsum("cmn,cmn->mn", fB + fH, u))
    return load


def forces_from_rest_lengths(system, rest_lengths=None, *, q=None, mesh_n: int = 10,
                             membrane=None, attachment: str = "point",
                             patch: float | None = None) -> dict:
    """Tendon forces T = EA (|d| - r)/r (eqs. 3.8-3.9) implied by rest lengths at q.

    Parameters
    ----------
    rest_lengths : array (n_t,), optional
        Defaults to ``system.rest_lengths``.
    membrane : (EquilibriumMatrix, PlaneStressMembrane, PlaneStressSolution), optional
        A precomputed :func:`membrane_state` to reuse.
    attachment, patch
        Corner attachment of the membrane (see :func:`membrane_state`) when ``membrane`` is
        not given.

    Returns
    -------
    dict with ``rest_lengths``, ``lengths``, ``strain`` ((|d|-r)/r; < 0 = slack),
    ``forces`` (linear law, negative when slack), ``slack`` (bool per tendon) and
    ``residual``: the relative residual of eq. 3.16 with the membrane forces of the FE,
    |A_T T + A_F F| / |A_F F| (0 at an equilibrium).
    """
    q = system.q if q is None else np.asarray(q, dtype=float)
    r = system.rest_lengths if rest_lengths is None else rest_length_array(rest_lengths,
                                                                          len(system.tendons))
    if r is None:
        raise InputError(f"system {system.name!r}: expected rest lengths to evaluate, found none")
    L = system.tendon_lengths(q)
    EA = system.tendon_EA
    strain = (L - r) / r
    T = EA * strain
    E, _, sol = membrane_state(system, q, mesh_n=mesh_n, attachment=attachment,
                               patch=patch) if membrane is None else membrane
    b = E.A_F @ free_forces(sol.corner_forces)
    residual = float(np.linalg.norm(E.A_T @ np.maximum(T, 0.0) + b) / max(np.linalg.norm(b), 1e-300))
    return {"rest_lengths": r, "lengths": L, "strain": strain, "forces": T,
            "slack": strain <= 0, "residual": residual}


def symmetric_null_summary(system, q=None, *, rtol: float = 1e-3) -> dict:
    """The positive null-vector search on the (5M-3) x (6M-4) matrix of 3.3.2: columns,
    null-space dimension, LP margin and the null vector scaled to F_Delta = 1 (if 1-D).

    Singular values up to ``rtol`` times the largest (columns scaled to unit norm) count as
    zero, so that a design given to printed precision (e.g. r_1 of Table 6.2) is recognised;
    ``smallest_sv`` reports the actual smallest relative singular value.
    """
    S = symmetric_matrix(system, q)
    nv = positive_null_vector(S.A, rtol=rtol)
    vec = None
    if nv.dim == 1 and abs(nv.x[-1]) > 1e-12 * np.abs(nv.x).max():
        vec = (nv.x / nv.x[-1]).tolist()
    return {"columns": S.cols, "rows": S.rows, "dim": nv.dim, "positive": bool(nv.exists),
            "margin": float(nv.margin) if np.isfinite(nv.margin) else None,
            "per_F_Delta": vec, "smallest_sv": float(nv.sv.min()), "rtol": rtol}


# ---------------------------------------------------------------------------- pipeline
def _radial_delta(system, delta: np.ndarray) -> float | None:
    """Radial corner displacement Delta of eq. 3.21 from corner 1, for symmetric systems."""
    if system.symmetric is None:
        return None
    b = beta(system.N)
    return float(delta[0, 0] / (np.cos(b[0]) - np.cos(b[-1])))


def design_equilibrium(system, *, q=None, mesh_n: int = 10, strict: bool = True,
                       residual_tol: float = 1e-3, attachment: str = "point",
                       patch: float | None = None, backend="scipy",
                       membrane_law: str = "svk") -> EquilibriumDesign:
    """Design the prestress of ``system`` at configuration q (dissertation 3.2, 6.2).

    Parameters
    ----------
    system : System
    q : array, optional
        Configuration (eqs. 3.1-3.2); defaults to ``system.q``.
    mesh_n : int
        Elements per side of each membrane patch (6.2: 10).
    strict : bool
        If True, a stretched membrane, taut tendons, the equilibrium residual and coplanar
        membrane corners are required: the first failed one raises (SlackMembrane,
        SlackTendon, InfeasibleDesign) naming it with its numbers and the other failures.
        Strength checks (yield, buckling) are reported in ``checks`` and never raise.
    residual_tol : float
        Largest accepted relative residual of eq. 3.16.
    attachment : {"point", "distributed"}
        Membrane corner attachment of the plane-stress FE. ``"point"`` (default, the
        dissertation's model) is singular: F_Delta, hence every force and rest length,
        falls like 1/log(n) under mesh refinement. ``"distributed"`` spreads each corner over
        a patch (RBE3-type affine coupling, the MTC model's ``attachment="distributed"``)
        and converges.
    patch : float, optional
        Patch radius [m] of the distributed attachment (default 10 % of r_mb).
    backend : str or Backend
        Linear-algebra backend of the plane-stress solves (:func:`tmfem.solvers.get_backend`).
    membrane_law : {"svk", "tension-field"}
        Plane-stress law of the membrane (eq. 5.8 or the tension-field law of
        :mod:`tmfem.fem.tension_field`; docs/guides/wrinkling.md).
    """
    q = system.q if q is None else np.asarray(q, dtype=float)
    E, model, sol = membrane_state(system, q, mesh_n=mesh_n, attachment=attachment, patch=patch,
                                   backend=backend, membrane_law=membrane_law)
    st = E.state
    N = system.N
    checks: list[Check] = []
    scale = float(np.abs(system.membrane_corners).max())
    dw = float(np.abs(st.delta[2]).max())
    checks.append(Check("membrane corners coplanar", "eq. 3.4-3.5", dw, 1e-9 * scale,
                        dw <= 1e-9 * scale,
                        f"out-of-plane corner displacement max |Delta_w| = {dw:.3g} m; the "
                        f"plane-stress membrane needs coplanar corners (<= {1e-9 * scale:.1g} m)"))
    F = sol.corner_forces
    radial = np.sum(F * model.radial_directions(), axis=0)
    F_Delta = float(radial.mean())
    Delta = _radial_delta(system, st.delta)
    if Delta is not None:
        checks.append(Check("membrane stretched", "eq. 3.22/3.36", Delta, 0.0, Delta > 0,
                            f"expected membrane corner displacement Delta > 0, found Delta = "
                            f"{Delta:.6g} m (F_Delta = {F_Delta:.4g} N)"))
    else:
        checks.append(Check("membrane stretched", "eq. 3.21", float(radial.min()), 0.0,
                            bool(radial.min() > 0),
                            "expected every membrane corner force pointing outward, found "
                            f"radial components {np.array2string(radial, precision=4)} N"))
    T, residual, kdim = tendon_forces_for(E, F)
    L = system.tendon_lengths(q)
    names = system.tendon_names()
    slack = np.flatnonzero(T <= 0)
    cf = None
    if system.symmetric is not None and system.M == 1:
        cf = closed_form_1ND(system) if system.deployable else closed_form_1N(system)
    hint = ""
    if slack.size and cf is not None:
        psi = system.symmetric.psi[0]
        if system.deployable:
            hint = (f"; the closed form needs {cf['r1_lower']:.6g} < r_1 < min({cf['r1_upper']:.6g}, "
                    f"{cf['r1_upper_SL']:.6g}) m (eq. 3.41 and the SL bound it omits), found "
                    f"r_1 = {system.symmetric.r[0]:.6g} m")
        else:
            hint = (f"; eq. 3.35 needs cot(psi_1) > tan(pi/N) = {np.tan(np.pi / N):.4g}, found "
                    f"psi_1 = {np.degrees(psi):.4g} deg")
    checks.append(Check("tendons taut", "eq. 3.16/3.35", float(T.min()), 0.0, slack.size == 0,
                        "expected all tendon forces > 0, found " + (", ".join(
                            f"{names[k]} = {T[k]:.4g} N" for k in slack[:8]) if slack.size
                            else f"min {T.min():.4g} N") + (
                            f" ({slack.size} of {T.size} slack)" if slack.size else "") + hint))
    extra = ""
    if cf is not None and not system.deployable:
        extra = (f"; for a 1-N system eq. 3.33 requires r_1 = {cf['r1_equilibrium']:.6g} m, "
                 f"found {system.symmetric.r[0]:.6g} m")
    checks.append(Check("equilibrium residual", "eq. 3.16", residual, residual_tol,
                        residual <= residual_tol,
                        f"expected |A_T T + A_F F| / |A_F F| <= {residual_tol:g}, found "
                        f"{residual:.3g}" + ("" if residual <= residual_tol else
                                              f": no tendon forces balance the membrane at this "
                                              f"q{extra}")))
    EA = system.tendon_EA
    # eqs. 3.8-3.9; a tendon that would have to push has no rest length (NaN)
    rest = np.full_like(T, np.nan)
    rest[T > 0] = linear_rest_length(L[T > 0], T[T > 0], EA[T > 0])
    sections = [system.tendon_section(t) for t in system.tendons]
    area = np.array([s.area for s in sections])
    stress = T / area
    ys = np.array([np.nan if s.yield_stress is None else s.yield_stress for s in sections])
    if np.any(np.isfinite(ys)):
        ratio = np.where(np.isfinite(ys), stress / ys, -np.inf)
        k = int(np.argmax(ratio))
        checks.append(Check("tendon yield", "section 6.2", float(stress[k]), float(ys[k]),
                            bool(ratio[k] <= 1),
                            f"max tendon stress {stress[k] / 1e6:.4g} MPa in {names[k]} vs "
                            f"yield {ys[k] / 1e6:.4g} MPa"))
    sy = system.membrane.yield_stress
    if sy is not None:
        checks.append(Check("membrane max principal stress", "eq. 5.29", sol.max_principal, sy,
                            sol.max_principal <= sy,
                            f"max sigma_p1 = {sol.max_principal / 1e6:.4g} MPa vs yield "
                            f"{sy / 1e6:.4g} MPa"))
        checks.append(Check("membrane von Mises stress", "eq. 5.30", sol.max_von_mises, sy,
                            sol.max_von_mises <= sy,
                            f"max sigma_v = {sol.max_von_mises / 1e6:.4g} MPa vs yield "
                            f"{sy / 1e6:.4g} MPa"))
    F3 = np.vstack([F, np.zeros((1, N))])
    loads = bar_axial_loads(system, q, T, -(st.R @ F3))
    crit = np.vectorize(system.bar.euler_critical_load)(system.l)
    k = np.unravel_index(np.argmax(loads / crit), loads.shape)
    checks.append(Check("bar buckling", "eq. 5.31", float(loads[k]), float(crit[k]),
                        bool(loads[k] <= crit[k]),
                        f"max bar compression {loads[k]:.4g} N (b_{k[0] + 1}{k[1] + 1}) vs Euler "
                        f"load {crit[k]:.6g} N"))
    design = EquilibriumDesign(
        system=system, q=q, nodes=system.nodes(q), corner_delta=st.delta, Delta=Delta,
        corner_forces=F, F_Delta=F_Delta, tendon_names=names, tendon_lengths=L,
        tendon_forces=T, force_densities=T / L, rest_lengths=rest, tendon_stress=stress,
        bar_loads=loads, bar_critical=crit, membrane_max_principal=sol.max_principal,
        membrane_max_von_mises=sol.max_von_mises, residual=residual, self_stress_dim=kdim,
        checks=checks, membrane=sol, membrane_model=model, matrix=E, closed_form=cf)
    if system.symmetric is not None:
        design.symmetric_null = symmetric_null_summary(system, q)
    if system.rest_lengths is not None:
        design.given_rest_lengths = forces_from_rest_lengths(system, q=q, membrane=(E, model, sol))
    if strict:
        failed = {c.name: c for c in checks if not c.ok}
        for name, exc in _RAISES:
            if name in failed:
                others = [n for n in failed if n != name]
                msg = f"{name} ({failed[name].equation}) violated: {failed[name].message}"
                if others:
                    msg += "; also failed: " + ", ".join(others)
                raise exc(msg)
    return design
