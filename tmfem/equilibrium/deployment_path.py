"""An automatic deployment path through the symmetric equilibria of an M >= 2 system.

A deployment of 7.4 moves a symmetric system (eqs. 3.19-3.20) from its packaged to its
deployed configuration through configurations that are equilibria. For M >= 2 stages the
bar attitudes (theta_i, psi_i) alone do not fix a configuration: the stage bases
(r_i, z_i, sigma_i, i >= 2) are free parameters of the family (3.3.2, eq. 5.97). The path of
:class:`SymmetricPath`, as a function of the progress s in [0, 1]:

* theta_i(s) and the azimuth relative to the stage base, psi_i(s) - sigma_i(s), linear
  between their end values (eq. 5.97 keeps them equal across stages when both ends do);
* the membrane stretch Delta(s) = Delta_0 + s (Delta_e - Delta_0) (eq. 3.22), which keeps the
  prestress between its end values as the 1-N(D) rule of psi does: the top-stage radius r_M
  is eq. 3.22 solved for r_M (:func:`top_radius_for_delta`);
* every other base parameter p (r_i for 2 <= i < M, z_i, sigma_i for i >= 2) linear plus a
  smooth correction that vanishes at both ends,
  p(s) = p_0 + s (p_e - p_0) + sum_k c_pk sin(k pi s), k = 1..K.

:func:`automatic_path` starts from c = 0 (the linear bases) and, where some point of the path
is not feasible, maximises the smallest feasibility margin over the path with respect to the
coefficients c (Nelder-Mead), a continuation of feasible bases from one end to the other. A
point is feasible (:func:`path_feasibility`) when the reduced symmetric equilibrium matrix of
3.3.2 has a positive null vector (every tendon group in tension with the membrane stretched),
Delta > 0, and every rest length (eqs. 3.8-3.9 with the tendon forces scaled to the membrane
force F_Delta = kappa Delta of the linear plane-stress membrane) lies in [r_min, L). The path
is checked at every s on a grid of the stated resolution; when no path is found the error
names the worst point (s, theta, psi) and the condition that fails there.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from tmfem.errors import InfeasibleDesign, InputError
from tmfem.system.geometry import SymmetricConfig, wrap_angle

log = logging.getLogger(__name__)

#: default spacing of the progress values where the path is checked
RESOLUTION = 0.01
#: default number of sine terms of each base correction
HARMONICS = 3


def top_radius_for_delta(*, l_M: float, theta_M: float, psi_rel: float, r_mb: float,
                         Delta: float, N: int, near: float | None = None) -> float:
    """Base radius r_M of the top stage that gives the corner displacement Delta: eq. 3.22,
    (r_mb + Delta)^2 = L^2 + r_M^2 - 2 r_M L sin(psi_rel + pi/N) with L = l_M sin(theta_M),
    solved for r_M. ``psi_rel`` = psi_M - sigma_M [rad]. The smaller root, or the root
    nearest to ``near`` [m] when given.

    Raises
    ------
    InputError
        No real root (the bar cannot reach r_mb + Delta).
    """
    L = l_M * np.sin(theta_M)
    b = 2 * L * np.sin(psi_rel + np.pi / N)
    c = L**2 - (r_mb + Delta)**2
    disc = b * b - 4 * c
    if disc < 0:
        raise InputError(f"eq. 3.22: no top radius gives r_mb + Delta = {r_mb + Delta:.6g} m "
                         f"(bar reach l sin(theta) = {L:.6g} m)")
    roots = (np.array([-1.0, 1.0]) * np.sqrt(disc) + b) / 2
    return float(roots[0] if near is None else roots[np.argmin(np.abs(roots - near))])


@dataclass(frozen=True)
class PathPoint:
    """Feasibility of one configuration of a path (:func:`path_feasibility`).

    margin : smallest entry of the positive null vector of the reduced matrix of 3.3.2 (LP of
        3.2, entries normalised to sum 1), capped by the Delta and rest-length conditions
        (negative where one fails); -inf without any self-stress.
    reason : "" when feasible, else which condition fails.
    """

    margin: float
    Delta: float
    reason: str = ""


def membrane_stiffness(design) -> float:
    """kappa = F_Delta / Delta [N/m] of an equilibrium design (ch. 3: the linear plane-stress
    membrane of eq. 5.8 is pulled radially by Delta at its corners, so F_Delta is linear in
    Delta with a stiffness that depends on the membrane only)."""
    return float(design.F_Delta / design.Delta)


def lpv_grid_point(theta: float, psi: float) -> str:
    """The name of the LPV grid point (theta, psi) [rad] in messages, in degrees."""
    return f"LPV grid point theta = {np.degrees(theta):.4g} deg, psi = {np.degrees(psi):.4g} deg"


def path_feasibility(system, cfg: SymmetricConfig, *, kappa: float | None = None,
                     r_min: float = 0.0) -> PathPoint:
    """Whether ``cfg`` is a feasible equilibrium of the M >= 2 ``system`` (module docstring):
    a positive null vector T_MN of the reduced (5M-3) x (6M-4) matrix of 3.3.2 (eq. 3.26),
    Delta > 0 (eq. 3.22) and, when ``kappa`` [N/m] is given, rest lengths
    r = L EA / (EA + T) (eq. 3.9) in [r_min, L) with T = (T_MN / F_Delta) kappa Delta."""
    from tmfem.equilibrium.general import positive_null_vector, symmetric_matrix
    from tmfem.equilibrium.symmetric_map import with_configuration
    s = with_configuration(system, cfg)
    D = cfg.membrane_delta(system.N, system.r_mb)
    S = symmetric_matrix(s)
    nv = positive_null_vector(S.A)
    if nv.dim == 0:
        return PathPoint(-np.inf, D, "no self-stress (the reduced matrix of 3.3.2 has full column rank)")
    if not nv.margin > 0:
        neg = [f"{c} ({v:+.3g})" for c, v in zip(S.cols, nv.x) if v <= 0]
        return PathPoint(nv.margin, D, "no positive null vector of 3.3.2: force sign of "
                         + ", ".join(neg) + " (a tendon group without tension needs a rest length "
                         "at or above its tendon length, eq. 3.9; F_Delta <= 0: the membrane pushing)")
    if not D > 0:
        return PathPoint(min(nv.margin, D), D, f"membrane not stretched: Delta = {D:.4g} m <= 0 (eq. 3.22)")
    if kappa is None:
        return PathPoint(float(nv.margin), D)
    r = _self_stress_rest_lengths(s, S, nv, kappa=kappa, Delta=D)
    k = int(np.argmin(r - r_min))
    if r[k] < r_min:
        name = s.tendon_names()[k]
        return PathPoint(-1.0, D, f"rest length of {name} {r[k]:.4g} m below the limit r_min = {r_min:.4g} m")
    return PathPoint(float(nv.margin), D)


def _self_stress_rest_lengths(s, S, nv, *, kappa: float, Delta: float) -> np.ndarray:
    """Rest lengths r = L EA / (EA + T) (eq. 3.9) of the system ``s`` with the tendon forces
    of the null vector ``nv`` of its reduced matrix ``S`` (3.3.2) scaled to F_Delta =
    kappa Delta, in the order of ``s.tendons``."""
    from tmfem.fem.truss import linear_rest_length
    groups = {g: x / nv.x[-1] * kappa * Delta for g, x in zip(S.cols[:-1], nv.x[:-1])}
    T = np.array([groups[t.group] for t in s.tendons])
    return linear_rest_length(s.tendon_lengths(), T, s.tendon_EA)


def path_rest_lengths(system, cfg: SymmetricConfig, *, kappa: float) -> np.ndarray:
    """Rest lengths u_d [m] of the symmetric equilibrium ``cfg`` of the M >= 2 ``system``
    (in the order of its tendons): eq. 3.9 with the tendon forces of the positive null vector
    of 3.3.2 scaled to the membrane force F_Delta = kappa Delta (:func:`path_feasibility`).

    Raises
    ------
    InfeasibleDesign
        ``cfg`` is not a feasible equilibrium (the condition of :func:`path_feasibility`).
    """
    from tmfem.equilibrium.general import positive_null_vector, symmetric_matrix
    from tmfem.equilibrium.symmetric_map import with_configuration
    p = path_feasibility(system, cfg)
    if p.reason:
        raise InfeasibleDesign(f"rest lengths along the deployment path: {p.reason}")
    s = with_configuration(system, cfg)
    S = symmetric_matrix(s)
    return _self_stress_rest_lengths(s, S, positive_null_vector(S.A), kappa=kappa, Delta=p.Delta)


@dataclass
class SymmetricPath:
    """The path s -> configuration of the module docstring between ``initial`` and ``final``
    (both of ``system``'s M >= 2 stages), with correction coefficients ``coefficients`` of shape
    (number of corrected parameters, K) [m for r and z, rad for sigma]."""

    system: object
    initial: SymmetricConfig
    final: SymmetricConfig
    coefficients: np.ndarray | None = None
    harmonics: int = HARMONICS
    names: list = field(init=False)

    def __post_init__(self):
        a, b = self.initial, self.final
        M = a.M
        if M < 2 or b.M != M:
            raise InputError(f"automatic path: expected two configurations of an M >= 2 system, "
                             f"found M = {a.M} and {b.M}")
        if not (np.allclose(a.l, b.l) and np.isclose(a.r[0], b.r[0])):
            raise InputError("automatic path: expected the same bar lengths l_i and stage-1 base "
                             f"r_1 at both ends, found l {a.l} / {b.l}, r_1 {a.r[0]:.6g} / {b.r[0]:.6g} m")
        self.names = ([f"r_{i + 1}" for i in range(1, M - 1)] + [f"z_{i + 1}" for i in range(1, M)]
                      + [f"sigma_{i + 1}" for i in range(1, M)])
        if self.coefficients is None:
            self.coefficients = np.zeros((len(self.names), self.harmonics))
        self._Delta = [c.membrane_delta(self.system.N, self.system.r_mb) for c in (a, b)]
        # sigma and psi of the final configuration continuous with the initial ones
        self._sigma_e = a.sigma + wrap_angle(b.sigma - a.sigma)
        rel0 = a.psi - a.sigma
        self._rel_e = rel0 + wrap_angle((b.psi - b.sigma) - rel0)

    def delta(self, s: float) -> float:
        """Delta(s) = Delta_0 + s (Delta_e - Delta_0) [m], the membrane stretch of eq. 3.22
        along the path (module docstring)."""
        return float(self._Delta[0] + s * (self._Delta[1] - self._Delta[0]))

    def config(self, s: float) -> SymmetricConfig:
        """The configuration at progress s (module docstring).

        Raises
        ------
        InputError
            eq. 3.22 has no top radius for Delta(s) at this point.
        """
        a, b, M = self.initial, self.final, self.initial.M
        lerp = lambda x, y: x + s * (y - x)                                     # noqa: E731
        corr = self.coefficients @ np.sin(np.pi * s * np.arange(1, self.coefficients.shape[1] + 1))
        nr = M - 2
        r = lerp(a.r, b.r)
        r[1:M - 1] += corr[:nr]
        z = lerp(a.z, b.z)
        z[1:] += corr[nr:nr + M - 1]
        sigma = lerp(a.sigma, self._sigma_e)
        sigma[1:] += corr[nr + M - 1:]
        theta = lerp(a.theta, b.theta)
        psi = sigma + lerp(a.psi - a.sigma, self._rel_e)
        D = self.delta(s)
        r[-1] = top_radius_for_delta(l_M=a.l[-1], theta_M=theta[-1], psi_rel=psi[-1] - sigma[-1],
                                     r_mb=self.system.r_mb, Delta=D, N=self.system.N, near=r[-1])
        return SymmetricConfig(theta=theta, psi=psi, sigma=sigma, z=z, r=r, l=a.l)

    def point(self, s: float, *, kappa: float, r_min: float = 0.0) -> PathPoint:
        """:func:`path_feasibility` at progress s (a point without a top radius is infeasible)."""
        try:
            cfg = self.config(s)
        except InputError as exc:
            return PathPoint(-1.0, float("nan"), f"stage bases: {exc}")
        return path_feasibility(self.system, cfg, kappa=kappa, r_min=r_min)

    def margins(self, ss, *, kappa: float, r_min: float = 0.0) -> list:
        """The :class:`PathPoint` at every progress value of ``ss``."""
        return [self.point(float(s), kappa=kappa, r_min=r_min) for s in ss]


@dataclass(frozen=True)
class PathReport:
    """What :func:`automatic_path` found: the path, the progress values it was checked at,
    the smallest margin and where, and the optimiser's evaluations (0: the linear bases were
    feasible)."""

    path: SymmetricPath
    checked: np.ndarray
    min_margin: float
    at: float
    evaluations: int

    def to_dict(self) -> dict:
        return {"rule": "auto", "resolution": float(self.checked[1] - self.checked[0]),
                "points_checked": int(self.checked.size), "min_margin": self.min_margin,
                "min_margin_progress": self.at, "optimizer_evaluations": self.evaluations,
                "corrections": {n: c.tolist() for n, c in zip(self.path.names, self.path.coefficients)}}


def automatic_path(system, initial: SymmetricConfig, *, kappa: float, r_min: float = 0.0,
                   resolution: float = RESOLUTION, harmonics: int = HARMONICS,
                   coarse: int = 21, maxiter: int = 400) -> PathReport:
    """A feasible path from ``initial`` (packaged) to ``system.symmetric`` (deployed) of an
    M >= 2 ``system`` (module docstring), checked at every multiple of ``resolution`` in
    [0, 1]. ``kappa``: the membrane's F_Delta / Delta [N/m] (:func:`membrane_stiffness`);
    ``coarse``: progress values the optimiser sees.

    Raises
    ------
    InfeasibleDesign
        No path: the worst point of the best path found, with s, theta, psi and the
        condition that fails there.
    """
    if not (0 < resolution <= 0.5):
        raise InputError(f"path resolution: expected 0 < resolution <= 0.5, found {resolution!r}")
    path = SymmetricPath(system=system, initial=initial, final=system.symmetric, harmonics=harmonics)
    fine = np.linspace(0.0, 1.0, int(round(1 / resolution)) + 1)
    ss = np.linspace(0.0, 1.0, coarse)
    ends = [p.margin for p in path.margins([0.0, 1.0], kappa=kappa, r_min=r_min)]
    target = 0.5 * min(ends)
    evaluations = 0

    def worst(c):
        path.coefficients = c.reshape(path.coefficients.shape)
        return min(p.margin for p in path.margins(ss, kappa=kappa, r_min=r_min))

    if min(ends) > 0 and worst(path.coefficients.ravel()) < target:
        best = {"x": path.coefficients.ravel().copy(), "m": -np.inf}

        def objective(c):
            m = worst(c)
            if m > best["m"]:
                best.update(x=c.copy(), m=m)
            return -m

        def stop(xk):
            if best["m"] >= target:
                raise StopIteration

        scale = 0.05 * float(np.mean(system.symmetric.l))
        x0 = np.zeros(path.coefficients.size)
        simplex = np.vstack([x0] + [x0 + scale * e for e in np.eye(x0.size)])
        res = minimize(objective, x0, method="Nelder-Mead", callback=stop,
                       options={"maxiter": maxiter, "initial_simplex": simplex, "xatol": 1e-6, "fatol": 1e-9})
        evaluations = int(res.nfev)
        path.coefficients = best["x"].reshape(path.coefficients.shape)
        log.info("automatic path: %d evaluations, worst margin %.3g", evaluations, best["m"])
    points = path.margins(fine, kappa=kappa, r_min=r_min)
    k = int(np.argmin([p.margin for p in points]))
    if not points[k].margin > 0:
        s = float(fine[k])
        try:
            c = path.config(s)
            where = (f"theta = {np.degrees(c.theta).round(3).tolist()} deg, psi = "
                     f"{np.degrees(c.psi).round(3).tolist()} deg")
        except InputError:
            where = "no configuration"
        raise InfeasibleDesign(f"deployment path: no path through the symmetric equilibria found "
                               f"from the packaged to the deployed configuration; the best path "
                               f"found fails at s = {s:.3g} ({where}): {points[k].reason}")
    return PathReport(path=path, checked=fine, min_margin=float(points[k].margin), at=float(fine[k]),
                      evaluations=evaluations)


@dataclass(frozen=True)
class PathBases:
    """Stage bases of the eq. 5.97 family at any (theta, psi) from an automatic path: the
    rule ``bases(theta, psi) -> {"r", "z", "sigma"}`` of an LPV grid over the bar attitude of
    stage 1 (8.3) for any symmetric M >= 2 system.

    At (theta, psi) the path's progress is s = (theta - theta_0) / (theta_e - theta_0), held
    in [0, 1] (outside the path's angles the bases of its nearer end); r_i (2 <= i < M), z_i
    and sigma_i are the path's at s, and the top-stage radius r_M is eq. 3.22 solved for the
    path's membrane stretch Delta(s) at the grid's theta and psi
    (:func:`top_radius_for_delta`, the root nearest to the path's). On the path's own azimuth
    (psi = psi_i(s) - sigma_i) the configuration is the path's at s; off it, the membrane
    keeps the path's stretch, as the stage-2 rule of Table 7.7 keeps Delta = 1 mm. Every
    configuration is checked (:func:`path_feasibility` with the membrane stiffness ``kappa``
    [N/m] and the rest-length limit ``r_min`` [m]).
    """

    path: SymmetricPath
    kappa: float
    r_min: float = 0.0

    def __post_init__(self):
        th0, the = self.path.initial.theta[0], self.path.final.theta[0]
        if abs(the - th0) < 1e-9:
            raise InputError("LPV grid on the automatic path: expected different packaged and deployed "
                             f"declination angles theta_1 (the grid's progress), found both "
                             f"{np.degrees(th0):.6g} deg")

    def progress(self, theta: float) -> float:
        """s of the grid angle ``theta`` [rad] on the path, held in [0, 1]."""
        th0, the = self.path.initial.theta[0], self.path.final.theta[0]
        return float(np.clip((theta - th0) / (the - th0), 0.0, 1.0))

    def __call__(self, theta: float, psi: float) -> dict:
        """{"r", "z", "sigma"} (length M) at (theta, psi) [rad] (class docstring).

        Raises
        ------
        InfeasibleDesign
            No top radius reaches the membrane, or the configuration is not a feasible
            equilibrium; the message names theta, psi and the condition.
        """
        where = lpv_grid_point(theta, psi)
        s = self.progress(theta)
        c = self.path.config(s)
        system = self.path.system
        r = np.array(c.r, dtype=float)
        try:
            r[-1] = top_radius_for_delta(l_M=c.l[-1], theta_M=theta, psi_rel=psi, r_mb=system.r_mb,
                                         Delta=self.path.delta(s), N=system.N, near=r[-1])
        except InputError as exc:
            raise InfeasibleDesign(f"{where} (path progress s = {s:.3g}): {exc}") from None
        sigma = np.array(c.sigma, dtype=float)
        cfg = SymmetricConfig(theta=np.full(c.M, theta), psi=psi + sigma, sigma=sigma, z=c.z, r=r, l=c.l)
        p = path_feasibility(system, cfg, kappa=self.kappa, r_min=self.r_min)
        if p.reason:
            raise InfeasibleDesign(f"{where} (path progress s = {s:.3g}) is not a feasible equilibrium: "
                                   f"{p.reason}")
        return {"r": r, "z": np.array(c.z, dtype=float), "sigma": sigma}
