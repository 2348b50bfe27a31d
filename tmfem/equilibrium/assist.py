"""Design assistance for symmetric systems: parameters that make a design feasible.

* :func:`membrane_radius_for_delta`: the membrane radius r_mb that gives a target corner
  displacement Delta (eq. 3.22: Delta = R_M - r_mb with R_M the circumradius of the top bar
  ends' polygon, so the membrane is stretched for r_mb < R_M);
* :func:`feasible_bases`: stage bases (r_i, z_i, sigma_i, i >= 2) of an M >= 2 system with a
  positive null vector of the reduced matrix of 3.3.2 and Delta > 0 at the file's theta, psi
  (eq. 5.97), in the file's units (degrees);
* the packaged configuration of a 1-N(D) system along its deployment path is found by
  :func:`tmfem.control.deployment.packaged.packaged_configurations`, that of a symmetric
  M >= 2 system (stage bases at the deployed Delta) by :func:`tmfem.control.deployment.
  packaged.packaged_stages` (both check the path);
* :func:`infeasibility_hint`: which parameter to change, and in which direction, for a slack
  membrane or slack tendons.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError, SlackMembrane


def symmetric_parameters(system, what: str):
    """``system.symmetric``, refused (naming ``what``) without a regular membrane."""
    if system.symmetric is None or system.r_mb is None:
        raise InputError(f"{what}: expected a symmetric system with a regular membrane "
                         f"([symmetric] and r_mb), found {system.name!r} without")
    return system.symmetric


def top_radius(system) -> float:
    """R_M: circumradius of the polygon of the top bar ends in O_f (eq. 3.22, Delta = R_M - r_mb) [m]."""
    from tmfem.equilibrium.symmetric import membrane_delta_system
    symmetric_parameters(system, "membrane radius")
    return float(membrane_delta_system(system) + system.r_mb)


def membrane_radius_for_delta(system, *, delta: float) -> dict:
    """r_mb [m] giving the corner displacement ``delta`` [m] (eq. 3.22) and the feasible range
    0 < r_mb < R_M (Delta > 0)."""
    R = top_radius(system)
    if not (np.isfinite(delta) and 0 < delta < R):
        raise InputError(f"target Delta: expected 0 < Delta < R_M = {R:.6g} m (eq. 3.22), found "
                         f"{delta!r} m")
    return {"r_mb": R - delta, "Delta": float(delta), "r_mb_max": R, "equation": "3.22",
            "r_mb_file": float(system.r_mb), "Delta_file": float(R - system.r_mb)}


def with_membrane_radius(system, r_mb: float):
    """A copy of the symmetric ``system`` with membrane radius ``r_mb`` [m] (rest lengths dropped)."""
    from tmfem.system.geometry import membrane_corners_regular
    return system.replace(r_mb=float(r_mb), membrane_corners=membrane_corners_regular(system.N, r_mb),
                          rest_lengths=None)


def feasible_bases(system, *, starts: int = 8, delta: float = 1e-3) -> dict:
    """Stage bases of an M >= 2 system at its own theta_1, psi_1 (eq. 5.97) that give a positive
    null vector (3.3.2) with the largest margin and Delta > 0
    (:func:`tmfem.equilibrium.symmetric_map.best_bases`), as ``[symmetric]`` entries in degrees
    and metres. When no bases give Delta > 0 with the file's r_mb, the search is repeated with
    the membrane radius free (the null vector does not depend on it, eq. 3.22: Delta = R_M -
    r_mb) and ``r_mb`` is the radius that gives ``delta`` [m] with those bases."""
    from tmfem.equilibrium.symmetric_map import best_bases, configuration_5_97, with_configuration
    c = symmetric_parameters(system, "feasible bases")
    if c.M < 2:
        raise InputError(f"feasible bases: expected a system with M >= 2 stages, found M = {c.M}")
    theta, psi = float(c.theta[0]), float(c.psi[0] - c.sigma[0])
    b = best_bases(system, theta, psi, starts=starts)
    r_mb = None
    if not b["feasible"]:
        b = best_bases(with_membrane_radius(system, 1e-6), theta, psi, starts=starts)
        if b["margin"] > 0:
            cfg = configuration_5_97(system, theta, psi, r=b["r"], z=b["z"], sigma=b["sigma"])
            R = top_radius(with_configuration(system, cfg))
            r_mb = R - delta
            b = {**b, "Delta": delta, "feasible": r_mb > 0}
    sigma = np.asarray(b["sigma"], dtype=float)
    return {"feasible": bool(b["feasible"]), "margin": float(b["margin"]), "Delta": float(b["Delta"]),
            "r_mb": None if r_mb is None else float(r_mb),
            "symmetric": {"theta_deg": [round(float(np.degrees(theta)), 6)] * c.M,
                          "psi_deg": np.degrees(psi + sigma).round(6).tolist(),
                          "sigma_deg": np.degrees(sigma).round(6).tolist(),
                          "z": np.round(b["z"], 6).tolist(), "r": np.round(b["r"], 6).tolist(),
                          "l": c.l.tolist()}}


def infeasibility_hint(system, error) -> str:
    """What to change, and which way, for the infeasible design of ``system`` that raised
    ``error``: a slack membrane (Delta <= 0, eq. 3.22) needs r_mb below R_M; slack tendons of
    an M >= 2 system need other stage bases (``--bases``); "" when there is no hint."""
    if system.symmetric is None or system.r_mb is None:
        return ""
    if isinstance(error, SlackMembrane) or "Delta > 0" in str(error):
        R = top_radius(system)
        if R <= 0:
            return ""
        return (f"decrease r_mb below R_M = {R:.6g} m (r_mb = {R - 1e-3:.6g} m gives Delta = 1 mm; "
                "`tmfem equilibrium FILE --target-delta 1`), or lengthen the bars (R_M grows "
                "with l_M sin(theta_M))")
    if system.M >= 2:
        return ("search stage bases with a positive null vector: `tmfem equilibrium FILE --bases` "
                "(r_i, z_i, sigma_i of stages i >= 2 in the file's units)")
    return ""
