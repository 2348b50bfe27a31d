"""Deployments (7.4, 8.4) set up from a system file, and what a deployment run writes.

The parameters of a deployment are the deployed system's own (:mod:`tmfem.system.problem`):
its ``[packaged]`` configuration, ``[deployment]`` (omega_r of eq. 5.68, the gains of Table
7.1, eq. 5.69, the controller's model error, the path), ``[control]`` (the H-infinity weights
and the measured membrane points of eqs. 5.73-5.75) and ``[lpv]`` (8.4). The presets 1-4D,
1-6D, 2-3-deploy and 2-3-lpv carry the dissertation's. The printed points lie on the membrane
edges (mid-edge points of the polygon); they are moved 1 mm toward the centroid so that they
fall inside the mesh (docs/validation/errata.md). ``tmfem deploy`` and ``tmfem report`` run them
(:func:`setup`, :func:`write_outputs`).
"""
from __future__ import annotations

import csv
import weakref
from pathlib import Path

import numpy as np

from tmfem.control.linear.generalized_plant import measured_points
from tmfem.errors import InfeasibleDesign, InputError
from tmfem.io.atomic import atomic_open
from tmfem.io.run import partial_name

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


def deployable_system(system):
    """``system`` (a System, or a preset name: the preset loader) checked to carry a
    deployment: a ``[packaged]`` configuration and a ``[deployment]`` table."""
    if isinstance(system, str):
        from tmfem.system.presets import load_preset
        system = load_preset(system)
    pr = system.problem
    missing = [t for t, v in (("[packaged]", pr.packaged), ("[deployment]", pr.deployment)) if v is None]
    if missing:
        raise InputError(f"deploy {system.name}: expected the tables [packaged] (the packaged "
                         f"configuration) and [deployment] (omega_r, gains) in the system file, "
                         f"missing {' and '.join(missing)} (docs/guides/system-file.md)")
    if system.symmetric is None or pr.packaged.symmetric is None:
        raise InputError(f"deploy {system.name}: expected a symmetric system ([symmetric]) with a "
                         "symmetric packaged configuration: the reference of eq. 5.68 runs through "
                         "the symmetric configurations")
    return system


def with_designed_rest_lengths(system, *, what: str):
    """``system`` with rest lengths: its own, else those of its equilibrium design (ch. 3,
    :func:`tmfem.equilibrium.design.design_equilibrium`, strict: a slack tendon or membrane
    is refused with the design's message, naming ``what`` configuration)."""
    if system.rest_lengths is not None:
        return system
    from tmfem.equilibrium.design import design_equilibrium
    from tmfem.errors import InfeasibleDesign
    try:
        d = design_equilibrium(system)
    except InfeasibleDesign as exc:
        raise type(exc)(f"deploy {system.name}: the {what} configuration is not a feasible "
                        f"equilibrium: {exc}") from None
    return system.with_rest_lengths(d.rest_lengths)


def checked_configurations(system):
    """The deployed ``system`` and its packaged configuration, both checked to be feasible
    equilibria with rest lengths (the file's, else designed: :func:`with_designed_rest_lengths`),
    before any controller design; the packaged one is ``result.problem.packaged``."""
    import dataclasses
    final = with_designed_rest_lengths(system, what="deployed")
    packaged = with_designed_rest_lengths(system.problem.packaged, what="packaged")
    return final.replace(problem=dataclasses.replace(final.problem, packaged=packaged))


def own_path(system) -> str:
    """The deployment path of ``system``: its ``[deployment] path``, else ``"delta"`` for a
    1-N(D) system, ``"auto"`` for an M >= 2 system and ``"linear"`` otherwise."""
    p = system.problem.deployment.path
    if p is not None:
        return p
    return "delta" if system.deployable else ("auto" if system.M >= 2 else "linear")


def automatic_path_of(final, *, r_min: float):
    """The automatic path (:func:`tmfem.equilibrium.deployment_path.automatic_path`) of the
    checked M >= 2 ``final`` (:func:`checked_configurations`) from its packaged configuration,
    with the membrane stiffness of its equilibrium design and the rest-length limit ``r_min``
    [m]."""
    from tmfem.equilibrium.deployment_path import automatic_path, membrane_stiffness
    from tmfem.equilibrium.design import design_equilibrium
    kappa = membrane_stiffness(design_equilibrium(final.replace(rest_lengths=None), strict=False))
    try:
        return automatic_path(final, final.problem.packaged.symmetric, kappa=kappa, r_min=r_min)
    except InfeasibleDesign as exc:
        raise type(exc)(f"deploy {final.name}: {exc}") from None


def setup(system, *, controller: str = "adaptive-hinf", uncertainty: str | None = None,
          allocation: str = "bounded", path: str | None = None, evaluation: str = "state",
          tendon_law: str = "fixed-rate", gains=None):
    """The deployment of ``system`` (a System with ``[packaged]`` and ``[deployment]``, or a
    preset name) from its packaged to its deployed configuration (:func:`build_deployment`).
    ``gains``: the PFL's (omega_0, omega_e, tau, d_c) of eq. 5.69 in rad/s, rad/s, s and -
    (default: the file's ``[deployment] gains``, Table 7.1 for the presets).
    ``path`` (default the file's): ``"delta"`` (1-N(D): psi_r from eq. 3.22 with the
    membrane stretch Delta linear in s), ``"table-7-7-bases"`` (2-3: the stage-2 base on the
    reconstructed Table 7.7 rule, :func:`tmfem.reference.tables.deployment_bases`) or
    ``"auto"`` (M >= 2: the automatic path through the symmetric equilibria,
    :func:`automatic_path_of`) or ``"linear"`` (every symmetric parameter linear in s). ``evaluation``: where the PFL
    evaluates its model terms (``"state"``, eq. 5.58, or ``"reference"``); ``tendon_law``: its
    tendon model (``"fixed-rate"``, eq. 5.19, or ``"cable"``, :mod:`tmfem.control.deployment.adaptive`)."""
    from tmfem.control.deployment.adaptive import Gains
    from tmfem.control.deployment.run import build_deployment
    from tmfem.reference.tables import deployment_bases
    final = deployable_system(system)
    check_choices(final, controller=controller, uncertainty=uncertainty, path=path)
    final = checked_configurations(final)
    p = final.problem.deployment
    path = path or own_path(final)
    w0, we, tau, dc = p.gains if gains is None else gains
    u_m = final.problem.control.u_m
    auto = automatic_path_of(final, r_min=p.r_min) if path == "auto" else None
    return build_deployment(final=final, initial=final.problem.packaged, omega_r=p.omega_r,
                            gains=Gains(omega_0=w0, omega_e=we, tau=tau, d_c=dc),
                            uncertainty=uncertainty or p.uncertainty,
                            output_points=inside_points(final, measured_points(final)) or None,
                            linear=CONTROLLERS[controller],
                            **({} if u_m is None else {"u_m": u_m}),
                            bases=deployment_bases(final) if path == "table-7-7-bases" else None,
                            delta_path=path == "delta", allocation=allocation,
                            evaluation=evaluation, tendon_law=tendon_law,
                            n_centers=p.rbf_centres, w_bar=p.w_bar, gamma=p.gamma, r_min=p.r_min,
                            path=None if auto is None else auto.path.config, tension_floor=p.floor,
                            info=None if auto is None else {"path_check": auto.to_dict()})


def check_choices(system, *, controller: str = "adaptive-hinf", uncertainty=None,
                  path=None) -> None:
    """Refuse a system without a deployment, one with fewer tendons than bar coordinates (B_q
    of eq. 5.46 without full row rank), an unknown controller, uncertainty model or path
    (before any work: ``tmfem deploy`` calls it first)."""
    system = deployable_system(system)
    nt, nq = len(system.tendons), len(system.q_names)
    if nt < nq:
        raise InputError(f"deploy {system.name}: the adaptive PFL needs at least one actuated tendon "
                         f"per bar coordinate (a B_q of eq. 5.46 with full row rank); this "
                         f"{system.M}-{system.N} system has {nt} tendons for {nq} bar coordinates")
    if system.problem.deployment.tension_floor is not None and nt == nq:
        raise InputError(f"deploy {system.name}: [deployment] tension_floor applies to an over-actuated "
                         f"system (more tendons than bar coordinates, whose spare tendons keep the "
                         f"prestress); this {system.M}-{system.N} system has {nt} tendons for {nq} bar "
                         "coordinates (a square B_q of eq. 5.46, no freedom to keep a floor)")
    own = own_path(system)
    allowed = ["linear", own] + (["auto"] if system.M >= 2 and own != "auto" else [])
    if path is not None and path not in allowed:
        raise InputError(f"--path for {system.name}: expected one of {allowed}, found {path!r}")
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


def write_deployment_series(directory, model, r, *, name: str) -> Path:
    """The ParaView series of run ``r``, a frame every :data:`VTK_EVERY` samples: bars,
    tendons with their forces and rest lengths, and the deflected membrane of the model's
    field (:func:`tmfem.post.deploy_plots.membrane_frames`) with its deflection in O_f."""
    from tmfem.io.fields import DISPLACEMENT_FIELD, MembraneField
    from tmfem.io.series import SeriesWriter
    from tmfem.post.deploy_plots import membrane_frames
    idx = np.arange(0, r.t.size, VTK_EVERY)
    xm, defl, _ = membrane_frames(model, r, idx)
    series = SeriesWriter(directory, name=name)
    for j, k in enumerate(idx):
        series.append_configuration(
            float(r.t[k]), model.system, q=r.z[k, :model.nq], tendon_forces=r.tendon_force[k],
            rest_lengths=r.u[k], membrane=MembraneField(mesh=model.membrane.mesh, x=xm[j],
                                                        point_data={DISPLACEMENT_FIELD: defl[j]}))
    return series.pvd


def write_outputs(s, r, *, preset: str, title: str, csv_path=None, plot=None, gif=None,
                  vtk=None, lpv: bool | None = None) -> dict:
    """Write the files of deployment run ``r`` of set-up ``s``: CSV, plot (Figures 7.2-7.4, or
    8.2-8.4 for an LPV deployment: ``lpv``, default whether the deployed system has an
    ``[lpv]`` table), GIF (Figures 7.5, 8.5) and ParaView series (a frame every
    :data:`VTK_EVERY` samples, series named ``preset``); returns {kind: path} of those written."""
    out = {}
    if csv_path:
        out["csv"] = write_csv(csv_path, r)
    if plot:
        from tmfem.post.deploy_plots import plot_deployment, plot_lpv_deployment
        if lpv is None:
            lpv = s.model.system.problem.lpv is not None
        draw = plot_lpv_deployment if lpv else plot_deployment
        out["plot"] = str(draw(plot, r, title=title))
    if gif:
        from tmfem.post.deploy_plots import animate_deployment
        out["gif"] = str(animate_deployment(gif, s.model, r))
    if vtk:
        out["pvd"] = str(write_deployment_series(Path(vtk), s.model, r, name=preset))
    return out


#: controllers of an LPV deployment (``tmfem deploy --controller``)
LPV_CONTROLLERS = ("lpv", "lpv-output")


#: the stage-base rules of LPV grids already built: id(system) -> (weak reference, rule)
_LPV_BASES: dict = {}


def lpv_bases(system):
    """The stage-base rule ``bases(theta, psi)`` of ``system``'s LPV grid (8.3, eq. 5.97) by
    its ``[lpv] path`` (:func:`tmfem.system.problem.lpv_path`): "table-7-7-bases",
    :func:`tmfem.reference.tables.deployment_bases` (two-stage systems); "auto", the
    automatic deployment path from the file's ``[packaged]`` to its deployed configuration
    (:func:`automatic_path_of`, both ends checked and designed first; the rest-length limit
    ``[deployment] r_min`` when the file has that table) read at every grid point by
    :class:`tmfem.equilibrium.deployment_path.PathBases`. Built once per system.

    Raises
    ------
    InputError
        A one-stage system (:func:`_one_stage_refusal`), or "auto" without a symmetric
        ``[packaged]`` configuration.
    InfeasibleDesign
        The packaged or deployed configuration, or every path between them, infeasible.
    """
    from tmfem.system.problem import DeploymentParameters, lpv_path
    known = _LPV_BASES.get(id(system))
    if known is not None and known[0]() is system:
        return known[1]
    if system.symmetric is None:
        raise InputError(f"LPV grid of {system.name}: expected a symmetric system ([symmetric]), found none")
    if system.M == 1:
        raise _one_stage_refusal(system)
    path = lpv_path(system)
    if path == "table-7-7-bases":
        from tmfem.reference.tables import deployment_bases
        rule = deployment_bases(system)
    else:
        from tmfem.equilibrium.deployment_path import PathBases, membrane_stiffness
        from tmfem.equilibrium.design import design_equilibrium
        pk = system.problem.packaged
        if pk is None or pk.symmetric is None:
            raise InputError(f"LPV grid of {system.name} on the automatic path: expected a symmetric "
                             "[packaged] configuration in the system file (the path's start), found "
                             + ("none" if pk is None else "a non-symmetric one"))
        r_min = (system.problem.deployment or DeploymentParameters()).r_min
        final = checked_configurations(system)
        auto = automatic_path_of(final, r_min=r_min)
        kappa = membrane_stiffness(design_equilibrium(final.replace(rest_lengths=None), strict=False))
        rule = PathBases(path=auto.path, kappa=kappa, r_min=r_min)
    return _remember(system, rule)


def _remember(system, rule):
    """``rule`` kept as ``system``'s for :func:`lpv_bases` (while the system lives)."""
    _LPV_BASES[id(system)] = (weakref.ref(system, lambda _, k=id(system), d=_LPV_BASES: d.pop(k, None)), rule)
    return rule


def _one_stage_refusal(system) -> InputError:
    """Why a one-stage system gets no LPV grid (docs/guides/lpv.md): the reference of eq.
    5.100 moves theta at a fixed psi_0, while a 1-N(D) system deploys along the Delta rule of
    eq. 3.22, psi moving with theta; a 1-N system's equilibria form a curve in (theta, psi)."""
    if not system.deployable:
        why = ("a 1-N system's reduced equilibrium matrix of 3.3.2 is square, so its equilibria form a curve in "
               "(theta, psi), not a region a grid covers")
    else:
        pk = system.problem.packaged
        ends = "" if pk is None or pk.symmetric is None else (
            f" (its packaged ({np.degrees(pk.symmetric.theta[0]):.4g}, {np.degrees(pk.symmetric.psi[0]):.4g}) deg "
            f"and deployed ({np.degrees(system.symmetric.theta[0]):.4g}, "
            f"{np.degrees(system.symmetric.psi[0]):.4g}) deg)")
        why = ("a 1-N(D) system deploys along the Delta rule of eq. 3.22, psi moving with theta" + ends
               + ", which the reference of eq. 5.100 (theta at a fixed psi_0) cannot follow; its deployment is "
               "the 7.4 one (tmfem deploy FILE: adaptive PFL, then the H-infinity switch)")
    return InputError(f"LPV grid of {system.name}: expected a symmetric system with M >= 2 stages, found "
                      f"M = 1: {why} (docs/guides/lpv.md)")


def lpv_setup(system, plant, *, model_at: str = "final"):
    """The deployment of 8.4 of ``system`` (a System with an ``[lpv]`` table and the
    scheduling values theta0_deg, theta_e_deg, psi0_deg of eq. 5.100, or a preset name) for
    the design plant ``plant`` (its grid built with the stage bases of :func:`lpv_bases`, as
    ``tmfem control lpv``): :func:`tmfem.control.lpv.deployment.lpv_deployment` with the file's ``[lpv]`` parameters
    (another System, e.g. with stiffer bars, for a perturbation study of an FE plant)."""
    from tmfem.control.lpv.deployment import lpv_deployment
    from tmfem.control.lpv.plant import lpv_membrane_modes
    if isinstance(system, str):
        from tmfem.system.presets import load_preset
        system = load_preset(system)
    p = system.problem.lpv
    if p is None:
        raise InputError(f"LPV deployment of {system.name}: expected an [lpv] table in the system "
                         "file (omega_r, membrane_modes, points, path; docs/guides/system-file.md)")
    missing = [k for k in ("theta0_deg", "theta_e_deg", "psi0_deg") if getattr(p, k) is None]
    if missing:
        raise InputError(f"LPV deployment of {system.name}: expected {missing} (eq. 5.100) in the "
                         "system file's [lpv] table")
    pts = p.points if p.points is not None else measured_points(system)
    from tmfem.system.problem import DeploymentParameters
    dp = system.problem.deployment or DeploymentParameters()
    return lpv_deployment(system, plant, theta_0=np.radians(p.theta0_deg),
                          theta_e=np.radians(p.theta_e_deg), psi_0=np.radians(p.psi0_deg),
                          omega_r=p.omega_r,
                          bases=lpv_bases(system), output_points=inside_points(system, pts),
                          membrane_modes=lpv_membrane_modes(system),
                          model_at=model_at, floor=dp.floor, r_min=dp.r_min)
