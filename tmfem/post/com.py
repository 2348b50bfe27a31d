"""Reports of the control-oriented model: its natural frequencies about the equilibrium (6.4,
eq. 5.33) with the sizes, rest lengths and prestress of the model, and their text."""
from __future__ import annotations

import numpy as np

from tmfem.errors import shorten

from tmfem.models.com.model import default_membrane_modes
from tmfem.models.com.mode_count import MembraneModeChoice

#: files ``tmfem modal`` can write for this model (none: it has no mesh of its own)
MODE_FILES = ()


def printed_prestress_scale(model) -> float | None:
    """Prestress factor implied by the printed maximum tendon stress (Tables 6.3, 6.5):
    s = sigma_printed A / max(T_design) for the model's own design tendon forces."""
    p = model.system.printed.get("tendon_max_stress")
    if p is None or model.design is None:
        return None
    A = np.array([model.system.tendon_section(t).area for t in model.system.tendons])
    return float(p * A[np.argmax(model.design.tendon_forces / A)] /
                 np.max(model.design.tendon_forces) / model.prestress_scale)


def printed_bar_load_prestress_scale(model, *, mesh_n: int = 10) -> float | None:
    """Prestress factor implied by the printed stage-1 bar load (Table 6.3 ``bar_load``,
    Table 6.5 ``bar_load_stage1``): s = F_printed / F_design, the one-number calibration of
    the MTC comparison (:func:`tmfem.reference.designs.calibrate_on_bar_load`) applied to the
    COM's design. F_design is the largest stage-1 bar compression of
    :func:`tmfem.equilibrium.design.design_equilibrium`, whose tendon forces the COM's design
    reproduces (tests/models/com/test_com_2_3.py); all design loads scale with the prestress (3.2)."""
    pr = model.system.printed
    p = pr.get("bar_load_stage1", pr.get("bar_load"))
    if p is None or model.design is None:
        return None
    from tmfem.equilibrium.design import design_equilibrium
    d = design_equilibrium(model.system, mesh_n=mesh_n)
    return float(p / np.max(d.bar_loads[0]) / model.prestress_scale)


def modal_summary(model, result, modes) -> dict:
    """Natural frequencies of the COM ``model`` about the equilibrium ``result`` (JSON-able
    dict): the first ``len(modes.freq_hz)`` and the highest of all, the sizes, the rest lengths
    (and the design tendon forces, or the equilibrium's for given rest lengths) and the
    prestress factors the printed tendon stress and bar load imply."""
    system = model.system
    f = model.linearization(at=result).frequencies_hz()
    n = min(len(modes.freq_hz), len(f))
    names = system.tendon_names()
    mesh_n = model.mesh_n
    out = {"system": system.name, "model": "com", "membrane_modes": model.K, "mesh_n": mesh_n,
           "prestress_scale": model.prestress_scale, "membrane_law": model.membrane_law,
           "sizes": model.summary(), "freq_hz": f[:n].tolist(), "highest_hz": float(f[-1]),
           "rest_lengths_source": "design" if model.design is not None else "system",
           "rest_lengths": dict(zip(names, model.u0.tolist())),
           "default_membrane_modes": _default_k(model),
           "membrane_mode_choice": model.membrane_mode_choice.to_dict()}
    if model.design is not None:
        out["design_tendon_forces"] = dict(zip(names, model.design.tendon_forces.tolist()))
        out["design_rest_lengths"] = dict(zip(names, model.design.rest_lengths.tolist()))
    else:
        z_e = result.state
        out["equilibrium_tendon_forces"] = dict(zip(names, model.tendon_forces(z_e).tolist()))
        out["equilibrium_shift_max"] = float(np.max(np.abs(z_e - model.z0)))
    s_pr = printed_prestress_scale(model)
    if s_pr is not None:
        out["printed_stress_prestress_scale"] = s_pr
    s_bar = printed_bar_load_prestress_scale(model, mesh_n=mesh_n)
    if s_bar is not None:
        out["printed_bar_load_prestress_scale"] = s_bar
    return out


def _default_k(model) -> int | None:
    """The system's default K: the model's own when it took the default; the file's when K was
    given; None for a given K on a file without one (the automatic choice is not run for it)."""
    c = model.membrane_mode_choice
    if c.source != "given":
        return c.K
    K = model.system.model_defaults.get("com", {}).get("membrane_modes")
    return None if K is None else default_membrane_modes(model.system)


def format_modal(r: dict) -> str:
    """Text table of a :func:`modal_summary` result: the COM column beside the printed one."""
    lines = [f"COM of {r['system']}: {r['sizes']['n_z']} coordinates (nq = {r['sizes']['n_q']}, "
             f"K = {r['membrane_modes']}), prestress x{r['prestress_scale']:g}, rest lengths "
             f"from the {r.get('rest_lengths_source', 'design')}"]
    if "membrane_mode_choice" in r:
        lines.append(MembraneModeChoice(**r["membrane_mode_choice"]).text)
    forces = r.get("design_tendon_forces") or r.get("equilibrium_tendon_forces") or {}
    if forces:
        lines.append("tendon forces [N]: " + shorten((f"{k}={v:.4g}" for k, v in forces.items()), 6))
    if "printed_stress_prestress_scale" in r:
        lines.append(f"prestress implied by the printed tendon stress: x{r['printed_stress_prestress_scale']:.4f}"
                     " (--prestress-scale in the Python API, docs/guides/com.md)")
    if "printed_bar_load_prestress_scale" in r:
        lines.append(f"prestress implied by the printed stage-1 bar load: x{r['printed_bar_load_prestress_scale']:.4f}")
    ref = r.get("dissertation", {}).get("COM", [])
    lines.append(f"{'mode':>4} {'COM [Hz]':>10}" + (f" {'printed':>10} {'rel.diff':>9}" if ref else ""))
    for i, f in enumerate(r["freq_hz"]):
        if i < len(ref):
            lines.append(f"{i + 1:>4} {f:>10.4f} {ref[i]:>10.4f} {f / ref[i] - 1:>+9.2%}")
        else:
            lines.append(f"{i + 1:>4} {f:>10.4f}")
    return "\n".join(lines)
