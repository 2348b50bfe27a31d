"""Free vibration of one system in the three models from the same perturbation (6.5,
Figs. 6.21-6.29): the SBC, MTC and COM models of :mod:`tmfem.reference.model_compare` (the
prestress of Tables 6.6/6.7), each from its own static equilibrium with the same initial
rate (6.5.1: theta_12' = 0.01 rad/s for 1-4; 6.5.2: theta_11' = 0.01 rad/s for 2-3),
integrated by Park's method with the same step (dt = 0.01 s).

Compared signals, all as displacements from the start: the bar coordinates q, the monitored bar
ends (``system.monitor_nodes``: B_12, B_14 for 1-4; A_21, B_11, B_21 for 2-3), the membrane
deflections w_k at the points of eqs. 5.36/5.38, and the largest tendon transverse deflection
(eq. 5.37; FE models only, the COM has no tendon dynamics). The differences are quantified
per signal against the SBC model (the dissertation's reference) as

    e = rms(s_model - s_SBC) / rms(s_SBC)

over the whole record and over its first :data:`EARLY` seconds (before the small frequency
differences of the models have accumulated into phase differences), beside the peak-to-peak
amplitudes and the fitted frequency of the perturbed bar's theta
(:func:`tmfem.models.mtc.dynamics.fit_frequency`).
"""
from __future__ import annotations

import csv
import logging
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from tmfem.errors import ConvergenceError, InputError
from tmfem.io.atomic import atomic_open
from tmfem.models.mtc.dynamics import fit_frequency
from tmfem.reference.model_compare import MODELS, com_model, compared_system, fe_models

log = logging.getLogger(__name__)

#: length [s] of the early window of the rms differences (module docstring)
EARLY = 2.0


def _signals(system, res, name: str) -> dict:
    """Displacement-from-start histories of one model's run, by signal name."""
    if name == "COM":
        q = res.z[:, :len(system.q_names)]
    else:
        q = res.q
    out = {n: q[:, i] - q[0, i] for i, n in enumerate(system.q_names)}
    for lab, X in res.nodes.items():
        for c, comp in enumerate("xyz"):
            out[f"{lab}_{comp}"] = X[:, c] - X[0, c]
    for k in range(res.w.shape[1]):
        out[f"w_{k + 1}"] = res.w[:, k] - res.w[0, k]
    if name != "COM":
        out["tendon_deflection"] = res.tendon_deflection
    return out


def three_model_vibration(system, *, t_end: float, dt: float = 0.01, perturb=None,
                          mesh_n: int = 10, tendon_elements: int = 3, backend="scipy",
                          progress=None) -> dict:
    """Free vibration of ``system`` in the SBC, MTC and COM models (module docstring).

    Parameters
    ----------
    system : System or preset name
    t_end, dt : float
        Duration and step [s] (6.5: dt = 0.01 s).
    perturb : dict, optional
        Initial perturbation by coordinate name (default the file's ``[report] perturbation``:
        6.5.1's theta_12' = 0.01 rad/s for 1-4, 6.5.2's theta_11' for 2-3; theta_11' = 0.01 rad/s
        otherwise).
    mesh_n, tendon_elements : int
        Membrane mesh (6.5: 10; the "20 x 20 mesh for the square membrane" of 6.5.1 is
        4 x 10 x 10) and truss elements per tendon
        of the FE models; the COM's membrane basis is computed on the same mesh.
    progress : callable, optional
        ``progress(model_name)`` before each model's run; it may return a
        ``progress(step, n_steps)`` callback for that run.

    Returns
    -------
    dict with ``t`` (nt,), ``signals`` {model: {signal: (nt,)}}, ``results`` {model: result},
    ``comparison`` (JSON-able: differences, amplitudes, frequencies, wall times).
    """
    from tmfem.simulation.vibration import free_vibration, model_free_vibration
    given = compared_system(system)
    name = given.name
    pert = dict(given.problem.report.perturbation if perturb is None else perturb)
    fe = fe_models(given, mesh_n=mesh_n, tendon_elements=tendon_elements, backend=backend)
    system = fe["MTC"].system
    results, static = {}, {}
    for key in ("SBC", "MTC"):
        steps = progress(key) if progress else None
        with named_model(key, name, mesh_n):
            st = fe[key].equilibrium()
            static[key] = st.time
            results[key] = model_free_vibration(fe[key], at=st, t_end=t_end, dt=dt,
                                                perturb=pert, progress=steps)
    steps = progress("COM") if progress else None
    with named_model("COM", name, mesh_n):
        com = com_model(given, mesh_n=mesh_n)
        results["COM"] = free_vibration(com, t_end=t_end, dt=dt, perturb=pert, jacobian="reuse",
                                        progress=steps)
    t = results["SBC"].t
    for k, r in results.items():
        if r.t.shape != t.shape:
            raise InputError(f"three-model vibration: {k} stopped at t = {r.t[-1]:.4g} s of {t[-1]:.4g} s")
    signals = {k: _signals(system, results[k], k) for k in MODELS}
    comparison = compare_histories(name, t, signals, system=system, perturb=pert, results=results,
                                   static=static, mesh_n=mesh_n, tendon_elements=tendon_elements)
    comparison["backend"] = {k: m.backend.name for k, m in fe.items()}
    return {"t": t, "signals": signals, "results": results, "comparison": comparison}


@contextmanager
def named_model(model: str, name: str, mesh_n: int):
    """Re-raise a :class:`~tmfem.errors.ConvergenceError` of one model's run with the model,
    system and mesh in front (which of the three failed)."""
    try:
        yield
    except ConvergenceError as exc:
        raise ConvergenceError(f"{model} model of {name} (FE mesh {mesh_n}): {exc}") from exc


def compare_histories(name, t, signals, *, system, perturb, results, static, mesh_n,
                      tendon_elements) -> dict:
    """The differences of :func:`three_model_vibration` (JSON-able; module docstring)."""
    ref = signals["SBC"]
    early = t <= min(EARLY, t[-1])
    diff, diff_early, ptp = {}, {}, {}
    for m in MODELS:
        ptp[m] = {s: float(np.ptp(v)) for s, v in signals[m].items()}
        if m == "SBC":
            continue
        diff[m], diff_early[m] = {}, {}
        for s, v in signals[m].items():
            for out, sel in ((diff[m], slice(None)), (diff_early[m], early)):
                scale = np.sqrt(np.mean(ref[s][sel] ** 2))
                if scale > 0:
                    out[s] = float(np.sqrt(np.mean((v[sel] - ref[s][sel]) ** 2)) / scale)
    perturbed = [k[:-4] if k.endswith("_dot") else k for k in perturb]
    freq = {}
    for q in perturbed:
        if q.startswith("theta") and t[-1] > 1.0:
            freq[q] = {m: fit_frequency(t, signals[m][q], f_min=0.05, f_max=3.0) for m in MODELS}
    return {"system": name, "perturbation": perturb, "t_end": float(t[-1]),
            "dt": float(t[1] - t[0]), "mesh_n": mesh_n, "tendon_elements": tendon_elements,
            "rms_difference_vs_SBC": diff, "rms_difference_vs_SBC_early": diff_early,
            "early_window_s": float(t[early][-1]), "peak_to_peak": ptp, "fitted_frequency_hz": freq,
            "max_tendon_deflection_m": {m: float(results[m].stats["max_tendon_deflection"])
                                        for m in ("SBC", "MTC")},
            "wall_time_s": {m: float(results[m].wall_time) for m in MODELS},
            "static_time_s": static,
            "energy_drift_over_initial_kinetic": {
                m: float(np.max(np.abs(results[m].energy - results[m].energy[0])) / results[m].kinetic[0])
                for m in ("SBC", "MTC")}}


def key_signals(system) -> list:
    """The signals a summary lists: the theta of every bar, the monitored bar ends' z, w_k."""
    th = [n for n in system.q_names if n.startswith("theta")]
    return th + [f"{lab}_z" for lab in system.monitor_nodes] + \
        [f"w_{k + 1}" for k in range(system.monitor_points.shape[1])]


def format_vibration_compare(c: dict, system) -> str:
    """Text of :func:`compare_histories`."""
    lines = [f"{c['system']}: free vibration in the three models, "
             + ", ".join(f"{k}={v:g}" for k, v in c["perturbation"].items())
             + f", {c['t_end']:g} s at dt = {c['dt']:g} s, FE mesh {c['mesh_n']}, "
             f"{c['tendon_elements']} elements/tendon"
             + "".join(f", {k} backend {v}" for k, v in c.get("backend", {}).items()),
             f"{'signal':>22} {'SBC p-p':>11} {'MTC p-p':>11} {'COM p-p':>11} "
             f"{'rms diff vs SBC: MTC':>21} {'COM':>8} {'first ' + format(c['early_window_s'], 'g') + ' s: MTC':>17} "
             f"{'COM':>8}"]
    for s in key_signals(system) + ["tendon_deflection"]:
        pp = c["peak_to_peak"]
        row = f"{s:>22} " + " ".join(f"{pp[m][s]:11.4e}" if s in pp[m] else f"{'-':>11}" for m in MODELS)
        for key, w in (("rms_difference_vs_SBC", (21, 8)), ("rms_difference_vs_SBC_early", (17, 8))):
            row += " " + " ".join(f"{100 * c[key][m][s]:{wd - 1}.2f}%" if s in c[key][m] else f"{'-':>{wd}}"
                                  for m, wd in zip(("MTC", "COM"), w))
        lines.append(row)
    for q, f in c["fitted_frequency_hz"].items():
        lines.append(f"fitted frequency of {q} [Hz]: " + ", ".join(f"{m} {v:.4f}" for m, v in f.items()))
    lines.append("largest tendon transverse deflection [mm]: " + ", ".join(
        f"{m} {1e3 * v:.3g}" for m, v in c["max_tendon_deflection_m"].items()))
    lines.append("energy drift / initial kinetic energy: " + ", ".join(
        f"{m} {v:.2e}" for m, v in c["energy_drift_over_initial_kinetic"].items()))
    lines.append("wall time of the runs [s]: " + ", ".join(
        f"{m} {v:.1f}" for m, v in c["wall_time_s"].items()))
    return "\n".join(lines)


def write_vibration_csv(path, t, signals) -> Path:
    """One row per time: t and every model's signals with their units
    (:func:`tmfem.io.run.column_header`: ``t [s]``, ``SBC_theta_12 [rad]``, ``MTC_w_1 [m]``, ...)."""
    from tmfem.io.run import column_header
    cols = [(m, s) for m in MODELS for s in signals[m]]
    with atomic_open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([column_header("t")] + [f"{m}_{column_header(s)}" for m, s in cols])
        data = np.column_stack([t] + [signals[m][s] for m, s in cols])
        w.writerows(data.tolist())
    return Path(path)
