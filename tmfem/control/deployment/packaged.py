"""The packaged configuration of a deployment (7.4; design assistance of ``tmfem equilibrium
--packaged``): a configuration from which the deployment path is a path of feasible equilibria.

* :func:`packaged_configurations`: a 1-N(D) system, a (theta, psi) on the ``delta`` path;
* :func:`packaged_stages`: a symmetric M >= 2 system, theta, psi and the stage bases at the
  deployed Delta (eq. 3.22) on the automatic path
  (:func:`tmfem.equilibrium.deployment_path.automatic_path`).
"""
from __future__ import annotations

import dataclasses
import logging
from collections import Counter

import numpy as np
from scipy.optimize import minimize

from tmfem.control.deployment.reference_trajectory import DeploymentReference
from tmfem.control.deployment.run import equilibrium_checker
from tmfem.equilibrium.assist import symmetric_parameters
from tmfem.equilibrium.symmetric import feasible_1ND, membrane_delta_system
from tmfem.errors import InfeasibleDesign, InputError
from tmfem.system.geometry import wrap_angle
from tmfem.system.problem import DeploymentParameters

log = logging.getLogger(__name__)


def packaged_configurations(system, *, theta_deg: float, step_deg: float = 0.05,
                            path_points: int = 101) -> dict:
    """The psi band [deg] at ``theta_deg`` where the 1-N(D) ``system`` is a feasible
    equilibrium (positive null vector of eq. 3.40, Delta > 0: :func:`tmfem.equilibrium.
    symmetric.feasible_1ND`, the conditions of :func:`tmfem.equilibrium.symmetric.check_1ND`,
    at every psi of the grid at once), and in it a packaged configuration for ``[packaged] symmetric``: the
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
    c = symmetric_parameters(system, "packaged configuration")
    if not system.deployable:
        raise InputError(f"packaged configuration: expected a 1-N(D) system (deployable = true) or a "
                         f"symmetric system with M >= 2 stages, found {system.M}-{system.N}")
    _check_theta(theta_deg)
    target = membrane_delta_system(system)
    x = (system.r_mb + target + c.r[0]) / c.l[0]
    theta_max = float(np.degrees(np.arcsin(x))) if x < 1 else 90.0
    scan = np.arange(-89.0, 89.0 + 1e-9, step_deg)
    ok, scan_delta = feasible_1ND(system, theta1=np.radians(theta_deg), psi1=np.radians(scan))
    rows = [(float(p), float(D), dataclasses.replace(c, theta=np.radians([theta_deg]), psi=np.radians([p])))
            for p, D in zip(scan[ok], scan_delta[ok])]
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


def packaged_stages(system, *, theta_deg: float, psi_step_deg: float = 10.0, refinements: int = 2,
                    starts: int = 2, maxiter: int = 100) -> dict:
    """A packaged configuration of the symmetric M >= 2 ``system`` at the bar declination
    ``theta_deg`` of every stage, from which :func:`tmfem.equilibrium.deployment_path.
    automatic_path` finds a feasible path to the deployed configuration (``[packaged]
    symmetric`` of 7.4 for any M and N).

    Candidates follow eq. 5.97: theta_i = theta, psi_i = psi + sigma_i (one azimuth relative
    to the stage bases), psi on a grid of ``psi_step_deg`` in [-80, 80] deg, halved up to
    ``refinements`` times (only the new azimuths are evaluated) while the grid has feasible
    candidates but none with a path (a grid without any is refused: feasible psi bands are
    wide where they exist, e.g. none on a 2.5 deg grid of the 3-3 at 70 deg). At each psi:

    * the top-stage radius r_M is eq. 3.22 solved for the deployed Delta (the packaged
      membrane keeps the deployed stretch; :func:`tmfem.equilibrium.deployment_path.
      top_radius_for_delta`, each positive root);
    * r_i (2 <= i < M), z_i and sigma_i (i >= 2): first where the positive null vector of
      the reduced matrix of 3.3.2 has its largest margin (:func:`tmfem.equilibrium.
      symmetric_map.best_bases` with r_M held, ``starts`` Nelder-Mead starts, the first from
      the deployed bases, ``maxiter`` iterations each; radii in [0.025, 1.1] and heights in
      [0.025, 1.4] times the mean bar length), then the bases nearest to the deployed ones
      that keep half of that margin (Nelder-Mead on the distance in bar lengths, sigma as the
      arc l sigma, with a penalty below the half margin): a packaged design close to the
      deployed one deploys with smaller transients (the user 2-5 from its largest-margin bases,
      sigma_2 = -20 deg: 742 MPa of tendon stress; from the nearest, sigma_2 = 4.6 deg: 399 MPa,
      below its 450 MPa yield stress);
    * the bases rounded to 1e-4 deg and 1e-6 m (r_M recomputed from eq. 3.22 for the rounded
      angles), and the rounded configuration checked by :func:`tmfem.equilibrium.
      deployment_path.path_feasibility` (tendons in tension, membrane stretched, rest lengths
      of eq. 3.9 at least the file's ``[deployment] r_min``, with forces scaled by the
      membrane stiffness of the deployed design).

    The feasible candidates of a grid are tried in order of the worst feasibility margin of the
    straight path (every parameter linear in the progress, :class:`tmfem.equilibrium.
    deployment_path.SymmetricPath` at 21 points) to the deployed configuration, the nearest to
    a feasible path first (ties: the larger null-vector margin); the first from which the
    automatic path is feasible is returned. Every candidate has the deployed Delta, so Delta
    does not rank them.

    Returns
    -------
    dict with ``theta_deg``, ``symmetric`` (the ``[packaged] symmetric`` entries: lists
    ``theta_deg``, ``psi_deg``, ``sigma_deg`` [deg], ``z``, ``r`` [m]), ``config`` (the
    :class:`~tmfem.system.geometry.SymmetricConfig`, not JSON), ``Delta`` and
    ``Delta_deployed`` [m], ``height`` [m] of the top bar ends above the stage-1 base,
    ``margin`` (null-vector margin), ``path`` (:meth:`~tmfem.equilibrium.deployment_path.
    PathReport.to_dict`), ``candidates`` (feasible candidates evaluated), ``psi_step_deg``
    (the grid step where it was found), ``r_min`` [m].

    Raises
    ------
    InfeasibleDesign
        No psi gives a feasible packaged equilibrium at this theta (the conditions that
        failed, with how often, and the psi range where eq. 3.22 has a top radius), or no
        automatic path exists from any (the last path's obstacle).
    """
    from tmfem.equilibrium.deployment_path import (SymmetricPath, automatic_path, membrane_stiffness,
                                                   path_feasibility, top_radius_for_delta)
    from tmfem.equilibrium.design import design_equilibrium
    from tmfem.equilibrium.symmetric_map import best_bases, configuration_5_97

    c = symmetric_parameters(system, "packaged configuration")
    if c.M < 2 or system.deployable:
        raise InputError(f"packaged stages: expected a symmetric system with M >= 2 stages, found "
                         f"{system.M}-{system.N}{'(D)' if system.deployable else ''}")
    _check_theta(theta_deg)
    if not (np.isfinite(psi_step_deg) and 0 < psi_step_deg <= 80 and refinements >= 0):
        raise InputError(f"packaged psi grid: expected 0 < step <= 80 deg and refinements >= 0, found "
                         f"{psi_step_deg!r} deg, {refinements!r}")
    target = float(membrane_delta_system(system))
    if not target > 0:
        raise InfeasibleDesign(f"packaged configuration: the deployed membrane is not stretched "
                               f"(Delta = {target:.4g} m <= 0, eq. 3.22); expected a feasible deployed design")
    r_min = (system.problem.deployment or DeploymentParameters()).r_min
    kappa = membrane_stiffness(design_equilibrium(system.replace(rest_lengths=None), strict=False))
    theta = np.radians(theta_deg)
    l = float(np.mean(c.l))

    def top(psi, near):
        return top_radius_for_delta(l_M=c.l[-1], theta_M=theta, psi_rel=psi, r_mb=system.r_mb,
                                    Delta=target, N=system.N, near=near)

    failures = Counter()

    def candidates_at(psis) -> list:
        """The feasible packaged candidates at the azimuths ``psis`` [deg], best first."""
        found = []
        for psi_deg in psis:
            psi = np.radians(psi_deg)
            try:
                roots = {round(top(psi, near), 9) for near in (0.0, 1e9)}
            except InputError:
                failures["the top bars do not reach r_mb + Delta (no r_M of eq. 3.22)"] += 1
                continue
            for r_top in sorted(r for r in roots if r > 0):
                b = best_bases(system, theta, psi, starts=starts, maxiter=maxiter, r_top=r_top,
                               r_bounds=(0.025 * l, 1.1 * l), z_bounds=(0.025 * l, 1.4 * l))
                r, z, sigma = _nearest_bases(system, theta, psi, b, l=l, kappa=kappa, r_min=r_min,
                                             maxiter=maxiter)
                r, z = np.round(r, 6), np.round(z, 6)
                r[-1] = top(psi, r_top)
                cfg = configuration_5_97(system, theta, psi, r=r, z=z, sigma=np.radians(np.round(np.degrees(sigma), 4)))
                p = path_feasibility(system, cfg, kappa=kappa, r_min=r_min)
                if p.reason:
                    failures[p.reason.split(":")[0]] += 1
                    continue
                straight = min(q.margin for q in SymmetricPath(system=system, initial=cfg, final=c).margins(
                    np.linspace(0.0, 1.0, 21), kappa=kappa, r_min=r_min))
                found.append({"straight": straight, "margin": p.margin, "psi_deg": float(psi_deg), "config": cfg})
        return sorted(found, key=lambda k: (-k["straight"], -k["margin"]))

    scanned, count, last = set(), 0, ""
    for level in range(refinements + 1):
        step = psi_step_deg / 2**level
        grid = [float(v) for v in np.round(np.arange(-80.0, 80.0 + 1e-9, step), 6) if float(v) not in scanned]
        scanned.update(grid)
        candidates = candidates_at(grid)
        count += len(candidates)
        for k in candidates:
            cfg = k["config"]
            try:
                rep = automatic_path(system, cfg, kappa=kappa, r_min=r_min)
            except InfeasibleDesign as exc:
                last = str(exc)
                log.info("packaged candidate psi = %g deg: %s", k["psi_deg"], exc)
                continue
            return {"theta_deg": float(theta_deg), "config": cfg, "symmetric": _entries(cfg),
                    "Delta": float(cfg.membrane_delta(system.N, system.r_mb)), "Delta_deployed": target,
                    "height": float(cfg.z[-1] + cfg.l[-1] * np.cos(theta)), "margin": float(k["margin"]),
                    "path": rep.to_dict(), "candidates": count, "psi_step_deg": float(step), "r_min": float(r_min)}
        if not count:                   # no feasible equilibrium on the grid: no refinement
            break
    where = (f"at theta = {theta_deg:g} deg (psi in [-80, 80] deg in steps down to {step:g} deg, the "
             f"deployed Delta = {1e3 * target:.4g} mm)")
    if count:
        raise InfeasibleDesign(f"packaged configuration: none of the {count} feasible packaged equilibria "
                               f"{where} has a path to the deployed configuration; the last: {last}")
    reach = (system.r_mb + target) / (c.l[-1] * np.sin(theta))
    band = ("every psi" if reach >= 1 else
            f"|cos(psi + 180/N)| <= {reach:.4g}: psi in [{np.degrees(np.arccos(reach)) - 180 / system.N:.4g}, "
            f"{180 - np.degrees(np.arccos(reach)) - 180 / system.N:.4g}] deg")
    why = "; ".join(f"{k} ({n} candidates)" for k, n in failures.most_common())
    raise InfeasibleDesign(f"packaged configuration: no feasible equilibrium {where}: {why}; eq. 3.22 "
                           f"has a top radius for {band}; expected another theta (the deployed one is "
                           f"{np.degrees(c.theta[0]):.4g} deg)")


def _nearest_bases(system, theta: float, psi: float, b: dict, *, l: float, kappa: float, r_min: float,
                   maxiter: int) -> tuple:
    """The stage bases (r, z, sigma) of ``system`` at (theta, psi) [rad] of eq. 5.97 nearest to
    its deployed bases that keep half of the largest null-vector margin of ``b`` (a
    :func:`tmfem.equilibrium.symmetric_map.best_bases` result): Nelder-Mead from ``b`` on the
    distance in bar lengths ``l`` (sigma in rad, the arc l sigma) plus a penalty below half the
    margin (:func:`tmfem.equilibrium.deployment_path.path_feasibility`); r_1 and r_M held."""
    from tmfem.equilibrium.deployment_path import path_feasibility
    from tmfem.equilibrium.symmetric_map import configuration_5_97
    if not b["margin"] > 0:
        return b["r"], b["z"], b["sigma"]
    c = system.symmetric
    M, nr = c.M, c.M - 2
    p0 = np.concatenate([b["r"][1:1 + nr], b["z"][1:], b["sigma"][1:]])
    pe = np.concatenate([c.r[1:1 + nr], c.z[1:], b["sigma"][1:] + wrap_angle(c.sigma[1:] - b["sigma"][1:])])
    scale = np.r_[np.full(nr + M - 1, 1.0 / l), np.ones(M - 1)]

    def bases(p):
        return np.r_[c.r[0], p[:nr], b["r"][-1]], np.r_[0.0, p[nr:nr + M - 1]], np.r_[0.0, p[nr + M - 1:]]

    def objective(p):
        r, z, sigma = bases(p)
        if np.any(r[1:] <= 0) or np.any(z[1:] <= 0):
            return np.inf
        m = path_feasibility(system, configuration_5_97(system, theta, psi, r=r, z=z, sigma=sigma),
                             kappa=kappa, r_min=r_min).margin
        return np.linalg.norm(scale * (p - pe)) + 1e3 * max(0.0, 0.5 * b["margin"] - m)

    res = minimize(objective, p0, method="Nelder-Mead", options={"maxiter": maxiter, "xatol": 1e-6})
    return bases(res.x if res.fun <= objective(p0) else p0)


def _entries(cfg) -> dict:
    """``[packaged] symmetric`` entries of ``cfg``: angles in degrees (1e-4), lengths in metres
    (1e-6; r_M to 1e-9 m, so that the file's Delta is the deployed one, eq. 3.22)."""
    deg = lambda a: [round(float(v), 4) + 0.0 for v in np.degrees(a)]   # noqa: E731
    r = [round(float(v), 6) for v in cfg.r[:-1]] + [round(float(cfg.r[-1]), 9)]
    return {"theta_deg": deg(cfg.theta), "psi_deg": deg(cfg.psi), "sigma_deg": deg(cfg.sigma),
            "z": [round(float(v), 6) + 0.0 for v in cfg.z], "r": r}


def _check_theta(theta_deg: float) -> None:
    if not (np.isfinite(theta_deg) and 0 < theta_deg < 90):
        raise InputError(f"--packaged: expected 0 < theta < 90 deg, found {theta_deg!r}")
