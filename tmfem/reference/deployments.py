"""The deployments of dissertation 7.4 and what a deployment run writes.

The dissertation's parameters per deployment (7.4): omega_r of eq. 5.68, the gains of
Table 7.1 (eq. 5.69), the uncertainty model of the controller (eq. 5.72 for 1-4(D), M G
ignored for 1-6(D) and 2-3) and the monitored membrane points of eqs. 5.73-5.75. The
printed points lie on the membrane edges (mid-edge points of the polygon); they are moved
1 mm toward the centroid so that they fall inside the mesh (docs/errata.md).
``tmfem deploy`` and ``tmfem report`` run them (:func:`setup`, :func:`write_outputs`).
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from tmfem.errors import InputError
from tmfem.io.atomic import atomic_open
from tmfem.io.run import partial_name

#: 7.4: omega_r (eq. 5.68), Table 7.1 (omega_0, omega_e, tau, d_c), uncertainty, points (5.73-5.75)
DEPLOYMENTS = {
    "1-4D": {"omega_r": 0.7, "table_7_1": (15.0, 150.0, 20.0, 1.5), "uncertainty": "initial",
             "points": [(1.0, 1.0), (2.0, 1.0), (1.0, 2.0)], "u_m": 0.01, "path": "delta"},
    "1-6D": {"omega_r": 0.35, "table_7_1": (4.0, 10.0, 20.0, 0.7), "uncertainty": "no-MG",
             "points": [(1.0, 1.732), (2.5, 0.866), (2.5, 2.598)], "u_m": 0.02, "path": "delta"},
    "2-3-deploy": {"omega_r": 0.5, "table_7_1": (1.0, 24.0, 5.0, 0.9), "uncertainty": "no-MG",
                   "points": [(0.866, 0.5), (1.30, 0.75), (0.433, 0.75)], "u_m": 0.01,
                   "path": "table-7-7-bases"},
}
CONTROLLERS = {"adaptive-hinf": "lmi", "adaptive-hinf-riccati": "hinf", "adaptive-lqr": "lqr",
               "adaptive": "none"}
UNCERTAINTIES = ("initial", "no-MG", "exact")

#: ParaView frames of a deployment: one every this many samples.
VTK_EVERY = 10


def inside_points(system, points, *, inset: float = 1e-3):
    """The points moved ``inset`` metres toward the membrane centroid (see module docstring)."""
    c = system.membrane_corners.mean(axis=1)
    out = []
    for p in points:
        p = np.asarray(p, dtype=float)
        d = c - p
        out.append(tuple(p + inset * d / np.linalg.norm(d)))
    return out


def setup(preset: str, *, controller: str = "adaptive-hinf", uncertainty: str | None = None,
          allocation: str = "bounded", path: str | None = None, evaluation: str = "state",
          tendon_law: str = "fixed-rate", gains=None):
    """The deployment of ``preset`` with the 7.4 parameters (:func:`build_deployment`).
    ``gains``: the PFL's (omega_0, omega_e, tau, d_c) of eq. 5.69 in rad/s, rad/s, s and -
    (default: the preset's Table 7.1 row).
    ``path`` (default the preset's): ``"delta"`` (1-N(D): psi_r from eq. 3.22 with the
    membrane stretch Delta linear in s), ``"table-7-7-bases"`` (2-3: the stage-2 base on the
    reconstructed Table 7.7 rule, :func:`tmfem.reference.tables.deployment_bases`) or
    ``"linear"`` (every symmetric parameter linear in s). ``evaluation``: where the PFL
    evaluates its model terms (``"state"``, eq. 5.58, or ``"reference"``); ``tendon_law``: its
    tendon model (``"fixed-rate"``, eq. 5.19, or ``"cable"``, :mod:`tmfem.control.deployment.adaptive`)."""
    from tmfem.control.deployment.adaptive import Gains
    from tmfem.control.deployment.run import build_deployment
    from tmfem.reference.tables import deployment_bases
    from tmfem.system.presets import load_preset
    check_choices(preset, controller=controller, uncertainty=uncertainty, path=path)
    p = DEPLOYMENTS[preset]
    path = path or p["path"]
    final, initial = load_preset(preset), load_preset(preset + "-initial")
    w0, we, tau, dc = p["table_7_1"] if gains is None else gains
    return build_deployment(final=final, initial=initial, omega_r=p["omega_r"],
                            gains=Gains(omega_0=w0, omega_e=we, tau=tau, d_c=dc),
                            uncertainty=uncertainty or p["uncertainty"],
                            output_points=inside_points(final, p["points"]),
                            linear=CONTROLLERS[controller], u_m=p["u_m"],
                            bases=deployment_bases(final) if path == "table-7-7-bases" else None,
                            delta_path=path == "delta", allocation=allocation,
                            evaluation=evaluation, tendon_law=tendon_law)


def check_choices(preset: str, *, controller: str = "adaptive-hinf", uncertainty=None,
                  path=None) -> None:
    """Refuse an unknown deployment preset, controller, uncertainty model or path (before
    any work: ``tmfem deploy`` calls it first)."""
    if preset not in DEPLOYMENTS:
        raise InputError(f"deploy: expected a preset among {sorted(DEPLOYMENTS)}, found {preset!r}")
    own = DEPLOYMENTS[preset]["path"]
    if path is not None and path not in ("linear", own):
        raise InputError(f"--path for {preset}: expected 'linear' or {own!r}, found {path!r}")
    if controller not in CONTROLLERS:
        raise InputError(f"--controller: expected one of {sorted(CONTROLLERS)}, found {controller!r}")
    if uncertainty is not None and uncertainty not in UNCERTAINTIES:
        raise InputError(f"--uncertainty: expected one of {list(UNCERTAINTIES)}, found {uncertainty!r}")


def csv_columns(r) -> list[str]:
    """Header of the deployment CSV: one column per named signal, with its unit
    (:func:`tmfem.io.run.column_header`): time, q, the references q_d, w, rest lengths u,
    tendon lengths L, the zero-dynamics energy, the plant's own tendon forces T (the FE
    plant's elements, the COM's k (L - u)), with force actuation the tension demand T_d and the
    FE rest lengths r_fe, and the active controller (a label, unit ``[-]`` as the
    dimensionless JSON entries of :mod:`tmfem.io.units`)."""
    from tmfem.io.run import column_header
    n = r.names
    names = (["t"] + n["q"] + [f"{q}_ref" for q in n["q"]] + n["w"] + n["u"]
             + [f"L_{t}" for t in n["tendons"]] + ["eta_energy"]
             + [f"{p}_{t}" for p, _ in _tendon_signals(r) for t in n["tendons"]])
    return [column_header(c) for c in names] + ["controller [-]"]


def _tendon_signals(r) -> list:
    """(column prefix, array (n, n_t)) of the run's tendon signals after the COM columns: the
    plant's own tendon forces ``T`` and, with force actuation, the tension demand ``T_d`` and
    the FE rest lengths set ``r_fe`` (:class:`tmfem.control.deployment.run.DeploymentResult`)."""
    out = [("T", r.tendon_force)] if r.tendon_force.size else []
    return out + [(p, r.actuator[k]) for p, k in (("T_d", "tension_demand"),
                                                  ("r_fe", "fe_rest_lengths")) if k in r.actuator]


def write_csv(path, r) -> str:
    """The deployment CSV (:func:`csv_columns`), ``\\n`` line endings, written atomically;
    a run that stopped early (``r.failure``) is written as ``NAME.csv.partial``
    (:func:`tmfem.io.run.partial_name`) and an earlier ``NAME.csv`` is removed."""
    nq = len(r.names["q"])
    if r.failure:
        Path(path).unlink(missing_ok=True)
        path = partial_name(path)
    with atomic_open(path, "w", newline="") as fh:
        wr = csv.writer(fh, lineterminator="\n")
        wr.writerow(csv_columns(r))
        for k in range(r.t.size):
            wr.writerow([f"{r.t[k]:.6g}"] + [f"{v:.10g}" for v in r.z[k, :nq]]
                        + [f"{v:.10g}" for v in r.q_d[k]] + [f"{v:.10g}" for v in r.w[k]]
                        + [f"{v:.10g}" for v in r.u[k]] + [f"{v:.10g}" for v in r.lengths[k]]
                        + [f"{r.eta_energy[k]:.6g}"]
                        + [f"{v:.10g}" for _, a in _tendon_signals(r) for v in a[k]]
                        + [r.controller[min(k, len(r.controller) - 1)]])
    return str(path)


def write_outputs(s, r, *, preset: str, title: str, csv_path=None, plot=None, gif=None,
                  vtk=None) -> dict:
    """Write the files of deployment run ``r`` of set-up ``s``: CSV, plot (Figures 7.2-7.4, or
    8.2-8.4 for an LPV preset), GIF (Figures 7.5, 8.5) and ParaView series (a frame every
    :data:`VTK_EVERY` samples); returns {kind: path} of those written."""
    out = {}
    if csv_path:
        out["csv"] = write_csv(csv_path, r)
    if plot:
        from tmfem.post.deploy_plots import plot_deployment, plot_lpv_deployment
        draw = plot_lpv_deployment if preset in LPV_DEPLOYMENTS else plot_deployment
        out["plot"] = str(draw(plot, r, title=title))
    if gif:
        from tmfem.post.deploy_plots import animate_deployment
        out["gif"] = str(animate_deployment(gif, s.model.system, r))
    if vtk:
        from tmfem.io.codes import configuration_cells
        from tmfem.io.series import write_series
        sysm = s.model.system
        cells = configuration_cells(sysm)
        idx = range(0, r.t.size, VTK_EVERY)
        out["pvd"] = str(write_series(Path(vtk), ((float(r.t[k]), sysm.nodes(r.z[k, :s.model.nq]),
                                                   cells) for k in idx), name=preset))
    return out


#: 8.4: eq. 5.100 (xi_r = 1, omega_r; theta_0, theta_e, psi_0 from the preset's printed
#: section) and the monitored points of eq. 5.101 (moved 1 mm inside as the 7.4 points)
LPV_DEPLOYMENTS = {
    "2-3-lpv": {"omega_r": 0.3, "points": [(0.866, 0.5), (1.30, 0.75), (0.433, 0.75)],
                "membrane_modes": 4, "path": "table-7-7-bases"},
}
#: controllers of an LPV deployment (``tmfem deploy --controller``)
LPV_CONTROLLERS = ("lpv", "lpv-output")


def lpv_setup(preset: str, plant, *, model_at: str = "final", system=None):
    """The deployment of 8.4 of ``preset`` for the design plant ``plant`` (its grid built with
    :func:`tmfem.reference.tables.deployment_bases`, as ``tmfem control lpv``):
    :func:`tmfem.control.lpv.deployment.lpv_deployment` with the parameters of
    :data:`LPV_DEPLOYMENTS`; ``system``: the System deployed, default the preset's (another
    one, e.g. with stiffer bars, for a perturbation study of an FE plant)."""
    from tmfem.control.lpv.deployment import lpv_deployment
    from tmfem.reference.tables import deployment_bases
    from tmfem.system.presets import load_preset
    if preset not in LPV_DEPLOYMENTS:
        raise InputError(f"LPV deployment: expected a preset among {sorted(LPV_DEPLOYMENTS)}, found {preset!r}")
    p = LPV_DEPLOYMENTS[preset]
    s = load_preset(preset) if system is None else system
    pr = s.printed
    return lpv_deployment(s, plant, theta_0=np.radians(pr["theta0_deg"]), theta_e=np.radians(pr["theta_e_deg"]),
                          psi_0=np.radians(pr["psi0_deg"]), omega_r=p["omega_r"], bases=deployment_bases(s),
                          output_points=inside_points(s, p["points"]), membrane_modes=p["membrane_modes"],
                          model_at=model_at)
