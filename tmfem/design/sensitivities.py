"""Exact design sensitivities of the MTC and SBC models at their static equilibrium.

Variables p (:mod:`tmfem.design.variables`): tendon rest lengths, per group (``"S1"``,
``"V2"``: every tendon of the group moves together, r = r_0 + G p) or per tendon, the membrane
thickness h, the bar diameter, the tendon diameters per family and the membrane radius. The
internal force, tangent and mass of the membrane are linear in h, those of the bars and of a
tendon family linear in their area A at fixed positions: dR/dA = f / A, dK/dA = K / A,
dM/dA = M / A, and dA/dd = pi d / 2; the membrane radius scales the membrane's reference mesh,
whose partial derivatives are central differences of the assembled quantities at fixed
positions (:func:`with_radius`); the configuration angles of a symmetric system are
rest-length directions G = dr/dp, the exact rate of the ch. 3 design
(:mod:`tmfem.design.design_derivative`), with the bases' motion prescribed
(:mod:`tmfem.design.configuration`), on either model.
Responses at the equilibrium R(u, p) = 0 (:data:`RESPONSES`): the lowest k
eigenvalues lambda = omega^2 of (K_T - lambda M) phi = 0 (eq. 5.32), the total mass, the tendon
forces and stresses (the slack margin is the smallest force), the bars' compression against
the Euler load (eq. 5.31), the membrane stresses (eqs. 5.29-5.30, KS aggregates), the corner
displacements Delta, the membrane's RMS deviation from its plane and a node coordinate.

Method: the *direct* method, one linear solve per variable with the tangent of the static
solve, factorised once,

    K_T du/dp = -dR/dp,

where dR/dp is analytic (:func:`tmfem.fem.truss.truss_rest_length_derivatives`). The direct
method is chosen over the adjoint because the variables are few (one per tendon group or
family) while every eigenvalue needs the derivative of the tangent *along* the state change,
dK = dK_T/du du/dp + dK_T/dp: with du/dp at hand this is one directional derivative per
variable, whereas the adjoint of an eigenvalue would need the gradient of phi^T K_T(u) phi
with respect to u (third derivatives of the strain energy of every element). That
directional derivative is a central difference of the assembled tangent along (du/dp, dp)
with a step that moves the state by 1e-4 of its scale: truncation O(h^2) about 1e-8 relative, while
the rounding of the stiff tendon and bar entries, eps |K| / h, stays below the smallest
eigenvalues' derivatives (a step of 1e-6 already loses five digits of the lowest ones to it).
The mass, linear in the rest lengths, is differenced exactly. For a simple M-normalised mode,

    d lambda = phi^T (dK - lambda dM) phi;

for a cluster of (numerically) repeated eigenvalues with M-orthonormal basis Phi, the
directional derivatives along each variable are the eigenvalues of Phi^T (dK - lambda dM) Phi
(sorted ascending): each eigenvalue of a cluster is only directionally differentiable, their
sum is smooth. A maximum or minimum over members (the largest tendon force, the smallest)
is differentiable where the extreme member is unique; over the membrane's Gauss points it
is replaced by a KS aggregate (:mod:`tmfem.design.responses`).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from tmfem.design.configuration import design_of, design_options, design_rates
from tmfem.design.kinematics import kinematics
from tmfem.design.responses import corner_deltas, membrane_aggregates, surface_rms
from tmfem.design.variables import (Variable, apply_design, area_derivative, parse_variables, variable_values,
                                    with_membrane_radius)
from tmfem.errors import InputError
from tmfem.fem.element import State
from tmfem.fem.truss import (TrussSet, truss_axial_force_derivatives, truss_internal, truss_mass,
                             truss_rest_length_derivatives)
from tmfem.solvers.eigen import lowest_modes

#: relative gap below which neighbouring eigenvalues form a cluster
CLUSTER_TOL = 1e-6

#: responses by name (:meth:`Sensitivities.value`): description and unit; a vector response
#: ``name`` has entries ``name_1``, ``name_2``, ... (1-based)
RESPONSES = {
    "mass": ("total mass of bars, tendons and membrane", "kg"),
    "omega2": ("lowest k eigenvalues omega^2 (eq. 5.32), vector", "rad^2/s^2"),
    "freq": ("lowest k natural frequencies, vector", "Hz"),
    "tendon_force": ("axial force of every tendon, vector", "N"),
    "tendon_stress": ("stress N / A of every tendon, vector", "Pa"),
    "tendon_force_min": ("smallest tendon force: the slack margin", "N"),
    "tendon_force_max": ("largest tendon force", "N"),
    "tendon_stress_max": ("largest tendon stress", "Pa"),
    "bar_force": ("axial force of every bar (tension positive), vector", "N"),
    "bar_buckling": ("compression over the Euler load -N / N_cr of every bar (eq. 5.31), vector", "-"),
    "bar_buckling_max": ("largest -N / N_cr", "-"),
    "membrane_von_mises": ("KS aggregate of the von Mises stress (eq. 5.30), >= its maximum", "Pa"),
    "membrane_min_principal": ("KS aggregate of the minor principal stress (eq. 5.29) inside "
                               "the aperture, <= its minimum; >= 0: no wrinkling", "Pa"),
    "wrinkled_area": ("smoothed area where the minor principal stress is below zero, sum_g "
                      "H_w(-sigma_2) dA_g (logistic H_w of width `wrinkle_width`); -> the tension-field "
                      "law's wrinkled and slack area as w -> 0", "m^2"),
    "corner_delta": ("corner displacements Delta_j of the membrane corners, vector", "m"),
    "corner_delta_max": ("largest corner displacement Delta", "m"),
    "surface_rms": ("RMS distance of the membrane from its best-fit plane", "m"),
    "position": ("coordinate `axis` of the node `node`", "m"),
}


@dataclass
class Sensitivities:
    """Responses and their derivatives with respect to the variables ``names``.

    Every response of :data:`RESPONSES` is read by name with :meth:`value` and
    :meth:`gradient`; the attributes below are kept for direct use.

    Attributes
    ----------
    names : list of str
        The variables (:mod:`tmfem.design.variables`).
    omega2, d_omega2 : (k,), (k, n_var)
        Lowest eigenvalues [rad^2/s^2] and their (directional, within clusters) derivatives.
    freq_hz, d_freq_hz : (k,), (k, n_var)
        f = sqrt(lambda) / (2 pi) and df = d lambda / (4 pi sqrt(lambda)).
    clusters : list of ndarray
        Index sets of the eigenvalue clusters (length > 1: repeated eigenvalues).
    max_tendon_force, d_max_tendon_force : float, (n_var,)
        Largest tendon element axial force [N] and its derivative.
    max_tendon_stress, d_max_tendon_stress : float, (n_var,)
        Largest tendon stress N / A [Pa] and its derivative.
    position, d_position : float, (n_var,)
        Coordinate of the requested node [m] and its derivative (None without a node).
    du : (n_dofs, n_var)
        Derivatives of the independent positions.
    values, gradients : dict
        Every response by name (:data:`RESPONSES`): value (scalar or vector) and derivative
        ((n_var,) or (n, n_var)).
    """

    names: list
    omega2: np.ndarray
    d_omega2: np.ndarray
    freq_hz: np.ndarray
    d_freq_hz: np.ndarray
    clusters: list
    max_tendon_force: float
    d_max_tendon_force: np.ndarray
    max_tendon_stress: float
    d_max_tendon_stress: np.ndarray
    position: float | None
    d_position: np.ndarray | None
    du: np.ndarray
    values: dict = field(default_factory=dict)
    gradients: dict = field(default_factory=dict)

    def _lookup(self, name: str):
        if not isinstance(name, str):
            raise InputError(f"response: expected a name, found {name!r}")
        if name in self.values:
            return self.values[name], self.gradients[name]
        base, _, idx = name.rpartition("_")
        if base in self.values and np.ndim(self.values[base]) == 1 and idx.isdigit():
            i = int(idx)
            n = len(self.values[base])
            if not 1 <= i <= n:
                raise InputError(f"response {name!r}: expected an index 1..{n} of {base!r}, found {i}")
            return self.values[base][i - 1], self.gradients[base][i - 1]
        if name == "position" or base == "position":
            raise InputError("response 'position': expected a node (design_sensitivities(node=...))")
        raise InputError(f"response {name!r}: expected one of {sorted(self.values)} (vectors also "
                         f"as name_i, 1-based)")

    def value(self, name: str):
        """Value of the response ``name`` (:data:`RESPONSES`; ``freq_2``: the second entry)."""
        return self._lookup(name)[0]

    def gradient(self, name: str) -> np.ndarray:
        """Derivative of the response ``name`` with respect to the variables ((n_var,), or
        (n, n_var) for a vector response)."""
        return self._lookup(name)[1]


def variable_map(model, variables):
    """Names and the map G (n_tendons, n_var) from the variables to the rest lengths (zero
    columns for the variables that are not rest lengths)."""
    vs = parse_variables(model.system, variables)
    return [v.name for v in vs], _rest_length_map(model, vs)


def _rest_length_map(model, vs: list, rates: dict | None = None) -> np.ndarray:
    """G (module docstring); ``rates``: {j: :func:`design_rates`} of the angle variables
    (computed here when not given)."""
    G = np.zeros((len(model.system.tendons), len(vs)))
    for j, v in enumerate(vs):
        if v.kind == "rest_length":
            G[list(v.tendons), j] = 1.0
        elif v.kind == "angle":
            G[:, j] = (rates[j] if rates else design_rates(model, v.angle, v.stage))[0]
    return G


def _clusters(lam: np.ndarray) -> list:
    """Runs of neighbouring eigenvalues within CLUSTER_TOL of each other (relative)."""
    scale = np.maximum(np.abs(lam[1:]), np.abs(lam[:-1])).clip(min=1e-12)
    breaks = np.flatnonzero(np.diff(lam) > CLUSTER_TOL * scale) + 1
    return np.split(np.arange(lam.size), breaks)


#: relative eigen-residual |K phi - lambda M phi| / |K phi| above which a cluster's modes are refined
MODE_TOL = 1e-8


def _refined_modes(K, M, lam, Phi, clusters, free, backend):
    """The eigenpairs of each cluster, refined where their residual exceeds :data:`MODE_TOL`.

    The eigenvalue derivatives are first order in the eigenvectors' error: the SBC model's
    ARPACK modes have residuals of 3e-4 (rotational dofs of small mass), which made its
    pair's derivatives split by 7e-4. Two steps of inverse subspace iteration shifted to
    1e-4 below the cluster, x <- (K - sigma M)^-1 M x, each followed by a Rayleigh-Ritz
    step, converge by (1e-4 / relative gap)^2 per step; the block holds every computed mode
    within 1 % of the cluster so that close neighbours are not mixed in.
    """
    lam, Phi = lam.copy(), Phi.copy()
    Kf, Mf = K[free][:, free], M[free][:, free]
    for c in clusters:
        P = Phi[free][:, c]
        KP = Kf @ P
        if np.abs(KP - (Mf @ P) * lam[c]).max() <= MODE_TOL * np.abs(KP).max():
            continue
        block = np.flatnonzero(np.abs(lam - lam[c].mean()) <= 1e-2 * abs(lam[c].mean()))
        sigma = lam[block].min() - 1e-4 * abs(lam[block].min())
        solve = backend.factorize((Kf - sigma * Mf).tocsr())
        P = Phi[free][:, block]
        for _ in range(2):
            Y = solve(Mf @ P).reshape(P.shape)
            Kr, Mr = Y.T @ (Kf @ Y), Y.T @ (Mf @ Y)
            w, V = scipy.linalg.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T))
            P = Y @ V
        Phi[np.ix_(free, block)] = P
        lam[block] = w
    return lam, Phi


@dataclass
class _Partials:
    """Derivatives at fixed positions of one variable: residual dR (reduced), tangent dK and
    mass dM (reduced; dK None for rest lengths, whose part is in the tangent difference),
    tendon element forces dN_t, bar forces dN_b, tendon areas dA_t (per tendon), Euler loads
    dNcr (per bar), mass dm."""

    dR: np.ndarray
    dK: object
    dM: object
    dN_t: np.ndarray
    dN_b: np.ndarray
    dA_t: np.ndarray
    dNcr: np.ndarray
    dm: float


def _subset(trusses: TrussSet, mask: np.ndarray) -> TrussSet:
    return TrussSet(conn=trusses.conn[:, mask], L=trusses.L[mask], EA=trusses.EA[mask],
                    rhoA=trusses.rhoA[mask], tension_only=trusses.tension_only[mask])


def _partials(model, v: Variable, g: np.ndarray, x, dL: np.ndarray, Ncr: np.ndarray, T) -> _Partials:
    """The :class:`_Partials` of variable v (g: its column of G, dL: of the element rest
    lengths; T: the reduced-to-full map of the residual)."""
    nt, nb = len(model.system.tendons), Ncr.size
    tendons, bars = model.tendons, getattr(model, "bars", None)
    zt, zb = np.zeros(tendons.ne), np.zeros(nb)
    if v.kind in ("rest_length", "angle"):         # an angle moves the rest lengths (configuration)
        dR = T.T @ (truss_rest_length_derivatives(x, tendons, dofmap=model.dofmap) @ dL)
        lumped = model.lumped_tendon_mass
        dM = T.T @ (truss_mass(dataclasses.replace(tendons, L=tendons.L + dL), model.dofmap, lumped=lumped)
                    - truss_mass(tendons, model.dofmap, lumped=lumped)) @ T
        _, _, dN_dL, _ = truss_axial_force_derivatives(x, tendons)
        return _Partials(dR, None, dM, dN_dL * dL, zb, np.zeros(nt), np.zeros(nb),
                         float(model.tendon_rhoA @ g))
    if v.kind == "membrane_radius":
        # the membrane's reference mesh scales with r_mb: central differences of the assembled
        # residual and mass at fixed positions (the bars' and tendons' parts cancel exactly);
        # the residual's Richardson-extrapolated, error O(d^4): the membrane stresses respond to
        # du/dp by E / (element size), so a relative error of 1e-8 in dR showed in them
        r, d = model.system.r_mb, 1e-4 * model.system.r_mb
        xr = model.reduce(x)
        pm = {k: with_radius(model, r + k * d) for k in (2, 1, -1, -2)}
        R = {k: m.residual(xr, tangent=False)[0] for k, m in pm.items()}
        dR = (8 * (R[1] - R[-1]) - (R[2] - R[-2])) / (12 * d)
        return _Partials(dR, None, (pm[1].mass() - pm[-1].mass()) / (2 * d), zt, zb, np.zeros(nt),
                         np.zeros(nb), (total_mass(pm[1]) - total_mass(pm[-1])) / (2 * d))
    if v.kind == "thickness":
        h = model.membrane.material.h
        f, K = model.membrane_element.internal(State(x=x))
        M = model.membrane_element.mass()
        return _Partials(T.T @ f / h, T.T @ K @ T / h, T.T @ M @ T / h, zt, zb, np.zeros(nt),
                         np.zeros(nb), float(M.sum()) / 3.0 / h)
    if v.kind == "bar_diameter":
        bar = model.system.bar
        s = area_derivative(bar.d) / bar.area                  # d/dd of a quantity linear in A
        r = truss_internal(x, bars, dofmap=model.dofmap)
        M = model.bar_element.mass()
        return _Partials(T.T @ r.f * s, T.T @ r.K @ T * s, T.T @ M @ T * s, zt, r.N * s,
                         np.zeros(nt), 4.0 * Ncr / bar.d, float(bars.rhoA @ bars.L) * s)
    # a tendon family's diameter
    d = model.system.tendon_section(model.system.tendons[v.tendons[0]]).d
    s = area_derivative(d) / model.tendon_area[v.tendons[0]]
    in_fam = np.isin(model.topology.tendon_of_element, v.tendons)
    sub = _subset(tendons, in_fam)
    r = truss_internal(x, sub, dofmap=model.dofmap)
    M = truss_mass(sub, model.dofmap, lumped=model.lumped_tendon_mass)
    dN = zt.copy()
    dN[in_fam] = r.N * s
    dA = np.zeros(nt)
    dA[list(v.tendons)] = area_derivative(d)
    return _Partials(T.T @ r.f * s, T.T @ r.K @ T * s, T.T @ M @ T * s, dN, zb, dA, np.zeros(nb),
                     float(sub.rhoA @ sub.L) * s)


def rebuilt(model, system):
    """The model of ``model``'s kind, options (mesh density, elements, attachment, law) and
    rest lengths for ``system``."""
    topo = model.topology
    common = dict(mesh_n=topo.mesh.n, tendon_elements=topo.tendon_elements, attachment=topo.attachment,
                  patch=model.patch, rest_lengths=model.rest_lengths.copy(), membrane_law=model.membrane_law)
    if model.name == "sbc":
        from tmfem.models.sbc.model import SBCModel
        per_bar = model.numbering.bar_elements // (2 if system.deployable else 1)   # two segments with H_1j
        return SBCModel(system, bar_elements=per_bar, **common)
    from tmfem.models.mtc.model import MTCModel
    return MTCModel(system, lumped_tendon_mass=model.lumped_tendon_mass, rigid_bar_points=system.deployable,
                    tendon_law=model.tendon_law, **common)


def with_radius(model, r_mb: float):
    """The model (MTC or SBC) of ``model``'s system with the membrane radius r_mb (same mesh density,
    options and rest lengths): its membrane mesh is the same mesh scaled."""
    return rebuilt(model, model.system.replace(**with_membrane_radius(model.system, r_mb)))


def _section_partials(model, v: Variable, state, Ncr: np.ndarray) -> _Partials:
    """The :class:`_Partials` of a thickness, diameter or membrane-radius variable v of the SBC
    model at ``state``: the five-point central difference (8 (F(d) - F(-d)) - (F(2d) - F(-2d))) / 12d
    of the residual, tangent, mass, member forces and total mass of the model rebuilt with
    p0 + k d, d = 1 % of p0. Exact (to rounding) for a polynomial of degree <= 4 in p: the
    beams' A, I, J go as d^2, d^4, d^4, the tendons' A as d^2; the degenerated shell's
    thickness also enters its metric (not a polynomial): truncation O(d^4), about 1e-8. The
    membrane radius scales the shells' reference mesh at the fixed state (not a polynomial
    either), with d = 1e-4 r_mb as on the MTC model (:func:`_partials`): the shells' stresses
    respond to du/dp by E / (element size)."""
    p0 = variable_values(model.system, model.rest_lengths, [v])[0]
    d = (1e-4 if v.kind == "membrane_radius" else 1e-2) * p0
    ms = {k: rebuilt(model, apply_design(model.system, model.rest_lengths, [v], [p0 + k * d])[0])
          for k in (2, 1, -1, -2)}

    def rate(y: dict):
        return (8 * (y[1] - y[-1]) - (y[2] - y[-2])) / (12 * d)

    RK = {k: m.residual(state) for k, m in ms.items()}
    forces = {k: m.member_forces(state) for k, m in ms.items()}
    dK = rate({k: K for k, (_, K) in RK.items()})
    dA = np.zeros(len(model.system.tendons))
    if v.kind == "tendon_diameter":
        dA[list(v.tendons)] = area_derivative(p0)
    dNcr = 4.0 * Ncr / p0 if v.kind == "bar_diameter" else np.zeros(Ncr.size)
    return _Partials(rate({k: R for k, (R, _) in RK.items()}), 0.5 * (dK + dK.T),
                     rate({k: m.mass(state) for k, m in ms.items()}),
                     rate({k: f["tendon_element"] for k, f in forces.items()}),
                     rate({k: f["bar"] for k, f in forces.items()}), dA, dNcr,
                     float(rate({k: total_mass(m) for k, m in ms.items()})))


def total_mass(model) -> float:
    """Total mass [kg]: bars rho A l, tendons rho A r (rest lengths), membrane rho h area."""
    sysm = model.system
    mat = sysm.membrane
    return float(sysm.bar.mass(float(sysm.l.sum())) + model.tendons.rhoA @ model.tendons.L
                 + mat.rho * mat.h * model.membrane_area())


def design_sensitivities(model, *, equilibrium=None, variables="groups", k: int = 4,
                         node: str | None = None, axis: int = 2, thickness: bool = False,
                         aperture: float | None = None, ks_width: float | None = None,
                         wrinkle_width: float | None = None, step: float = 1e-4) -> Sensitivities:
    """Responses of an MTC or SBC model at its static equilibrium and their exact derivatives
    with respect to the design variables (module docstring: direct method, eigenvalue and
    cluster derivatives; :mod:`tmfem.design.kinematics` for the SBC model's rotations).

    Parameters
    ----------
    model : MTCModel or SBCModel
        On the SBC model the partials of the thickness, diameter and membrane-radius variables are
        :func:`_section_partials`; its rest lengths and angles are those of the MTC model. On the
        PETSc backend (one rank) the matrices are assembled serially and factorised and
        eigen-solved by PETSc.
    equilibrium : Equilibrium, optional
        A converged ``model.equilibrium()`` at the model's current rest lengths (default:
        solved here from the undeformed membrane).
    variables : {"groups", "tendons"} or sequence of str
        One variable per tendon group (r_t = r_t0 + p_group), per tendon, or the named
        variables of :func:`tmfem.design.variables.parse_variables`.
    k : int
        Number of lowest eigenvalues.
    node : str, optional
        Label of a system node (``"H_11"``, ``"A_12"``) whose coordinate ``axis`` is a response.
    thickness : bool
        Add the membrane thickness h as the last variable (``"h_membrane"``).
    aperture : float, optional
        The wrinkling indicator ``membrane_min_principal`` over the Gauss points within
        ``aperture`` times the membrane's inradius of its centre (default: all).
    ks_width : float, optional
        Width w of the KS aggregates of the membrane stresses [Pa] (default 1e-6 E of the
        membrane: within w ln(n) of the extreme of n Gauss points).
    wrinkle_width : float, optional
        Width w of the smooth step of the wrinkled area ``wrinkled_area`` [Pa] (default
        1e-6 E of the membrane; :func:`tmfem.design.responses.smooth_step`).
    step : float
        Relative step of the directional central difference of the tangent.
    """
    if not (isinstance(k, (int, np.integer)) and k >= 1):
        raise InputError(f"k: expected a positive integer, found {k!r}")
    if axis not in (0, 1, 2):
        raise InputError(f"axis: expected 0, 1 or 2, found {axis!r}")
    if getattr(model, "name", None) not in ("mtc", "sbc"):
        raise InputError(f"sensitivities: expected an MTC or SBC model, found {getattr(model, 'name', model)!r}")
    if model.tendon_law != "cable":
        raise InputError(f"sensitivities: expected a model with tendon_law='cable' (EA fixed as the "
                         f"rest length changes), found {model.tendon_law!r}")
    distributed = model.distributed is not None
    if distributed and getattr(getattr(model.backend, "comm", None), "size", 1) > 1:
        raise InputError("sensitivities: expected one process (the PETSc backend on one rank), found "
                         f"{model.backend.comm.size} ranks")
    if aperture is not None and not (isinstance(aperture, (int, float)) and aperture > 0):
        raise InputError(f"aperture: expected a positive fraction of the inradius, found {aperture!r}")
    width = 1e-6 * model.system.membrane.E if ks_width is None else ks_width
    if not (isinstance(width, (int, float)) and width > 0):
        raise InputError(f"ks_width: expected a positive stress [Pa], found {ks_width!r}")
    wrinkle_w = 1e-6 * model.system.membrane.E if wrinkle_width is None else wrinkle_width
    if not (isinstance(wrinkle_w, (int, float)) and wrinkle_w > 0):
        raise InputError(f"wrinkle_width: expected a positive stress [Pa], found {wrinkle_width!r}")
    node_at = None if node is None else model.topology.system_node[model.system.node_index(node)]
    vs = parse_variables(model.system, variables)
    if thickness and "h_membrane" not in [v.name for v in vs]:
        vs.append(Variable("h_membrane", "thickness"))
    sbc = model.name == "sbc"
    eq = model.equilibrium() if equilibrium is None else equilibrium
    kin = kinematics(model, eq)
    names = [v.name for v in vs]
    design = design_of(model.system, **design_options(model)) if any(v.kind == "angle" for v in vs) else None
    rates = {j: design_rates(model, v.angle, v.stage, design=design) for j, v in enumerate(vs) if v.kind == "angle"}
    G = _rest_length_map(model, vs, rates)
    n_var = len(vs)
    topo, free = model.topology, model.free
    x = kin.x
    tendons = model.tendons
    kt = topo.tendon_elements
    e2t = sp.csr_matrix((np.full(tendons.ne, 1.0 / kt), (np.arange(tendons.ne), topo.tendon_of_element)),
                        shape=(tendons.ne, G.shape[0]))
    dL = e2t @ G                                                       # dL_e / dp  (ne, n_var)
    Ncr = np.array([model.system.bar.euler_critical_load(l) for l in model.system.l.ravel()])
    state0 = kin.point(np.zeros(model.free.size)) if sbc else None
    parts = [_section_partials(model, v, state0, Ncr) if sbc and v.kind not in ("rest_length", "angle")
             else _partials(model, v, G[:, j], x, dL[:, j], Ncr, kin.T) for j, v in enumerate(vs)]
    dR = np.column_stack([p.dR for p in parts])
    n_red = dR.shape[0]
    # the assembled tangent (a distributed backend's equilibrium holds its own matrix type)
    K = eq.tangent if eq.tangent is not None and not distributed else kin.tangent(kin.point(np.zeros(n_red)))
    solve = model.backend.factorize(sp.csr_matrix(K)[free][:, free])
    # an angle of a 1-N system moves the pinned bases: their motion is prescribed
    du = np.zeros((n_red, n_var))
    for j, (_, base_rate) in rates.items():
        du[:, j] = kin.supports(base_rate)
    du[free] = solve(-(dR + sp.csr_matrix(K) @ du)[free]).reshape(-1, n_var)
    dx = np.stack([kin.positions(du[:, j]) for j in range(n_var)], axis=-1)   # (3, nn, n_var)

    # eigenvalues: two extra modes so that a cluster at the k-th is complete
    n_modes = min(k + 2, int(free.sum()))
    K0 = sp.csr_matrix(K)
    K0 = 0.5 * (K0 + K0.T)
    M0 = kin.mass(kin.point(np.zeros(n_red)))
    modes = lowest_modes(K0, M0, k=n_modes, free=free, sigma=-1.0, backend=model.backend) if distributed \
        else model.modes(k=n_modes, at=eq)
    lam, Phi = modes.omega2, modes.shapes
    clusters = [c for c in _clusters(lam) if c[0] < k]
    lam, Phi = _refined_modes(K0, M0, lam, Phi, clusters, free, model.backend)
    r0 = model.rest_lengths.copy()
    scale = step * max(float(np.abs(x).max()), float(r0.max()))
    dlam = np.zeros((k, n_var))
    dNb_state = np.zeros((Ncr.size, n_var))
    for j in range(n_var):
        # the step moves the state by `scale` at most, whatever the variable's units; an angle's
        # (per degree, rates of 1e-2 m) by `scale` exactly: a smaller move loses digits to rounding
        floor = 0.0 if vs[j].kind == "angle" else 1.0
        h = scale / max(floor, float(np.abs(du[:, j]).max()), float(np.abs(G[:, j]).max()))
        Kpm, Mpm, Npm = [], [], []
        try:
            for sgn in (1.0, -1.0):
                model.set_tendon_lengths(r0 + sgn * h * G[:, j])
                pt = kin.point(sgn * h * du[:, j])
                if vs[j].kind == "membrane_radius" and not sbc:   # the state and the reference mesh together
                    Kpm.append(with_radius(model, model.system.r_mb + sgn * h).residual(pt)[1])
                    continue
                Kpm.append(kin.tangent(pt))
                if sbc:                  # the shells' and beams' mass follows the directors
                    Mpm.append(kin.mass(pt))
                    Npm.append(kin.bar_forces(pt))
        finally:
            model.set_tendon_lengths(r0)
        dK = (Kpm[0] - Kpm[1]) / (2 * h)
        if parts[j].dK is not None:
            dK = dK + parts[j].dK
        dM = (Mpm[0] - Mpm[1]) / (2 * h) if sbc else parts[j].dM
        if sbc and parts[j].dK is not None:          # a section's own part (rest lengths: in Mpm)
            dM = dM + parts[j].dM
        if sbc:
            dNb_state[:, j] = (Npm[0] - Npm[1]) / (2 * h)
        for c in clusters:
            P = Phi[:, c]
            A = P.T @ (dK @ P) - lam[c].mean() * (P.T @ (dM @ P))
            ev = np.linalg.eigvalsh(0.5 * (A + A.T))
            keep = c < k
            dlam[c[keep], j] = ev[keep]
    lam = lam[:k]
    freq = np.sqrt(np.abs(lam)) / (2 * np.pi)
    dfreq = dlam / (4 * np.pi * np.sqrt(np.abs(lam)))[:, None]

    # members: N(l(x), L, A) of tendon elements and bars
    def member_forces(trusses, partial):
        N, dN_dl, _, e = truss_axial_force_derivatives(x, trusses)
        c0, c1 = trusses.conn
        dN = dN_dl[:, None] * np.einsum("ie,iej->ej", e, dx[:, c1] - dx[:, c0]) + partial
        return N, dN

    N, dN = member_forces(tendons, np.column_stack([p.dN_t for p in parts]))
    area = model.tendon_area[topo.tendon_of_element]
    dA = np.column_stack([p.dA_t for p in parts])
    dstress = dN / area[:, None] - (N / area**2)[:, None] * dA[topo.tendon_of_element]
    if sbc:                              # the beams' axial forces, along (du/dp, dp)
        Nb, dNb = kin.bar_forces(kin.point(np.zeros(n_red))), dNb_state + np.column_stack([p.dN_b for p in parts])
    else:
        Nb, dNb = member_forces(model.bars, np.column_stack([p.dN_b for p in parts]))
    dNcr = np.column_stack([p.dNcr for p in parts])
    i_f, i_s = int(np.argmax(N)), int(np.argmax(N / area))
    position = d_position = None
    if node_at is not None:
        position, d_position = float(x[axis, node_at]), dx[axis, node_at].copy()

    # per tendon: the mean of its elements (equal in statics)
    t_force, d_t_force = e2t.T @ N, e2t.T @ dN
    t_stress, d_t_stress = e2t.T @ (N / area), e2t.T @ dstress
    buck = -Nb / Ncr
    d_buck = -dNb / Ncr[:, None] + (Nb / Ncr**2)[:, None] * dNcr
    delta, d_delta = corner_deltas(model, x, dx)
    d_delta[:, [v.kind == "membrane_radius" for v in vs]] -= 1.0          # Delta = |c_j - c| - r_mb
    values = {"mass": total_mass(model), "omega2": lam, "freq": freq,
              "tendon_force": t_force, "tendon_stress": t_stress,
              "bar_force": Nb, "bar_buckling": buck, "corner_delta": delta}
    grads = {"mass": np.array([p.dm for p in parts]), "omega2": dlam, "freq": dfreq,
             "tendon_force": d_t_force, "tendon_stress": d_t_stress,
             "bar_force": dNb, "bar_buckling": d_buck, "corner_delta": d_delta}
    for name, vec, pick in (("tendon_force_min", "tendon_force", np.argmin),
                            ("tendon_force_max", "tendon_force", np.argmax),
                            ("tendon_stress_max", "tendon_stress", np.argmax),
                            ("bar_buckling_max", "bar_buckling", np.argmax),
                            ("corner_delta_max", "corner_delta", np.argmax)):
        i = int(pick(values[vec]))
        values[name], grads[name] = float(values[vec][i]), grads[vec][i].copy()
    def radius_fields(j):
        def fields(step):
            return [kinematics(with_radius(model, model.system.r_mb + sgn * step), eq).membrane(
                kin.point(sgn * step * du[:, j])) for sgn in (1.0, -1.0)]
        return fields

    moved = {j: radius_fields(j) for j, v in enumerate(vs) if v.kind == "membrane_radius"}
    for name, (val, grad) in membrane_aggregates(model, kin, du, width=width, aperture=aperture,
                                                 wrinkle_width=wrinkle_w, moved=moved).items():
        values[name], grads[name] = val, grad
    # the Gauss points' areas scale with r_mb^2: d(sum H dA) = sum dH dA + 2 A_w / r_mb
    for j in (j for j, v in enumerate(vs) if v.kind == "membrane_radius"):
        grads["wrinkled_area"][j] += 2.0 * values["wrinkled_area"] / model.system.r_mb
    values["surface_rms"], grads["surface_rms"] = surface_rms(model, x, dx)
    if position is not None:
        values["position"], grads["position"] = position, d_position
    return Sensitivities(names=names, omega2=lam, d_omega2=dlam, freq_hz=freq, d_freq_hz=dfreq,
                         clusters=clusters, max_tendon_force=float(N[i_f]), d_max_tendon_force=dN[i_f],
                         max_tendon_stress=float(N[i_s] / area[i_s]),
                         d_max_tendon_stress=dstress[i_s],
                         position=position, d_position=d_position, du=du,
                         values=values, gradients=grads)
