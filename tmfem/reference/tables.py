"""The dissertation's equilibrium tables and their reconstruction (Tables 6.2-6.5, 7.2-7.7, 8.1).

The printed values are collected in :data:`PRINTED` (tables of parameters and stresses); the
printed frequencies (Tables 6.6, 6.7) live in the preset files (``[printed.frequencies_hz]``,
:func:`printed_frequencies`). The functions below evaluate the
symmetric prestress design of chapter 3 fast enough to *fit* unprinted parameters to the
printed rest lengths:

* :func:`symmetric_prestress`: null vector of the reduced matrix of 3.3.2
  (:func:`tmfem.equilibrium.general.symmetric_matrix`) scaled by the membrane corner force
  F_Delta = k_Delta Delta (linear plane-stress FE, :mod:`tmfem.fem.plane_stress`, eq. 3.21-3.22),
  then tendon forces and the rest lengths of eqs. 3.8-3.9, r = EA |d| / (T + EA).
* :func:`fit_rest_lengths`: least squares of the relative rest-length misfit over any set of
  free parameters of a symmetric configuration.

The reconstructions themselves (what was fitted, to which numbers, how well) are recorded in
``docs/validation/errata.md`` and asserted in ``tests/reference/test_tables.py``; ``demos/equilibrium_*.py`` print
them beside the printed tables.
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from tmfem.equilibrium.deployment_path import top_radius_for_delta
from tmfem.errors import InputError
from tmfem.fem.truss import linear_rest_length

#: Values exactly as printed in the dissertation (SI units, angles in degrees).
PRINTED = {
    "6.2": {"theta_deg": 60.0, "psi_deg": 10.0, "l": 2.015, "r1": 0.4286, "rest_S1": 1.529,
            "r_mb": 1.4142},
    "6.3": {"membrane_max_sigma_p1": 2.12e6, "membrane_max_von_mises": 1.91e6,
            "bar_load": 14.53, "bar_critical_load": 19153.0, "tendon_max_stress": 37.98e6},
    "6.4": {"theta_deg": (63.0, 63.0), "psi_deg": (20.0, -46.45), "l": (2.5, 2.5),
            "r": (0.7, 0.503), "r_mb": 1.87, "sigma2_deg": -66.45, "z2": 0.794,
            "rest": {"S1": 1.9425, "V2": 1.9953, "D2": 2.1424, "C2": 0.8204, "R2": 0.8042,
                     "P2": 2.0176, "S2": 2.0939}},
    "6.5": {"membrane_max_sigma_p1": 1.25e6, "membrane_max_von_mises": 1.15e6,
            "bar_load_stage1": 14.48, "bar_load_stage2": 5.02, "bar_critical_load": 19153.0,
            "tendon_max_stress": 33.58e6},
    "7.2": {"bar_E": 11e9, "bar_rho": 800.0, "bar_d_printed": 0.03e-3, "d_SL": 0.8e-3,
            "d_SU": 0.4e-3, "tendon_E": 2e9, "bar_critical_load": 891.9, "l": 2.2},
    "7.3": {"l": 2.2, "r1": 0.79, "r_mb": 1.414,
            "initial": {"theta_deg": 87.6, "psi_deg": 38.4, "rest": {"SL": 0.7502, "SU": 1.4785}},
            "final": {"theta_deg": 75.0, "psi_deg": 30.0, "rest": {"SL": 0.6726, "SU": 1.7720}}},
    "7.4": {"d_SL": 0.8e-3, "d_SU": 0.4e-3, "tendon_E": 2e9, "bar_critical_load": 479.6, "l": 3.0},
    "7.5": {"l": 3.0, "r1": 1.2, "r_mb": 2.0,
            "initial": {"theta_deg": 88.6, "psi_deg": 33.2, "rest": {"SL": 0.6909, "SU": 2.5350}},
            "final": {"theta_deg": 72.0, "psi_deg": 24.5, "rest": {"SL": 0.6566, "SU": 2.7457}}},
    "7.6": {"tendon_E": 2e9, "d": {"S1": 0.254e-3, "S2": 0.254e-3, "V2": 0.254e-3, "R2": 0.254e-3,
                                   "P2": 0.254e-3, "C2": 0.4e-3, "D2": 0.4e-3},
            "bar_critical_load": 1332.3, "l": 1.8},
    "7.7": {"l": 1.8, "r1": 0.75, "r_mb": 1.0,
            "initial": {"theta_deg": 79.63, "psi_deg": (10.0, -24.86),
                        "rest": {"S1": 0.6159, "V2": 0.9624, "D2": 1.0075, "C2": 1.1153,
                                 "R2": 1.3658, "P2": 0.7302, "S2": 0.5070}},
            "final": {"theta_deg": 55.0, "psi_deg": (10.0, -24.86),
                      "rest": {"S1": 1.0286, "V2": 0.7736, "D2": 0.7199, "C2": 1.1094,
                               "R2": 1.4835, "P2": 0.8459, "S2": 1.1831}}},
    "8.1": {"l": 1.8, "bar_rho": 800.0, "bar_d": 0.03, "tendon_E": 2e9, "tendon_d": 0.254e-3,
            "theta_grid_deg": (63.0, 65.86, 68.73, 71.59, 74.45, 77.32),
            "psi_grid_deg": (7.5, 8.36, 9.21), "theta0_deg": 77.32, "theta_e_deg": 63.0,
            "psi0_deg": 8.36, "bar_critical_load": 1332.3},
}


@lru_cache(maxsize=64)
def _k_delta(N: int, r_mb: float, E: float, nu: float, h: float, n: int) -> float:
    from tmfem.fem.plane_stress import PlaneStressMembrane
    from tmfem.system import MembraneMaterial, membrane_corners_regular
    mat = MembraneMaterial(E=E, nu=nu, rho=1.0, h=h)
    return PlaneStressMembrane(corners=membrane_corners_regular(N, r_mb), material=mat,
                               n=n).symmetric_response(1.0).F_Delta


def corner_force_per_Delta(system, *, mesh_n: int = 10) -> float:
    """F_Delta / Delta of the system's regular membrane (linear FE, eq. 3.21), cached."""
    m = system.membrane
    if system.r_mb is None:
        raise InputError(f"system {system.name!r}: expected a regular membrane (r_mb)")
    return _k_delta(system.N, float(system.r_mb), m.E, m.nu, m.h, int(mesh_n))


def printed_frequencies(system) -> dict | None:
    """The natural frequencies [Hz] printed for ``system`` (its file's
    ``[printed.frequencies_hz]``: ``source`` and the columns ``SBC``, ``MTC``, ``COM``, optional
    ``COM_highest``), or None when the file prints none."""
    f = system.printed.get("frequencies_hz")
    return dict(f) if isinstance(f, dict) else None


def __getattr__(name: str):
    """``FREQUENCIES``: the printed frequencies of the presets that carry them, by preset name
    (Tables 6.6 for ``1-4``, 6.7 for ``2-3``; read from the preset files, for tests and demos)."""
    if name == "FREQUENCIES":
        from tmfem.system.presets import list_presets, load_preset
        out = {n: printed_frequencies(load_preset(n)) for n in list_presets()}
        return {n: f for n, f in out.items() if f is not None}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass(frozen=True)
class SymmetricPrestress:
    """Group-wise prestress of a symmetric design (eq. 3.23, 3.26).

    ``groups`` in the order of eq. 3.26; ``per_F`` the null vector T_g / F_Delta; ``length``,
    ``force``, ``rest`` per group; ``Delta`` (eq. 3.22), ``F_Delta``; ``margin`` the smallest
    entry of the positive-null-vector LP (> 0: all tendons taut).
    """

    groups: list
    per_F: np.ndarray
    length: np.ndarray
    force: np.ndarray
    rest: np.ndarray
    Delta: float
    F_Delta: float
    margin: float

    def as_dict(self, values) -> dict:
        return dict(zip(self.groups, np.asarray(values, dtype=float).tolist()))


def symmetric_prestress(system, *, mesh_n: int = 10) -> SymmetricPrestress:
    """Tendon forces and rest lengths of a symmetric design (3.3, eqs. 3.8-3.9, 3.21-3.22).

    The force ratios are the null vector of the reduced matrix of 3.3.2 (no positivity
    imposed: negative entries are reported as they are); F_Delta = k_Delta Delta with
    k_Delta from the linear plane-stress FE on the ``mesh_n`` mesh. A group with T <= -EA
    has no rest length (NaN).
    """
    from tmfem.equilibrium.general import null_space, positive_null_vector, symmetric_matrix
    from tmfem.equilibrium.symmetric import membrane_delta_system

    S = symmetric_matrix(system)
    Z, rel = null_space(S.A, rtol=1e-6)
    if Z.shape[1] != 1:
        # the smallest singular direction (designs given to printed precision)
        _, _, Vt = np.linalg.svd(S.A / np.linalg.norm(S.A, axis=0))
        z = Vt[-1] / np.linalg.norm(S.A, axis=0)
    else:
        z = Z[:, 0]
    if abs(z[-1]) < 1e-14 * np.abs(z).max():
        raise InputError(f"system {system.name!r}: the null vector of 3.3.2 does not load the membrane")
    per_F = z[:-1] / z[-1]
    margin = positive_null_vector(S.A, rtol=1e-6).margin
    groups = S.cols[:-1]
    gid = [t.group for t in system.tendons]
    L = system.tendon_lengths()
    EA = system.tendon_EA
    length = np.array([L[gid.index(g)] for g in groups])
    EAg = np.array([EA[gid.index(g)] for g in groups])
    Delta = membrane_delta_system(system)
    F = corner_force_per_Delta(system, mesh_n=mesh_n) * Delta
    T = per_F * F
    with np.errstate(invalid="ignore", divide="ignore"):
        rest = np.where(T + EAg > 0, linear_rest_length(length, T, EAg), np.nan)
    return SymmetricPrestress(groups=list(groups), per_F=per_F, length=length, force=T,
                              rest=rest, Delta=float(Delta), F_Delta=float(F), margin=float(margin))


def rest_length_misfit(system, printed_rest: dict, *, mesh_n: int = 10) -> dict:
    """Relative misfit (ours - printed) / printed of the rest lengths per printed group."""
    p = symmetric_prestress(system, mesh_n=mesh_n)
    ours = p.as_dict(p.rest)
    return {g: (ours[g] - r) / r for g, r in printed_rest.items()}


def fit_rest_lengths(build, x0, printed_rest_sets, *, mesh_n: int = 10, bounds=(-np.inf, np.inf)):
    """Least-squares fit of free parameters x to printed rest lengths.

    Parameters
    ----------
    build : callable
        ``build(x) -> list of System`` (one per printed configuration).
    x0 : array_like
        Start.
    printed_rest_sets : list of dict
        Printed rest lengths per group, one dict per configuration returned by ``build``.

    Returns
    -------
    x : ndarray, misfit : ndarray (relative, all configurations and groups in order)
    """
    from scipy.optimize import least_squares

    def resid(x):
        out = []
        for s, pr in zip(build(x), printed_rest_sets):
            m = rest_length_misfit(s, pr, mesh_n=mesh_n)
            out += [m[g] for g in pr]
        out = np.array(out)
        return np.where(np.isfinite(out), out, 10.0)

    sol = least_squares(resid, np.asarray(x0, dtype=float), bounds=bounds, x_scale="jac")
    return sol.x, sol.fun


def with_symmetric(system, **changes):
    """A copy of a symmetric system with parameters of its SymmetricConfig changed
    (``theta``, ``psi``, ``sigma``, ``z``, ``r``, ``l``: arrays in radians / metres), and
    optionally ``r_mb`` or ``k_H``; rest lengths are dropped."""
    from tmfem.equilibrium.symmetric_map import with_configuration
    from tmfem.system import SymmetricConfig
    from tmfem.system.geometry import membrane_corners_regular

    c = system.symmetric
    kw = {k: changes.pop(k, getattr(c, k)) for k in ("theta", "psi", "sigma", "z", "r", "l")}
    cfg = SymmetricConfig(**kw)
    extra = {}
    if "r_mb" in changes:
        extra["r_mb"] = float(changes.pop("r_mb"))
        extra["membrane_corners"] = membrane_corners_regular(system.N, extra["r_mb"])
    if "k_H" in changes:
        extra["k_H"] = float(changes.pop("k_H"))
    if changes:
        raise InputError("with_symmetric: expected parameters among theta, psi, sigma, z, r, l, "
                         f"r_mb, k_H, found {sorted(changes)}")
    return with_configuration(system.replace(**extra) if extra else system, cfg)


def deployment_bases(system, *, z_ratio: float = 0.7, Delta: float = 1e-3, sigma2=None):
    """Stage-2 base rule reconstructed from Table 7.7 for 2-stage systems (see docs/validation/errata.md).

    sigma_2 fixed (default: that of ``system``), z_2 = z_ratio l_1 cos(theta), r_2 from
    eq. 3.22 such that the membrane corner displacement is ``Delta``. Returns a callable
    ``bases(theta, psi) -> {"r", "z", "sigma"}`` for
    :func:`tmfem.equilibrium.symmetric_map.equilibrium_map` (eq. 5.97 family).
    """
    c = system.symmetric
    if c is None or c.M != 2:
        raise InputError(f"system {system.name!r}: deployment_bases expected a symmetric 2-stage "
                         f"system, found " + ("no symmetric parametrisation" if c is None
                                              else f"M = {c.M}"))
    sg2 = float(c.sigma[1]) if sigma2 is None else float(sigma2)

    def bases(theta, psi):
        r2 = top_radius_for_delta(l_M=c.l[1], theta_M=theta, psi_rel=psi, r_mb=system.r_mb,
                                  Delta=Delta, N=system.N)
        if not r2 > 0:
            raise InputError(f"path table-7-7-bases of {system.name}: the stage-2 base radius of "
                             f"eq. 3.22 at theta = {np.degrees(theta):.4g} deg, psi = "
                             f"{np.degrees(psi):.4g} deg is {r2:.4g} m; expected > 0 (a configuration "
                             "outside the rule's range, e.g. [packaged]; use --path linear)")
        return {"r": np.array([c.r[0], r2]), "z": np.array([0.0, z_ratio * c.l[0] * np.cos(theta)]),
                "sigma": np.array([0.0, sg2])}

    return bases


def relative_difference(ours, printed) -> float | None:
    """(ours - printed) / |printed|; None when either is not a number (None: not printed /
    not computed, or a string), ``printed`` is 0 or ``ours`` is not finite."""
    def number(v):
        return isinstance(v, numbers.Real) and not isinstance(v, bool)
    if number(printed) and number(ours) and printed != 0 and np.isfinite(ours):
        return (ours - printed) / abs(printed)
    return None


def comparison_row(quantity: str, printed, ours, unit: str = "") -> tuple:
    """One row (quantity, printed, ours, relative difference) for :func:`format_comparison`;
    ``printed`` or ``ours`` may be None (not printed / not computed) or a string."""
    return (quantity + (f" [{unit}]" if unit else ""), printed, ours,
            relative_difference(ours, printed))


def format_comparison(rows, title: str = "") -> str:
    """Plain-text columns: quantity, printed, ours, rel. diff."""
    def fmt(v):
        if v is None:
            return "-"
        if isinstance(v, str):
            return v
        if not np.isfinite(v):
            return "n/a"
        return f"{v:.6g}"
    table = [("quantity", "printed", "ours", "rel. diff")]
    table += [(q, fmt(p), fmt(o), "-" if r is None else f"{100 * r:+.2f} %") for q, p, o, r in rows]
    w = [max(len(r[k]) for r in table) for k in range(4)]
    lines = [title] if title else []
    for k, r in enumerate(table):
        lines.append("  ".join(s.ljust(w[i]) if i == 0 else s.rjust(w[i]) for i, s in enumerate(r)))
        if k == 0:
            lines.append("  ".join("-" * x for x in w))
    return "\n".join(lines)
