"""The complete analysis of one dissertation system, written as a report directory.

:func:`write_report` runs, for a preset such as ``1-4`` (6.2-6.5):

1. the equilibrium design of ch. 3 beside the printed Tables 6.2-6.3 (:mod:`tmfem.reference.study`);
2. the static equilibrium of the membrane-truss-cable (MTC) FE model (4.4, 6.2) for the
   designed rest lengths and, when the file gives one (``[report] implied_rest_lengths``: the
   prestress the dissertation's own results imply for the preset 1-4, docs/validation/errata.md), for a
   second set of rest lengths;
3. the 12 lowest modes of the MTC model, the shell-beam-cable (SBC) model and the
   control-oriented model (COM, ch. 5) at both prestress levels, beside the printed ones when
   the file carries them (``[printed.frequencies_hz]``, Table 6.6 for 1-4; eq. 5.32);
4. free vibration of both models after the perturbation of 6.5 (Park's method, eq. 5.34-5.35);
5. the closed-loop deployment of :func:`report_deployment` (7.4; the preset 1-4 runs 1-4(D)),
   with its plot, animation and ParaView series;

and writes every table (CSV with units in the headers, Markdown), plot (PNG), ParaView file
(VTU/PVD) and an ``index.md`` that links them and explains where and why the numbers differ
from the printed ones. The CLI front end is ``tmfem report``; ``make demo`` runs it for 1-4.
"""
from __future__ import annotations

import csv
import json
import logging
from pathlib import Path

import numpy as np
from tabulate import tabulate

from tmfem.errors import ConvergenceError, InfeasibleController, InfeasibleDesign
from tmfem.io.atomic import atomic_open, write_text
from tmfem.reference.study import has_printed

log = logging.getLogger(__name__)

def explanations(system, part: str) -> list[str]:
    """The notes the system's file gives beside its results (``[report] notes_design`` or
    ``notes_models``; ``part``: design or models); none unless the file carries them."""
    r = system.problem.report
    return list(r.notes_design if part == "design" else r.notes_models)


def report_deployment(system) -> dict | None:
    """The deployment the report of ``system`` runs: the file's ``[report] deployment``
    (``system``: a preset name or a system file; 1-4 -> 1-4D for the preset), else the
    system's own when it declares one (``[packaged]`` and ``[deployment]``: the H-infinity
    switch with the exact model, 20 s), else None. ``spec["system"]`` is the System deployed."""
    d = system.problem.report.deployment
    if d is not None:
        target = d["system"]
        if Path(target).suffix == ".toml":
            from tmfem.system.spec import load_system
            deployed = load_system(target)
        else:
            from tmfem.system.presets import load_preset
            deployed = load_preset(target)
        return {**d, "system": deployed, "source": target}
    if system.problem.packaged is not None and system.problem.deployment is not None:
        return {"system": system, "uncertainty": "exact", "t_end": 20.0,
                "controller": "adaptive-hinf"}
    return None


#: the finite-element models of the report by key
FE_NAMES = {"MTC": "membrane-truss-cable", "SBC": "shell-beam-cable"}

#: Steps of :func:`write_report`, for a progress bar.
STEPS = ("equilibrium design", "MTC statics (designed)", "MTC statics (implied)",
         "MTC modes", "SBC modes", "COM modes", "COM free vibration", "MTC free vibration",
         "deployment", "index")


def _csv(path: Path, header: list, rows: list) -> Path:
    with atomic_open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(header)
        w.writerows(rows)
    return path


def finite_or_none(obj):
    """``obj`` (nested dicts, lists, numbers) with every NaN or infinite float replaced by
    None: a value that could not be computed is absent, never a NaN in a file."""
    if isinstance(obj, dict):
        return {k: finite_or_none(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite_or_none(v) for v in obj]
    if isinstance(obj, (float, np.floating)) and not np.isfinite(obj):
        return None
    return obj


def frequency_cell(f, nd=5) -> str:
    """A natural frequency [Hz] for a table; a negative one (omega^2 < 0 in eq. 5.32: the
    equilibrium is unstable in that mode) is written ``unstable``, never as a frequency."""
    f = float(f)
    return "unstable" if f < 0 else _num(f, nd)


def unstable_modes(freqs: dict) -> dict:
    """{column: [mode numbers with omega^2 < 0]} of the frequency columns that have any."""
    out = {k: [i + 1 for i, f in enumerate(v) if f < 0] for k, v in freqs.items()}
    return {k: v for k, v in out.items() if v}


def _num(v, nd=5):
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "-"
    return f"{v:.{nd}g}"


def write_report(system, out, *, mesh_n: int = 10, modes: int = 12, t_end: float = 10.0,
                 dt: float = 0.01, render: bool = True, deploy: bool = True, progress=None,
                 run_progress=None, uncontrollable: str | None = None) -> dict:
    """Run the complete analysis of ``system`` and write it to the directory ``out``.

    Parameters
    ----------
    system : System
        Any system; its file's printed values and ``[report]`` table are shown where given
        (the preset ``1-4`` reproduces 6.2-6.5 in full).
    out : Path
        Output directory (must exist and be writable; the CLI checks it first).
    mesh_n : int
        Membrane elements per side of each of the N quadrilaterals (6.2: 10).
    modes : int
        Number of modes (Table 6.6: 12).
    t_end, dt : float
        Free-vibration duration and time step [s] (6.5: dt = 0.01 s).
    render : bool
        Draw the pyvista renders.
    deploy : bool
        Run the deployment of :func:`report_deployment` (when the system has one).
    uncontrollable : {"refuse", "exclude"}, optional
        The ``[control] uncontrollable`` of the deployed system, overriding its file's
        (:func:`tmfem.control.linear.deployed_design.deployed_hinf`).
    progress : callable, optional
        ``progress(step_name)`` after each entry of :data:`STEPS`.
    run_progress : callable, optional
        ``run_progress(label)`` -> a ``progress(step, n_steps)`` callback for the time runs.

    Returns
    -------
    dict (JSON-able): ``files`` (name -> path), ``tables``, ``ok`` and the summaries.
    """
    from tmfem.equilibrium.design import design_equilibrium
    from tmfem.io.codes import kind_cell_data
    from tmfem.io.units import with_units
    from tmfem.io.writer import write_configuration, write_modes
    from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes
    from tmfem.models.com.model import membrane_modes_of
    from tmfem.models.mtc.model import MTCModel
    from tmfem.models.fe.outputs import q_from_positions
    from tmfem.models.mtc.post import member_state, static_summary
    from tmfem.post.fields import placed_membrane_field
    from tmfem.post.mtc import membrane_field, model_cells, plot_membrane_stress
    from tmfem.post.plots import plot_free_vibration
    from tmfem.reference.com_modal import modal_summary
    from tmfem.reference.study import plot_configuration, plot_membrane_stress as plot_design_stress
    from tmfem.reference.study import write_tables
    from tmfem.reference.tables import printed_frequencies
    from tmfem.simulation.vibration import free_vibration, model_free_vibration

    out = Path(out)
    name = system.name
    step = progress or (lambda s: None)
    files: dict[str, str] = {}
    notes = explanations(system, "design") + explanations(system, "models")
    rep = system.problem.report
    implied = (None if rep.implied_rest_lengths is None else
               {"rest_lengths": dict(rep.implied_rest_lengths), "source": rep.implied_source})
    perturb = dict(rep.perturbation)

    def add(key, path):
        files[key] = str(Path(path).relative_to(out))

    # 1. design (ch. 3) ------------------------------------------------------------------
    d = design_equilibrium(system, mesh_n=mesh_n)
    tables = write_tables(out, d, system, notes=explanations(system, "design"))
    for f in ("equilibrium.md", "equilibrium.csv", "tendons.csv"):
        add(f, out / f)
    add("configuration.png", plot_configuration(out / "configuration.png", d, system))
    add("membrane_stress.png", plot_design_stress(out / "membrane_stress.png", d))
    membrane = placed_membrane_field(system, d.membrane_model, d.membrane)
    add("configuration.vtu", write_configuration(
        out / "configuration.vtu", system, tendon_forces=d.tendon_forces,
        rest_lengths=d.rest_lengths, membrane=membrane, bar_forces=-d.bar_loads.ravel()))
    if render:
        from tmfem.post.render import render_configuration
        add("render.png", render_configuration(out / "render.png", system,
                                               tendon_forces=d.tendon_forces, membrane=membrane,
                                               membrane_field="von_mises",
                                               title=f"{name}: equilibrium design (ch. 3)"))
    step(STEPS[0])

    # 2. FE statics (MTC; SBC for 1-N(D)) at both prestress levels ----------------------------------------
    cases = {"designed": ("design", system)}
    if implied is not None:
        cases["implied"] = ("system", system.with_rest_lengths(implied["rest_lengths"]))
    mtc, sbc_runs, statics = {}, {}, {}
    fe = "SBC" if system.deployable else "MTC"      # the MTC model has no H_1j nodes (1-N(D))
    for k, (label, (rest, sys_k)) in enumerate(cases.items()):
        if system.deployable:
            from tmfem.models.sbc.model import SBCModel
            from tmfem.models.sbc.post import static_summary as sbc_static_summary
            sbc = SBCModel(sys_k, mesh_n=mesh_n, tendon_elements=3, rest_lengths=rest)
            st = sbc.equilibrium()
            sbc_runs[label] = (sbc, st)
            statics[label] = sbc_static_summary(sbc, st)
            step(STEPS[1 + k])
            continue
        model = MTCModel(sys_k, mesh_n=mesh_n, tendon_elements=3, rest_lengths=rest)
        res = model.equilibrium(start="undeformed")
        mtc[label] = (model, res)
        statics[label] = static_summary(model, res.x, result=res)
        X = res.x[:, model.topology.system_node]
        q = q_from_positions(sys_k, X)
        ms = member_state(model, res.x)
        mf = membrane_field(model, res.x)
        add(f"static_{label}.vtu", write_configuration(
            out / f"static_{label}.vtu", sys_k, q=q, tendon_forces=ms["tendon_force"],
            rest_lengths=model.rest_lengths, membrane=mf, bar_forces=ms["bar_force"]))
        add(f"static_{label}_stress.png", plot_membrane_stress(
            out / f"static_{label}_stress.png", model, res.x,
            title=f"{name} MTC equilibrium, {label} prestress: membrane stresses (O_f frame)"))
        if render:
            from tmfem.post.render import render_configuration
            add(f"static_{label}.png", render_configuration(
                out / f"static_{label}.png", sys_k, q=q, tendon_forces=ms["tendon_force"],
                membrane=mf, membrane_field="von_mises",
                title=f"{name} MTC equilibrium, {label} prestress"))
        step(STEPS[1 + k])
    if implied is None:
        step(STEPS[2])
    add("statics.csv", _statics_table(out / "statics.csv", system, statics, fe))

    # 3. modes -------------------------------------------------------------------------------
    freqs = {}
    for label, (model, res) in mtc.items():
        md = model.modes(k=modes, at=res)
        freqs[f"MTC {label}"] = md.freq_hz
        if label == "designed":
            shapes = model.topology.T @ md.shapes
            cells = model_cells(model)
            add("modes.vtu", write_modes(out / "modes.vtu", res.x, cells, shapes, md.freq_hz,
                                         cell_data=kind_cell_data(cells)))
            if render:
                from tmfem.post.render import render_modes
                add("modes.png", render_modes(out / "modes.png", points=res.x, cells=cells,
                                              shapes=shapes, freq_hz=md.freq_hz,
                                              k=min(modes, 12),
                                              title=f"{name} MTC modes, designed prestress"))
    step(STEPS[3])
    for label, (sbc, st) in sbc_runs.items():
        freqs[f"SBC {label}"] = sbc.modes(k=modes, at=st).freq_hz
    if not system.deployable:
        from tmfem.models.sbc.model import SBCModel
        for label, (rest, sys_k) in cases.items():
            sbc = SBCModel(sys_k, mesh_n=mesh_n, tendon_elements=3, rest_lengths=rest)
            st = sbc.equilibrium()
            freqs[f"SBC {label}"] = sbc.modes(k=modes, at=st).freq_hz
    step(STEPS[4])
    K = default_membrane_modes(system)
    com_design = modal_summary(system, modes=modes, membrane_modes=K, mesh_n=mesh_n)
    freqs["COM designed"] = np.array(com_design["freq_hz"])
    scale = com_design.get("printed_stress_prestress_scale")
    if scale is not None:
        com_implied = modal_summary(system, modes=modes, membrane_modes=K, prestress_scale=scale,
                                   mesh_n=mesh_n)
        freqs[f"COM x{scale:.4f}"] = np.array(com_implied["freq_hz"])
    step(STEPS[5])
    disagreement = com_disagreement(freqs, fe, K, declared=system.model_defaults.get("com", {}).get(
        "membrane_modes") is not None)
    if disagreement:
        log.warning("%s: %s", name, disagreement["message"])
    printed = printed_frequencies(system)
    add("frequencies.csv", _frequency_table(out / "frequencies.csv", freqs, printed, modes))
    add("frequencies.png", _frequency_plot(out / "frequencies.png", freqs, printed, modes, name))

    # 4. free vibration -----------------------------------------------------------------------
    pts, nodes = monitored(system)
    com = ControlOrientedModel(system, membrane_modes=K, mesh_n=mesh_n, output_points=pts)
    vdir = out / "vibration_com"
    r_com = free_vibration(com, t_end=t_end, dt=dt, perturb=perturb, monitor_nodes=nodes,
                           csv_path=out / "vibration_com.csv", jacobian="reuse",
                           vtk_dir=vdir, vtk_every=max(1, int(round(0.1 / dt))),
                           progress=_run_progress(run_progress, "COM free vibration"))
    add("vibration_com.csv", out / "vibration_com.csv")
    add("vibration_com.pvd", Path(r_com.stats["pvd"]))
    add("vibration_com.png", plot_free_vibration(
        r_com, out / "vibration_com.png",
        title=f"{name} COM free vibration, K = {K}, " + _perturbation_text(perturb)))
    step(STEPS[6])
    lo = fe.lower()
    model, res = sbc_runs["designed"] if system.deployable else mtc["designed"]
    r_fe = model_free_vibration(model, at=res, dynamics={"output_points": pts}, t_end=t_end, dt=dt,
                                perturb=perturb, monitor_nodes=nodes,
                                csv_path=out / f"vibration_{lo}.csv",
                                progress=_run_progress(run_progress, f"{fe} free vibration"))
    add(f"vibration_{lo}.csv", out / f"vibration_{lo}.csv")
    add(f"vibration_{lo}.png", plot_free_vibration(
        r_fe, out / f"vibration_{lo}.png",
        title=f"{name} {fe} free vibration, mesh {mesh_n}, " + _perturbation_text(perturb)))
    step(STEPS[7])
    deployment = None
    spec = report_deployment(system) if deploy else None
    if spec is not None and uncontrollable is not None:
        from tmfem.control.linear.deployed_design import with_uncontrollable
        spec["system"] = with_uncontrollable(spec["system"], uncontrollable)
    if spec is not None:
        try:
            deployment = _deployment(out, spec, dt=dt, add=add,
                                     progress=_run_progress(run_progress, "deployment"))
        except (InfeasibleController, InfeasibleDesign, ConvergenceError) as exc:
            # the rest of the report stands; section 5 and the failed checks say why it has no run
            deployment = {"system": spec["system"].name, "controller": spec["controller"],
                          "uncertainty": spec["uncertainty"], "t_end": spec["t_end"], "not_run": str(exc)}
    step(STEPS[8])

    vibration = {"COM": _vibration_summary(r_com), fe: _vibration_summary(r_fe)}
    summary = {"system": name, "fe_model": fe, "mesh_n": mesh_n, "modes": modes, "t_end_s": t_end, "dt_s": dt,
               "perturbation": perturb, "design_ok": bool(d.ok),
               "failed_checks": [c.name for c in d.failed] + _result_failures(statics, freqs, fe)
               + deployment_failures(deployment),
               "implied_prestress": implied,
               "statics": {k: _static_brief(v) for k, v in statics.items()},
               "frequencies_hz": {k: v.tolist() for k, v in freqs.items()},
               "unstable_modes": unstable_modes(freqs), "com_disagreement": disagreement,
               "com_membrane_modes": membrane_modes_of(system).to_dict(),
               "printed_frequencies_hz": printed, "vibration": vibration,
               "deployment": deployment}
    summary = finite_or_none(summary)
    write_text(out / "report.json", json.dumps(with_units(summary), indent=1, allow_nan=False))
    add("report.json", out / "report.json")
    _index(out, system, summary, files, tables["rows"], notes, freqs, printed, statics)
    add("index.md", out / "index.md")
    from tmfem.post.html_report import write_html_report
    add("report.html", write_html_report(out))
    step(STEPS[9])
    summary["files"] = files
    summary["notes"] = notes
    summary["out"] = str(out)
    summary["ok"] = not summary["failed_checks"]
    return summary


def monitored(system) -> tuple:
    """(membrane points (x_f, y_f) [m], node labels) the free vibration records: the file's
    ``[monitor]`` points and nodes, else points inside the membrane
    (:func:`tmfem.control.linear.generalized_plant.interior_points`) and the upper end of the
    first bar of the top stage."""
    from tmfem.control.linear.generalized_plant import interior_points
    pts = ([tuple(p) for p in system.monitor_points.T.tolist()] if system.monitor_points.size
           else interior_points(system))
    nodes = list(system.monitor_nodes) or [f"B_{system.M}1"]
    return pts, nodes


#: relative difference of a COM frequency to the FE model's above which the report names the
#: mode (6.4 finds < 3 % for 1-4 and < 1 % for 2-3 with the dissertation's K)
COM_TOLERANCE = 0.05


def com_disagreement(freqs: dict, fe: str, K: int, *, declared: bool = True) -> dict | None:
    """Modes whose COM frequency (designed prestress) differs from the FE model's by more than
    :data:`COM_TOLERANCE`, with a hint: the K membrane modes of the COM (``[models.com]
    membrane_modes``) limit the membrane modes it represents (the 3 m Kapton 1-4 of the tests:
    modes 8-12 at K = 4 differ by up to 35 %, at K = 8 by up to 7 %). ``declared``: K is the
    file's; otherwise it is the automatic choice, beyond which more modes no longer change the
    frequencies, and the hint says so. None when all agree."""
    com, ref = freqs.get("COM designed"), freqs.get(f"{fe} designed")
    if com is None or ref is None:
        return None
    n = min(len(com), len(ref))
    c, r = np.asarray(com[:n], dtype=float), np.asarray(ref[:n], dtype=float)
    ok = (c > 0) & (r > 0)
    rel = np.where(ok, c / np.where(ok, r, 1.0) - 1, 0.0)
    bad = [int(i) + 1 for i in np.flatnonzero(ok & (np.abs(rel) > COM_TOLERANCE))]
    if not bad:
        return None
    msg = (f"COM frequencies of modes {bad} differ from the {fe} model's by more than "
           f"{100 * COM_TOLERANCE:g} % (largest {100 * np.max(np.abs(rel)):.1f} %): the COM has K = "
           + (f"{K} membrane modes ([models.com] membrane_modes in the system file): more modes bring "
              "its higher membrane modes closer; what remains is " if declared else
              f"{K} membrane modes (the automatic choice: more modes do not bring them closer): the "
              "difference is ")
           + "the COM's own approximation "
           "(rigid bars, linear tendon springs of eqs. 3.8-3.9, membrane modes about the designed "
           "prestress, ch. 5)")
    return {"modes": bad, "relative_difference": rel.tolist(), "tolerance": COM_TOLERANCE,
            "message": msg}


def _result_failures(statics: dict, freqs: dict, fe: str) -> list[str]:
    """Failed checks of the model results: the FE statics' checks (yield, slack tendons,
    buckling: :func:`tmfem.models.mtc.post.design_checks`) per prestress case, and an unstable
    equilibrium (omega^2 < 0) per frequency column, with its modes."""
    out = [f"{fe} {label}: {c['check']}" for label, st in statics.items()
           for c in st.get("checks", []) if not c["ok"]]
    out += [f"{col}: unstable equilibrium (modes {m})" for col, m in unstable_modes(freqs).items()]
    return out


def _run_progress(factory, label):
    return None if factory is None else factory(label)


def deployment_failures(deployment: dict | None) -> list[str]:
    """The report's failed checks of its deployment (the checks `tmfem deploy` exits 1 on):
    not run, a diverged run (``failure``), and the strength checks of the run (tendon and
    membrane yield, bar buckling: ``strength_checks_failed``), each named "deployment: ..."."""
    if not deployment:
        return []
    if "not_run" in deployment:
        return ["deployment not run"]
    out = [f"deployment: diverged ({deployment['failure']})"] if deployment.get("failure") else []
    return out + [f"deployment: {c}" for c in deployment.get("strength_checks_failed") or []]


def _deployment(out: Path, spec: dict, *, dt: float, add, progress) -> dict:
    """Run the deployment ``spec`` (:func:`report_deployment`) and write its CSV, plot, GIF and
    ParaView series into ``out`` (:func:`tmfem.reference.deployments.write_outputs`)."""
    from tmfem.control.deployment.run import run_deployment
    from tmfem.reference.deployments import setup, write_outputs

    deployed = spec["system"]
    p = file_stem(deployed.name)
    s = setup(deployed, controller=spec["controller"], uncertainty=spec["uncertainty"])
    r = run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                       t_end=spec["t_end"], dt=dt, progress=progress)
    files = write_outputs(s, r, preset=p, csv_path=out / f"deploy-{p}.csv",
                          plot=out / f"deploy-{p}.png", gif=out / f"deploy-{p}.gif",
                          vtk=out / f"deploy-{p}",
                          title=f"{p} deployment: {spec['controller']}, uncertainty "
                                f"{s.adaptive.uncertainty}")
    suffix = {"csv": "csv", "plot": "png", "gif": "gif", "pvd": "pvd"}
    for kind, path in files.items():
        add(f"deploy-{p}.{suffix[kind]}", path)
    scalars = {k: float(v) for k, v in s.info.items() if np.isscalar(v)}
    ys = [s.model.system.tendon_section(t).yield_stress for t in s.model.system.tendons]
    yield_mpa = min(ys) / 1e6 if all(ys) else None
    excluded = {k: s.info[k] for k in ("excluded_modes_hz",) if k in s.info}
    return {**spec, "system": deployed.name, "file_stem": p, "dt_s": dt, **r.summary(), **scalars,
            "tendon_yield_MPa": yield_mpa, **excluded}


def file_stem(name: str) -> str:
    """``name`` as a file-name stem (letters, digits, ``-``, ``_`` and ``.``; others become ``_``)."""
    import re
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_") or "system"


def _perturbation_text(perturb: dict) -> str:
    """``theta_12_dot = 0.01 rad/s`` (rates in rad/s, angles in rad, positions in m)."""
    def unit(k):
        base = k[:-4] if k.endswith("_dot") else k
        u = "rad" if base.startswith(("theta", "psi")) else "m"
        return u + "/s" if k.endswith("_dot") else u
    return ", ".join(f"{k} = {v:g} {unit(k)}" for k, v in perturb.items())


def _static_brief(s: dict) -> dict:
    return {"tendon_stress_max_MPa": s["tendon_stress_max"] / 1e6,
            "bar_load_max_N": s["bar_load_max"],
            "membrane_max_sigma_p1_MPa": s["membrane_max_sigma_p1"] / 1e6,
            "membrane_max_von_mises_MPa": s["membrane_max_von_mises"] / 1e6,
            "Delta_mean_mm": float(np.mean(s["Delta"])) * 1e3,
            "rest_lengths_m": s["rest_lengths"], "iterations": s.get("iterations"),
            "slack_tendons": s["tendon_slack"]}


def _statics_rows(system, statics: dict) -> list:
    """Rows [quantity, unit, printed, (ours, rel. diff) per case]; without printed values
    (:func:`tmfem.reference.study.has_printed`) [quantity, unit, ours per case]."""
    rows = _statics_rows_printed(system, statics)
    if has_printed(system=system):
        return rows
    return [r[:2] + r[3::2] for r in rows]


def _statics_rows_printed(system, statics: dict) -> list:
    p = system.printed
    rows = []
    spec = [("max tendon stress", "MPa", "tendon_stress_max_MPa", p.get("tendon_max_stress"), 1e-6),
            ("max bar load (compression)", "N", "bar_load_max_N", p.get("bar_load"), 1.0),
            ("membrane max sigma_p1", "MPa", "membrane_max_sigma_p1_MPa",
             p.get("membrane_max_sigma_p1"), 1e-6),
            ("membrane max von Mises", "MPa", "membrane_max_von_mises_MPa",
             p.get("membrane_max_von_mises"), 1e-6),
            ("mean corner displacement Delta", "mm", "Delta_mean_mm", None, 1.0)]
    briefs = {k: _static_brief(v) for k, v in statics.items()}
    for q, unit, key, pr, f in spec:
        row = [q, unit, None if pr is None else pr * f]
        for label in statics:
            v = briefs[label][key]
            row += [v, None if pr is None else v / (pr * f) - 1]
        rows.append(row)
    # the first tendon's rest length, named (S_11 of an M-N system, SL_1 of a 1-N(D) one)
    first = next(iter(briefs[next(iter(statics))]["rest_lengths_m"]))
    group = next((t.group for t in system.tendons if t.name == first), None)
    r = [f"rest length {first}", "m", (p.get("rest_lengths") or {}).get(group)]
    for label in statics:
        r += [briefs[label]["rest_lengths_m"][first], None]
    rows.append(r)
    return rows


def _statics_header(system, statics: dict, fe: str = "MTC") -> list:
    if not has_printed(system=system):
        return ["quantity", "unit"] + [f"{fe} {label}" for label in statics]
    h = ["quantity", "unit", "printed"]
    for label in statics:
        h += [f"{fe} {label}", f"rel_diff {label}"]
    return h


def _statics_table(path: Path, system, statics: dict, fe: str) -> Path:
    rows = _statics_rows(system, statics)
    return _csv(path, _statics_header(system, statics, fe),
                [[r[0], r[1]] + [_num(v, 6) for v in r[2:]] for r in rows])


def _frequency_table(path: Path, freqs: dict, printed, modes: int) -> Path:
    cols = list(freqs)
    head = ["mode"] + [f"{c} [Hz]" for c in cols]
    if printed:
        head += [f"{m} {printed['source'].split()[-1]} printed [Hz]" for m in ("MTC", "SBC", "COM")]
    rows = []
    for i in range(modes):
        row = [i + 1] + [frequency_cell(freqs[c][i], 6) if i < len(freqs[c]) else "-" for c in cols]
        if printed:
            row += [_num(printed[m][i], 6) if i < len(printed[m]) else "-" for m in ("MTC", "SBC", "COM")]
        rows.append(row)
    return _csv(path, head, rows)


def _frequency_plot(png: Path, freqs: dict, printed, modes: int, name: str) -> Path:
    """Our frequencies with the printed ones (black open markers) and, when the system has
    printed ones, a second panel with the relative difference of each of our columns to the
    printed column of its model. Unstable modes (omega^2 < 0) have no point."""
    from tmfem.post.plots import mode_styles, new_figure, save_figure

    if printed:
        fig = new_figure(figsize=(7.5, 7.2))
        ax, dx = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    else:
        fig = new_figure(figsize=(7.5, 4.5))
        ax, dx = fig.subplots(1, 1), None
    k = np.arange(1, modes + 1)
    styles = mode_styles(len(freqs))
    for (label, f), style in zip(freqs.items(), styles):
        n = min(modes, len(f))
        f = np.asarray(f[:n], dtype=float)
        ok = f >= 0                                   # unstable modes have no frequency
        ax.plot(k[:n][ok], f[ok], label=label, ms=4, lw=1.0, **style)
        ref = np.asarray((printed or {}).get(label.split()[0], []), dtype=float)
        m = min(n, ref.size)
        if m:
            j = ok[:m]
            dx.plot(k[:m][j], 100 * (f[:m][j] / ref[:m][j] - 1), ms=4, lw=1.0, label=label, **style)
    if printed:
        src = printed["source"].split("dissertation ")[-1]
        for m, mk in (("MTC", "o"), ("SBC", "s"), ("COM", "^")):
            ref = np.asarray(printed.get(m, []), dtype=float)[:modes]
            ax.plot(k[:ref.size], ref, mk, mfc="none", mec="k", ms=8, mew=0.8,
                    label=f"{m} printed ({src})")
    ax.set_ylabel("natural frequency [Hz]")
    ax.set_title(f"{name}: natural frequencies (eq. 5.32)"
                 + (" beside the printed table" if printed else ""), fontsize=10)
    ax.legend(fontsize=7, loc="upper left", ncol=2)
    if dx is not None:
        dx.axhline(0.0, color="k", lw=0.6)
        dx.set_ylabel("difference to the printed\ncolumn of the model [%]")
    bottom = dx if dx is not None else ax
    bottom.set_xlabel("mode number")
    bottom.set_xticks(k)
    for a in (ax, dx):
        if a is not None:
            a.grid(True, alpha=0.3)
    return save_figure(fig, png)


def _vibration_summary(r) -> dict:
    return {"steps": int(r.stats["steps"]), "wall_time_s": float(r.wall_time),
            "min_tendon_force_N": float(r.stats["min_tendon_force"]),
            "min_tendon_force_tendon": r.stats["min_tendon_force_tendon"],
            "peak_to_peak_mm": {k: (1e3 * np.ptp(v, axis=0)).tolist() for k, v in r.nodes.items()}}


def _largest_differences(freqs: dict, printed) -> str:
    """One line: the largest relative difference of each of our columns to the printed
    column of its model (MTC, SBC, COM)."""
    if not printed:
        return ""
    parts = []
    for label, f in freqs.items():
        ref = np.asarray(printed.get(label.split()[0], []), dtype=float)
        n = min(len(ref), len(f))
        if n:
            parts.append(f"{label} {100 * np.max(np.abs(np.asarray(f[:n]) / ref[:n] - 1)):.2f} %")
    return "Largest difference to the printed column of the same model: " + ", ".join(parts) + "."


def _deployment_section(d, link, img) -> list[str]:
    """Section 5 of the index: the deployment run of :func:`report_deployment`."""
    if not d:
        return []
    if "not_run" in d:
        return ["## 5. Deployment (7.4)", "",
                f"The deployment of `{d['system']}` (`--controller {d['controller']}`, `--uncertainty "
                f"{d['uncertainty']}`) was not run: {d['not_run']}", ""]
    p = d["file_stem"]
    rows = [("switching time to the linear controller", "s", d["switch_time_s"]),
            ("largest membrane deflection w", "mm", 1e3 * d["max_membrane_deflection_m"]),
            ("peak bar compression", "N", d["peak_bar_compression_N"]),
            ("bar Euler load (eq. 5.31)", "N", d["bar_critical_load_N"]),
            ("largest membrane von Mises stress", "MPa", 1e-6 * d["max_von_mises_Pa"]),
            ("largest tendon stress", "MPa", 1e-6 * d["max_tendon_stress_Pa"]),
            ("tendon yield stress", "MPa", d.get("tendon_yield_MPa")),
            ("rest lengths at a limit", "s", d["limits_active_s"]),
            ("relative tracking error at the end", "-", d["final_tracking_error"]),
            ("wall time", "s", d["wall_time_s"])]
    how = (f"--preset {d['source']}" if d.get("source") and not d["source"].endswith(".toml")
           else "SYSTEM.toml")
    excluded = d.get("excluded_modes_hz", [])
    return ["## 5. Deployment (7.4)", "",
            f"`{d['system']}` from its packaged configuration to the deployed one: adaptive "
            "partial feedback linearisation (the gains of the file's [deployment] table, eq. 5.69; "
            "eq. 5.68 reference), then the "
            f"switch to the linear controller of `--controller {d['controller']}` (adaptive-hinf: "
            "the H-infinity controller of 7.3: the central one at 1.01 gamma_opt), "
            f"{d['t_end']:g} s at dt = {d['dt_s']:g} s, the controller's model error "
            f"`--uncertainty {d['uncertainty']}`. Same run: `tmfem deploy "
            f"{how} --uncertainty {d['uncertainty']} --t-end {d['t_end']:g}"
            f"{' --exclude-uncontrollable' if excluded else ''}`.", "",
            *(["Modes no tendon reaches (PBH, eq. 5.71), left out of the H-infinity design "
               "([control] uncontrollable = \"exclude\" or --exclude-uncontrollable): "
               f"{', '.join(f'{f:.4g} Hz' for f in excluded)}. They stay open loop, neither damped "
               "nor excited by the linear controller.", ""] if excluded else []),
            f"Files: {link(f'deploy-{p}.csv')} (every signal, units in the header), "
            f"{link(f'deploy-{p}.png')}, {link(f'deploy-{p}.gif')} (animation), "
            f"{link(f'deploy-{p}.pvd')} (ParaView series).", "",
            tabulate([[q, u, _num(v)] for q, u, v in rows], headers=["quantity", "unit", "value"],
                     tablefmt="github", disable_numparse=True), "",
            *([("The largest tendon stress exceeds the tendons' yield stress."), ""]
              if d.get("tendon_yield_MPa") and 1e-6 * d["max_tendon_stress_Pa"] > d["tendon_yield_MPa"]
              else []),
            img(f"deploy-{p}.png", "deployment"), "", img(f"deploy-{p}.gif", "deployment animation"),
            ""]


def _index(out: Path, system, summary: dict, files: dict, design_rows, notes, freqs, printed,
           statics) -> None:
    from tmfem.reference.study import markdown_table

    name = system.name
    link = lambda key, text=None: f"[{text or key}]({files[key]})" if key in files else "-"  # noqa: E731
    img = lambda key, alt: f"![{alt}]({files[key]})" if key in files else ""  # noqa: E731
    L = [f"# Report: the {name} system", "", system.description, "",
         f"Membrane mesh {system.N} x {summary['mesh_n']} x {summary['mesh_n']}, 3 truss elements "
         f"per tendon, {summary['modes']} modes, free vibration for {summary['t_end_s']:g} s in "
         f"steps of {summary['dt_s']:g} s. Made by `tmfem report`; every number "
         "below is in the linked CSV files (units in the headers). Printed values: "
         f"{system.printed.get('source', 'none')}.", ""]
    if notes:
        L += ["## Why ours and the printed values differ", ""] + [f"- {n}" for n in notes] + [""]
    L += ["## 1. Equilibrium design (ch. 3)", "",
          f"Files: {link('equilibrium.md')}, {link('equilibrium.csv')}, {link('tendons.csv')}, "
          f"{link('configuration.vtu')} (ParaView: bars, tendons with forces, membrane with "
          "stresses; cell data `kind` 0 bar, 1 tendon, 2 membrane).", "",
          markdown_table(design_rows), "",
          "Checks: " + ("all passed." if not summary["failed_checks"] else
                        "FAILED: " + ", ".join(summary["failed_checks"])), "",
          img("render.png", "design render"), "",
          img("configuration.png", "design configuration"), img("membrane_stress.png",
                                                                "design membrane stress"), ""]
    fe = summary["fe_model"]
    lo = fe.lower()
    L += [f"## 2. Statics of the {FE_NAMES[fe]} model (6.2)", "",
          *([("The membrane-truss-cable model has no nodes along its bars, so a 1-N(D) system "
              "(tendons attached at H_1j along the bars) is analysed with the shell-beam-cable "
              "model here."), ""] if fe == "SBC" else []),
          "From the undeformed membrane the rest lengths pull the system into equilibrium. "
          "'designed': the rest lengths of the design above"
          + ("; 'implied': rest lengths " + ", ".join(
              f"{g} = {v} m" for g, v in summary['implied_prestress']['rest_lengths'].items())
             + f" ({summary['implied_prestress']['source']})."
             if summary["implied_prestress"] else "."), "",
          "Files: " + ", ".join(link(k) for k in ["statics.csv", *(f"static_{c}.vtu" for c in statics)]
                                if k in files) + ".", ""]
    rows = _statics_rows(system, statics)
    with_printed = has_printed(system=system)
    L.append(tabulate([[r[0], r[1]] + [_num(v) if not with_printed or j % 2 == 1 or j == 0 else
                                        ("" if v is None else f"{100 * v:+.1f} %")
                                        for j, v in enumerate(r[2:])] for r in rows],
                      headers=_statics_header(system, statics, fe), tablefmt="github",
                      disable_numparse=True))
    L += ["", "Membrane stresses are element values (means over the Gauss points in the "
          "stress maps, maxima over Gauss points in the table); the peaks sit at the "
          "point-attached corners.", ""]
    for k in statics:
        L += [img(f"static_{k}.png", f"{fe} equilibrium {k}"), "",
              img(f"static_{k}_stress.png", f"{fe} membrane stress {k}"), ""]
    L += ["## 3. Natural frequencies and mode shapes (6.4, eq. 5.32)", "",
          f"Files: {link('frequencies.csv')}" + (f", {link('modes.vtu')} (ParaView: Warp By Vector "
                                                 "with `mode_k`; field data `mode_k_hz`; cell data "
                                                 "`kind`)" if "modes.vtu" in files else "") + ".", ""]
    head = ["mode"] + [f"{c} [Hz]" for c in freqs]
    if printed:
        head += [f"{m} printed [Hz]" for m in ("MTC", "SBC", "COM")]
    body = []
    for i in range(summary["modes"]):
        row = [i + 1] + [frequency_cell(f[i], 5) if i < len(f) else "-" for f in freqs.values()]
        if printed:
            row += [_num(printed[m][i], 5) if i < len(printed[m]) else "-" for m in ("MTC", "SBC", "COM")]
        body.append(row)
    L += [tabulate(body, headers=head, tablefmt="github", disable_numparse=True), "",
          f"Printed: {printed['source'] if printed else 'none'}. MTC: membrane-truss-cable "
          "(4.4), SBC: shell-beam-cable (4.3, MITC4 shell and beam bars), both on the mesh "
          "above; COM: control-oriented model (ch. 5) with K membrane modes"
          + ("; 'x<s>' scales the designed membrane prestress to the printed tendon stress."
             if any(k.startswith("COM x") for k in freqs) else "."), "",
          _largest_differences(freqs, printed), "",
          *([f"Warning: {summary['com_disagreement']['message']}.", ""]
            if summary.get("com_disagreement") else []),
          img("frequencies.png", "frequencies"), "", img("modes.png", "mode shapes"), ""]
    v = summary["vibration"]
    L += ["## 4. Free vibration (6.5)", "",
          f"Perturbation `{_perturbation_text(summary['perturbation'])}`, Park's method, "
          f"dt = {summary['dt_s']:g} s, designed prestress.", "",
          f"Files: {link('vibration_com.csv')}, {link('vibration_com.pvd')} (ParaView series), "
          f"{link(f'vibration_{lo}.csv')}.", ""]
    body = [[m, s["steps"], f"{s['wall_time_s']:.1f}", f"{s['min_tendon_force_N']:.4g} "
             f"({s['min_tendon_force_tendon']})",
             "; ".join(f"{n}: " + ", ".join(f"{a:.3f}" for a in p) for n, p in s["peak_to_peak_mm"].items())]
            for m, s in v.items()]
    L += [tabulate(body, headers=["model", "steps", "wall time [s]", "smallest tendon force [N]",
                                  "peak-to-peak x, y, z [mm]"], tablefmt="github",
                   disable_numparse=True), "",
          img("vibration_com.png", "COM free vibration"), "",
          img(f"vibration_{lo}.png", f"{fe} free vibration"), ""]
    L += _deployment_section(summary.get("deployment"), link, img)
    L += ["## All files", ""] + [f"- [{k}]({p})" for k, p in sorted(files.items())]
    write_text(out / "index.md", "\n".join(L) + "\n")
