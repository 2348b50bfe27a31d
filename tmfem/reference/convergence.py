"""Mesh and tendon-subdivision convergence of the FE models (dissertation 6.3, Figs. 6.11-6.14).

6.3 studies the shell-beam-cable (SBC) model; the membrane-truss-cable (MTC) model runs the
same study. Each row solves the statics and the modes of one (mesh n, tendon elements k): the
MTC model from the design, the SBC model from the MTC equilibrium on the same mesh (its MTC
predictor, :meth:`SBCModel.equilibrium`), both with the rest lengths held over the study
(:func:`resolve_rest_lengths`).
"""
from __future__ import annotations

import logging
import time

import numpy as np

from tmfem.errors import InputError
from tmfem.models.fe.rest_lengths import design_mesh_of, design_rest_lengths_at
from tmfem.models.mtc.model import MTCModel
from tmfem.models.mtc.post import static_summary

log = logging.getLogger(__name__)

ROW_KEYS = ("mesh_n", "tendon_elements", "attachment", "elements", "h", "dofs", "iterations",
            "static_s", "modal_s", "Delta_mm", "tendon_stress_max_MPa", "bar_load_max_N",
            "sigma_p1_max_MPa", "von_mises_max_MPa", "sigma_p1_elem_max_MPa",
            "von_mises_elem_max_MPa", "membrane_law", "wrinkled_fraction", "slack_fraction",
            "model", "backend")


#: Rest-length rule of a study of a system without rest lengths: the ch. 3 design of 6.2
#: (point corners, mesh n = 10), held fixed on every mesh.
DEFAULT_RULE = "design@10"


def resolve_rest_lengths(system, *, rest_lengths):
    """(rest lengths, rule) of a study: an array held fixed on every mesh, or a rule
    recomputed per mesh (``"design"``, ``"mtc"``), and the name of the rule.

    ``None`` is ``"system"`` for a system with rest lengths, else :data:`DEFAULT_RULE`;
    ``"system"``, ``"design@n"`` (:func:`tmfem.models.mtc.design.design_rest_lengths_at`)
    and values are evaluated once, so every mesh analyses the same physical structure.
    ``"design"`` designs on each analysis mesh (as ``tmfem modal``/``static`` do by default),
    so the structure changes with the mesh.
    """
    if rest_lengths is None:
        rest_lengths = "system" if system.rest_lengths is not None else DEFAULT_RULE
    if isinstance(rest_lengths, str) and rest_lengths in ("mtc", "design"):
        return rest_lengths, rest_lengths
    n = design_mesh_of(rest_lengths)
    if n is not None:
        return design_rest_lengths_at(system, n), rest_lengths
    if isinstance(rest_lengths, str):
        if rest_lengths != "system":
            raise InputError(f"rest_lengths: expected an array or one of 'system', 'design', "
                             f"'design@n' (n >= 1), 'mtc', found {rest_lengths!r}")
        if system.rest_lengths is None:
            raise InputError(f"rest_lengths='system': expected rest lengths in system "
                             f"{system.name!r}, found none (use 'design' or 'mtc')")
        return system.rest_lengths.copy(), "system"
    from tmfem.system.system import rest_length_array
    return rest_length_array(rest_lengths, len(system.tendons)), "given"


def _mtc_row(system, n, k, *, attachment, patch, rest, modes, backend, membrane_law):
    """(model, static iterations, frequencies, summary values) of one MTC run."""
    m = MTCModel(system, mesh_n=int(n), tendon_elements=int(k), attachment=attachment,
                 patch=patch, rest_lengths=rest, backend=backend, membrane_law=membrane_law)
    res = m.equilibrium(start="design")
    t1 = time.perf_counter()
    md = m.modes(k=modes, at=res)
    st = static_summary(m, res.x)
    return m, res.iterations, md.freq_hz, t1, {
        "Delta_mm": 1e3 * float(np.mean(st["Delta"])),
        "tendon_stress_max_MPa": st["tendon_stress_max"] / 1e6,
        "bar_load_max_N": st["bar_load_max"],
        "sigma_p1_max_MPa": st["membrane_max_sigma_p1"] / 1e6,
        "von_mises_max_MPa": st["membrane_max_von_mises"] / 1e6,
        "sigma_p1_elem_max_MPa": st["membrane_max_sigma_p1_element_mean"] / 1e6,
        "von_mises_elem_max_MPa": st["membrane_max_von_mises_element_mean"] / 1e6,
        "membrane_law": m.membrane_law,
        "wrinkled_fraction": st["membrane_state_fractions"]["wrinkled"],
        "slack_fraction": st["membrane_state_fractions"]["slack"]}


def _sbc_row(system, n, k, *, attachment, patch, rest, modes, backend, membrane_law):
    """(model, static iterations, frequencies, summary values) of one SBC run (its membrane
    is the MITC4 shell; "element mean" stresses are the element centres, mid surface)."""
    from tmfem.models.sbc.model import SBCModel
    from tmfem.models.sbc.post import static_summary as sbc_summary
    m = SBCModel(system, mesh_n=int(n), tendon_elements=int(k), attachment=attachment,
                 patch=patch, rest_lengths=rest, backend=backend, membrane_law=membrane_law)
    res = m.equilibrium()
    t1 = time.perf_counter()
    md = m.modes(k=modes, at=res)
    st = sbc_summary(m, res)
    return m, res.iterations, md.freq_hz, t1, {
        "Delta_mm": 1e3 * st["Delta_mean"], "tendon_stress_max_MPa": st["tendon_stress_max"] / 1e6,
        "bar_load_max_N": st["bar_load_max"],
        "sigma_p1_max_MPa": st["membrane_max_sigma_p1"] / 1e6,
        "von_mises_max_MPa": st["membrane_max_von_mises"] / 1e6,
        "sigma_p1_elem_max_MPa": st["membrane_max_sigma_p1_element_centre"] / 1e6,
        "von_mises_elem_max_MPa": st["membrane_max_von_mises_element_centre"] / 1e6,
        "membrane_law": membrane_law, "wrinkled_fraction": st["membrane_state_fractions"]["wrinkled"],
        "slack_fraction": st["membrane_state_fractions"]["slack"], "dofs": m.ndof}


ROWS = {"mtc": _mtc_row, "sbc": _sbc_row}


def convergence_rows(system, *, meshes, tendon_elements, attachment: str = "point",
                     rest_lengths=None, modes: int = 12, patch: float | None = None,
                     progress: bool = True, backend="scipy", membrane_law: str = "svk",
                     model: str = "mtc"):
    """Yield one result row (dict) per (mesh n, tendon elements k) pair, as it is computed.

    Each row: mesh size, DOFs, static iterations and time, landing (Delta), peak stresses
    (Gauss-point maxima and element-mean maxima; SBC: element centres), and the frequencies
    ``f1 .. f<modes>`` [Hz]. ``h`` is the element size sqrt(area / elements). ``model``:
    ``"mtc"`` or ``"sbc"`` (module docstring). ``membrane_law`` selects the membrane law (of
    the shell's lamina in the SBC model); the rows carry the fractions of wrinkled and slack
    Gauss points (criterion of :mod:`tmfem.fem.tension_field`; SBC: the sign of the
    mid-surface principal stresses).
    """
    if model not in ROWS:
        raise InputError(f"convergence: expected model one of {sorted(ROWS)}, found {model!r}")
    rest, _ = resolve_rest_lengths(system, rest_lengths=rest_lengths)
    for n in meshes:
        for k in tendon_elements:
            t0 = time.perf_counter()
            m, its, freq, t1, vals = ROWS[model](system, n, k, attachment=attachment, patch=patch,
                                                 rest=rest, modes=modes, backend=backend,
                                                 membrane_law=membrane_law)
            t2 = time.perf_counter()
            ne = m.topology.mesh.t.shape[1]
            row = {"mesh_n": int(n), "tendon_elements": int(k), "attachment": attachment,
                   "elements": ne, "h": float(np.sqrt(m.membrane_area() / ne)),
                   "dofs": vals.pop("dofs", m.ndof), "iterations": its, "static_s": t1 - t0,
                   "modal_s": t2 - t1, **vals, "model": model, "backend": m.backend.name}
            for i, f in enumerate(freq):
                row[f"f{i + 1}"] = float(f)
            if progress:
                log.info("converge %s: n=%3d k=%d %s: %d dofs, f1 = %.5f Hz, max sigma_p1 = %.3f MPa "
                         "(%.1f s)", model, n, k, attachment, row["dofs"], freq[0],
                         row["sigma_p1_max_MPa"], t2 - t0)
            yield row


def fit_convergence(rows, *, by: str = "h", modes: int = 12) -> dict:
    """Rates from ``np.polyfit`` on log h.

    Frequencies: |f(h) - f(h_min)| ~ C h^p over all but the finest row (p > 0 converges; the
    finest mesh stands in for the limit, so p reads high when it is not converged itself),
    and the successive changes per halving of h ~ C h^q (``successive_change_rates``: q ~ p
    for a converging sequence, q <= 0 when every refinement moves the frequency as much as the
    last; only from four meshes on, where three changes give the slope more than two points;
    ``frequency_change_per_halving_last`` the finest pair's).
    Peak stresses: sigma_max ~ C h^p over all rows (p < 0: grows without bound as h -> 0).
    """
    rows = sorted(rows, key=lambda r: -r[by])
    h = np.array([r[by] for r in rows], dtype=float)
    out = {"h": h.tolist()}
    if len(rows) < 3:
        return out
    F = np.array([[r[f"f{i + 1}"] for i in range(modes)] for r in rows])
    ref = F[-1]
    rates = []
    for c in range(modes):
        err = np.abs(F[:-1, c] - ref[c]) / ref[c]
        ok = err > 1e-12
        rates.append(float(np.polyfit(np.log(h[:-1][ok]), np.log(err[ok]), 1)[0])
                     if ok.sum() >= 2 else float("nan"))
    out["frequency_rates"] = rates
    out["frequency_change_last"] = (np.abs(F[-1] - F[-2]) / F[-1]).tolist()
    # successive changes per halving of h, |f_i+1 - f_i| / f / log2(h_i / h_i+1) ~ h^q: they
    # fall like h^p for a sequence converging at rate p, stay level (q ~ 0) for a drift like
    # log h -- a test that does not take the finest mesh for the limit
    per = np.abs(np.diff(F, axis=0)) / F[1:] * np.log(2) / np.log(h[:-1] / h[1:])[:, None]
    hm = np.sqrt(h[:-1] * h[1:])
    out["frequency_change_per_halving_last"] = per[-1].tolist()
    if len(rows) >= 4:
        out["successive_change_rates"] = [
            float(np.polyfit(np.log(hm), np.log(np.maximum(per[:, c], 1e-16)), 1)[0]) for c in range(modes)]
    for key in ("sigma_p1_max_MPa", "von_mises_max_MPa", "sigma_p1_elem_max_MPa",
                "von_mises_elem_max_MPa", "Delta_mm", "tendon_stress_max_MPa"):
        v = np.array([r[key] for r in rows])
        out[f"{key}_exponent"] = float(np.polyfit(np.log(h), np.log(np.abs(v)), 1)[0])
    return out
