"""Region of symmetric equilibria over (theta, psi) (3.3.2, eq. 5.97).

Degrees of freedom. A symmetric M-N system is described by theta_i, psi_i, l_i, r_i of
each stage, sigma_i, z_i of stages i >= 2 and r_mb. The reduced equilibrium matrix of
3.3.2 has 5M-3 rows and 6M-4 columns, so for M >= 2 it always has a null space of
dimension >= M-1 (1 for a 2-3 system): every geometry has a force ratio that balances it,
and equilibrium is the *inequality* that this null vector is positive (tendons taut,
F_Delta > 0) together with Delta > 0 (eq. 3.22). The equilibria of a 2-3 system with l,
r_1 and r_mb fixed therefore form an open region in the 7 parameters (theta_1, psi_1,
theta_2, psi_2, r_2, z_2, sigma_2), not a surface; r_2, z_2 and sigma_2 of Table 6.4 are
free choices, not results of the method.

Eq. 5.97 (ch. 8) parametrises symmetric configurations by two numbers: theta_ij = theta and
psi_ij = psi + sigma_i + 2 j pi / N, i.e. theta_1 = theta_2 = theta and the azimuth of each
stage relative to its own base equal to psi. The map below evaluates that family on a
(theta, psi) grid with everything else (l_i, r_i, z_i, sigma_i, r_mb) held at the values
of the given system: these are what the axes fix.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from tmfem.equilibrium.general import positive_null_vector, symmetric_matrix
from tmfem.equilibrium.symmetric import membrane_delta_system
from tmfem.errors import InputError
from tmfem.system.geometry import SymmetricConfig, wrap_angle


def configuration_5_97(system, theta: float, psi: float, *, r=None, z=None,
                       sigma=None) -> SymmetricConfig:
    """The symmetric configuration of eq. 5.97 for (theta, psi).

    r, z, sigma (length M, stage 1 entries 0 for z and sigma) default to those of
    ``system``; pass them to follow another rule for the stage bases.
    """
    c = system.symmetric
    if c is None:
        raise InputError(f"system {system.name!r}: expected a symmetric system (3.3.1), found "
                         "no symmetric parametrisation")
    M = c.M
    sg = c.sigma if sigma is None else np.asarray(sigma, dtype=float)
    return SymmetricConfig(theta=np.full(M, theta), psi=psi + sg, sigma=sg,
                           z=c.z if z is None else z, r=c.r if r is None else r, l=c.l)


def with_configuration(system, cfg: SymmetricConfig):
    """A copy of a symmetric system at another symmetric configuration (eqs. 3.19-3.20):
    q, base A_1j and bar lengths l_ij from ``cfg``; rest lengths dropped."""
    if system.M != cfg.M:
        raise InputError(f"expected a configuration with M = {system.M} stages, found {cfg.M}")
    return system.replace(symmetric=cfg, rest_lengths=None, **cfg.system_arrays(system.N))


@dataclass
class EquilibriumMap:
    """Result of :func:`equilibrium_map`.

    Attributes
    ----------
    theta, psi : (n_theta,), (n_psi,) grid axes [rad].
    feasible : (n_theta, n_psi) bool: positive null vector and Delta > 0.
    positive : (n_theta, n_psi) bool: positive null vector of the reduced matrix.
    margin : (n_theta, n_psi) smallest entry of the null vector (LP of 3.2, entries
        normalised to sum 1; > 0 when positive).
    Delta : (n_theta, n_psi) eq. 3.22 [m] (NaN where the point could not be built).
    ratios : (n_theta, n_psi, 6M-4) null vector scaled to F_Delta = 1 (NaN where none).
    columns : names of the null-vector entries (eq. 3.26).
    fixed : the parameters the axes hold fixed.
    reason : (n_theta, n_psi) str: why a point is infeasible without being evaluated (the
        ``bases`` rule has no stage base there, e.g. no r_2 of eq. 3.22 reaches the
        membrane); "" where the point was evaluated.
    """

    theta: np.ndarray
    psi: np.ndarray
    feasible: np.ndarray
    positive: np.ndarray
    margin: np.ndarray
    Delta: np.ndarray
    ratios: np.ndarray
    columns: list
    fixed: dict
    reason: np.ndarray | None = None

    def __post_init__(self):
        if self.reason is None:
            self.reason = np.full(self.feasible.shape, "", dtype=object)

    def to_dict(self) -> dict:
        return {"theta_deg": np.degrees(self.theta).tolist(), "psi_deg": np.degrees(self.psi).tolist(),
                "feasible": self.feasible.tolist(), "positive": self.positive.tolist(),
                "margin": np.where(np.isfinite(self.margin), self.margin, None).tolist(),
                "Delta": np.where(np.isfinite(self.Delta), self.Delta, None).tolist(),
                "reason": self.reason.tolist(), "columns": self.columns, "fixed": self.fixed}


def equilibrium_map(system, *, theta, psi, bases=None, progress=None) -> EquilibriumMap:
    """Evaluate the family of eq. 5.97 on a (theta, psi) grid [rad].

    At each point: the reduced (5M-3) x (6M-4) matrix of 3.3.2, the LP search for a
    positive null vector, and Delta of eq. 3.22.

    Parameters
    ----------
    bases : callable, optional
        ``bases(theta, psi) -> dict`` with any of ``r``, ``z``, ``sigma`` (arrays of length
        M) giving the stage bases along the family (e.g. a reconstructed deployment rule);
        by default they are held at the values of ``system``. Where the rule raises
        :class:`~tmfem.errors.InputError` (no admissible base at that point, e.g.
        :func:`tmfem.reference.tables.deployment_bases` where no r_2 satisfies eq. 3.22) the point is
        marked infeasible, its message kept in ``reason``, and the map goes on.
    progress : callable, optional
        ``progress(done, total)`` after each row of theta (the CLI draws a bar with it).
    """
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    psi = np.atleast_1d(np.asarray(psi, dtype=float))
    c = system.symmetric
    if c is None or system.r_mb is None:
        raise InputError(f"system {system.name!r}: the map needs a symmetric system with r_mb")
    shape = (theta.size, psi.size)
    positive = np.zeros(shape, dtype=bool)
    margin = np.full(shape, -np.inf)
    Delta = np.zeros(shape)
    reason = np.full(shape, "", dtype=object)
    cols = symmetric_matrix(system).cols
    ratios = np.full(shape + (len(cols),), np.nan)
    for a, th in enumerate(theta):
        for b, ps in enumerate(psi):
            try:
                rule = bases(th, ps) if bases else {}
            except InputError as exc:       # no stage base at this point: infeasible
                reason[a, b] = f"bases rule: {exc}"
                Delta[a, b] = np.nan
                continue
            cfg = configuration_5_97(system, th, ps, **rule)
            s = with_configuration(system, cfg)
            S = symmetric_matrix(s)
            nv = positive_null_vector(S.A)
            positive[a, b] = nv.exists
            margin[a, b] = nv.margin
            if nv.dim == 1 and abs(nv.x[-1]) > 1e-12 * np.abs(nv.x).max():
                ratios[a, b] = nv.x / nv.x[-1]
            Delta[a, b] = membrane_delta_system(s)
        if progress is not None:
            progress(a + 1, theta.size)
    fixed = {"l": c.l.tolist(), "r": c.r.tolist(), "z": c.z.tolist(),
             "sigma_deg": np.degrees(c.sigma).tolist(), "r_mb": system.r_mb,
             "rule": "eq. 5.97: theta_i = theta, psi_i = psi + sigma_i"
                     + ("; bases from a user rule" if bases else "")}
    return EquilibriumMap(theta=theta, psi=psi, feasible=positive & (Delta > 0), positive=positive,
                          margin=margin, Delta=Delta, ratios=ratios, columns=cols, fixed=fixed,
                          reason=reason)


def best_bases(system, theta: float, psi: float, *, starts: int = 8, seed: int = 0,
               r_bounds=(0.05, 2.0), z_bounds=(0.05, 2.5), maxiter: int = 300,
               r_top: float | None = None) -> dict:
    """Stage bases (r_i, z_i, sigma_i, i >= 2) that maximise the null-vector margin at
    (theta, psi) of eq. 5.97 with Delta > 0 (eq. 3.22); a multi-start Nelder-Mead search.

    The bases are the free parameters of a symmetric M-N equilibrium (see the module
    docstring); this gives one admissible choice, e.g. a rule ``bases`` for
    :func:`equilibrium_map`. r_1, l_i and r_mb are those of ``system``. ``r_top`` [m] holds
    the top-stage radius r_M (e.g. eq. 3.22 solved for a given Delta,
    :func:`tmfem.equilibrium.deployment_path.top_radius_for_delta`); the search is then over
    r_i (2 <= i < M), z_i and sigma_i (i >= 2). The first start is the bases of ``system``.

    Returns
    -------
    dict with ``r``, ``z``, ``sigma`` (length M), ``margin`` (> 0: a positive null vector
    exists), ``Delta`` and ``feasible``.
    """

    c = system.symmetric
    if c is None or c.M < 2:
        raise InputError("best_bases: expected a symmetric system with M >= 2 stages")
    M = c.M
    rng = np.random.default_rng(seed)
    nr = M - 1 if r_top is None else M - 2          # free radii r_2 .. r_M (or r_{M-1})
    top = [] if r_top is None else [float(r_top)]

    def unpack(p):
        return (np.concatenate([[c.r[0]], p[:nr], top]), np.concatenate([[0.0], p[nr:nr + M - 1]]),
                np.concatenate([[0.0], p[nr + M - 1:]]))

    def evaluate(p):
        r, z, sg = unpack(p)
        if np.any(r[1:1 + nr] < r_bounds[0]) or np.any(r[1:1 + nr] > r_bounds[1]) or \
                np.any(z[1:] < z_bounds[0]) or np.any(z[1:] > z_bounds[1]):
            return -np.inf, -np.inf
        cfg = configuration_5_97(system, theta, psi, r=r, z=z, sigma=sg)
        s = with_configuration(system, cfg)
        nv = positive_null_vector(symmetric_matrix(s).A)
        return nv.margin, membrane_delta_system(s)

    def objective(p):
        m, D = evaluate(p)
        if not np.isfinite(m):
            return 10.0
        return -m + 10.0 * max(0.0, -D)

    best = None
    for k in range(starts):
        p0 = np.concatenate([rng.uniform(*r_bounds, M - 1)[:nr], rng.uniform(*z_bounds, M - 1),
                             rng.uniform(-np.pi, np.pi, M - 1)])
        if k == 0:
            p0 = np.concatenate([c.r[1:1 + nr], c.z[1:], c.sigma[1:]])
        res = minimize(objective, p0, method="Nelder-Mead",
                       options={"maxiter": maxiter, "xatol": 1e-6, "fatol": 1e-9})
        if best is None or res.fun < best.fun:
            best = res
    m, D = evaluate(best.x)
    r, z, sg = unpack(best.x)
    sg = wrap_angle(sg)
    sg[0] = 0.0
    return {"r": r, "z": z, "sigma": sg, "margin": float(m), "Delta": float(D),
            "feasible": bool(m > 0 and D > 0)}
