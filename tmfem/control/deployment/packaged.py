"""The packaged configuration of a 1-N(D) system: a (theta, psi) from which its deployment
path is a path of feasible equilibria (7.4; design assistance of ``tmfem equilibrium
--packaged``)."""
from __future__ import annotations

import dataclasses

import numpy as np

from tmfem.control.deployment.reference_trajectory import DeploymentReference
from tmfem.control.deployment.run import equilibrium_checker
from tmfem.equilibrium.assist import symmetric_parameters
from tmfem.equilibrium.symmetric import check_1ND, membrane_delta_system
from tmfem.equilibrium.symmetric_map import with_configuration
from tmfem.errors import InfeasibleDesign, InputError


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
    c = symmetric_parameters(system, "packaged configuration")
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
