"""Design assistance for symmetric systems: parameters that make a design feasible.

* :func:`membrane_radius_for_delta`: the membrane radius r_mb that gives a target corner
  displacement Delta (eq. 3.22: Delta = R_M - r_mb with R_M the circumradius of the top bar
  ends' polygon, so the membrane is stretched for r_mb < R_M);
* :func:`feasible_bases`: stage bases (r_i, z_i, sigma_i, i >= 2) of an M >= 2 system with a
  positive null vector of the reduced matrix of 3.3.2 and Delta > 0 at the file's theta, psi
  (eq. 5.97), in the file's units (degrees);
* :func:`packaged_configurations`: the band of psi at a packaged theta where a 1-N(D) system
  is a feasible equilibrium (eqs. 3.38-3.41, Delta > 0) and the psi whose Delta matches the
  deployed one;
* :func:`infeasibility_hint`: which parameter to change, and in which direction, for a slack
  membrane or slack tendons.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InfeasibleDesign, InputError, SlackMembrane


def _symmetric(system, what: str):
    if system.symmetric is None or system.r_mb is None:
        raise InputError(f"{what}: expected a symmetric system with a regular membrane "
                         f"([symmetric] and r_mb), found {system.name!r} without")
    return system.symmetric


def top_radius(system) -> float:
    """R_M: circumradius of the polygon of the top bar ends in O_f (eq. 3.22, Delta = R_M - r_mb) [m]."""
    from tmfem.equilibrium.symmetric import membrane_delta_system
    _symmetric(system, "membrane radius")
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
    c = _symmetric(system, "feasible bases")
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
            "symmetric": {"theta_deg": [float(np.degrees(theta))] * c.M,
                          "psi_deg": np.degrees(psi + sigma).round(6).tolist(),
                          "sigma_deg": np.degrees(sigma).round(6).tolist(),
                          "z": np.round(b["z"], 6).tolist(), "r": np.round(b["r"], 6).tolist(),
                          "l": c.l.tolist()}}


def packaged_configurations(system, *, theta_deg: float, step_deg: float = 0.05,
                            path_points: int = 101) -> dict:
    """The psi band [deg] at ``theta_deg`` where the 1-N(D) ``system`` is a feasible
    equilibrium (positive null vector of eq. 3.40, Delta > 0: :func:`tmfem.equilibrium.
    symmetric.check_1ND`), and in it a packaged configuration for ``[packaged] symmetric``: the
    psi whose Delta is closest to the deployed configuration's among those from which the
    deployment path (psi_r from eq. 3.22 with Delta linear in the progress, the ``delta`` rule
    of :class:`tmfem.control.deployment.reference_trajectory.DeploymentReference`) is a
    feasible equilibrium at ``path_points`` progress values.

    Delta of eq. 3.22 is at least l sin(theta) - r_1 - r_mb (the top bar ends at their
    closest to the axis), so the deployed Delta_e is reachable only for
    sin(theta) <= (r_mb + Delta_e + r_1) / l: ``theta_max_deg``.

    Raises
    ------
    InfeasibleDesign
        No feasible psi at this theta, or no feasible deployment path from any.
    """
    import dataclasses

    from tmfem.control.deployment.reference_trajectory import DeploymentReference
    from tmfem.control.deployment.run import equilibrium_checker
    from tmfem.equilibrium.symmetric import check_1ND, membrane_delta_system
    from tmfem.equilibrium.symmetric_map import with_configuration
    c = _symmetric(system, "packaged configuration")
    if not system.deployable:
        raise InputError(f"packaged configuration: expected a 1-N(D) system (deployable = true), "
                         f"found {system.M}-{system.N}")
    if not (np.isfinite(theta_deg) and 0 < theta_deg < 90):
        raise InputError(f"--packaged: expected 0 < theta < 90 deg, found {theta_deg!r}")
    target = membrane_delta_system(system)
    x = (system.r_mb + target + c.r[0]) / c.l[0]
    theta_max = float(np.degrees(np.arcsin(x))) if x < 1 else 90.0
    rows = []
    for p in np.arange(-89.0, 89.0 + 1e-9, step_deg):
        cfg = dataclasses.replace(c, theta=np.radians([theta_deg]), psi=np.radians([p]))
        s = with_configuration(system, cfg)
        try:
            check_1ND(s)
        except InfeasibleDesign:
            continue
        rows.append((float(p), float(membrane_delta_system(s)), cfg))
    if not rows:
        raise InfeasibleDesign(f"packaged configuration: no psi in (-89, 89) deg gives a feasible "
                               f"1-N(D) equilibrium at theta = {theta_deg:g} deg (eq. 3.40 and "
                               f"Delta > 0); expected a theta closer to the deployed "
                               f"{np.degrees(c.theta[0]):.4g} deg")
    psi = np.array([r[0] for r in rows])
    breaks = np.flatnonzero(np.diff(psi) > step_deg * 1.5)
    starts, ends = np.r_[0, breaks + 1], np.r_[breaks, psi.size - 1]
    bands = [[float(psi[a]), float(psi[b])] for a, b in zip(starts, ends)]
    check = equilibrium_checker(system)
    chosen, last = None, ""
    for k in np.argsort([abs(r[1] - target) for r in rows], kind="stable"):
        try:
            ref = DeploymentReference(initial=rows[k][2], final=c, N=system.N, q_names=list(system.q_names),
                                      omega_r=1.0, r_mb=system.r_mb)
            ref.check_equilibria(checker=check, n=path_points)
        except (InfeasibleDesign, InputError) as exc:
            last = str(exc)
            continue
        chosen = rows[k]
        break
    if chosen is None:
        raise InfeasibleDesign(f"packaged configuration: no psi of the feasible bands {bands} deg at "
                               f"theta = {theta_deg:g} deg has a feasible deployment path to the "
                               f"deployed configuration (Delta linear in the progress); the last "
                               f"tried: {last}")
    return {"theta_deg": float(theta_deg), "psi_deg_bands": bands,
            "psi_deg": chosen[0], "Delta": chosen[1], "Delta_deployed": float(target),
            "theta_max_deg": theta_max, "path_points_checked": int(path_points),
            "step_deg": step_deg}


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
