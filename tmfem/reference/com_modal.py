"""Natural frequencies of the control-oriented model (6.4, eq. 5.33) and studies.

The COM is linearised about its equilibrium (eq. 5.33); the undamped natural frequencies
are sqrt(eig(M_hat^-1 K)) / 2 pi. The dissertation's COM columns (Tables 6.6, 6.7) and the
highest COM frequencies quoted in 6.5 (2.4322 Hz for 1-4 with 13 coordinates, 4.4607 Hz
for 2-3) are printed beside ours.
"""
from __future__ import annotations

import logging

import numpy as np

from tmfem.errors import InputError, shorten
from tmfem.models.com.linearize import linearize
from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes
from tmfem.reference.tables import FREQUENCIES, HIGHEST_COM_FREQUENCY

log = logging.getLogger(__name__)

def dissertation_com_frequencies(name: str):
    """COM column of Table 6.6 (1-4) or 6.7 (2-3), or None."""
    ref = FREQUENCIES.get(name)
    return None if ref is None else (ref["source"], list(ref["COM"]))


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


def com_frequencies(system, *, membrane_modes: int, prestress_scale: float = 1.0,
                    mesh_n: int = 10, rest_lengths=None, membrane_law: str = "svk"):
    """(frequencies in Hz, model) of the COM linearised about its equilibrium (eq. 5.33)."""
    if rest_lengths is None:       # the system's own (e.g. printed) if it has them
        rest_lengths = "design" if system.rest_lengths is None else "system"
    m = ControlOrientedModel(system, membrane_modes=membrane_modes, mesh_n=mesh_n,
                             prestress_scale=prestress_scale, rest_lengths=rest_lengths,
                             membrane_law=membrane_law)
    lin = linearize(m)
    return lin.frequencies_hz(), m


def modal_summary(system, *, modes: int = 12, membrane_modes: int | None = None,
                  prestress_scale: float = 1.0, mesh_n: int = 10, membrane_law: str = "svk") -> dict:
    """Natural frequencies of the COM beside Tables 6.6/6.7 (JSON-able dict).

    Parameters
    ----------
    system : System
    modes : int
        Number of frequencies reported (at most the number of coordinates nq + K).
    membrane_modes : int, optional
        K; default the dissertation's (5 for 1-4, 4 for 2-3).
    prestress_scale : float
        Factor on the designed membrane prestress (1 = designed, see ControlOrientedModel).
    membrane_law : {"svk", "tension-field"}
        Membrane basis about the linear or the tension-field prestress (docs/wrinkling.md).
    """
    K = default_membrane_modes(system) if membrane_modes is None else int(membrane_modes)
    if not (isinstance(modes, int) and modes >= 1):
        raise InputError(f"--modes: expected an integer >= 1, found {modes!r}")
    log.info("%s COM, K = %d membrane modes", system.name, K)
    f, m = com_frequencies(system, membrane_modes=K, prestress_scale=prestress_scale,
                           membrane_law=membrane_law,
                           mesh_n=mesh_n)
    n = min(modes, len(f))
    names = system.tendon_names()
    out = {"system": system.name, "model": "com", "membrane_modes": K, "mesh_n": mesh_n,
           "prestress_scale": prestress_scale, "membrane_law": membrane_law, "sizes": m.summary(),
           "freq_hz": f[:n].tolist(), "highest_hz": float(f[-1]),
           "rest_lengths_source": "design" if m.design is not None else "system",
           "rest_lengths": dict(zip(names, m.u0.tolist()))}
    if m.design is not None:
        out["design_tendon_forces"] = dict(zip(names, m.design.tendon_forces.tolist()))
        out["design_rest_lengths"] = dict(zip(names, m.design.rest_lengths.tolist()))
    else:
        z_e = m.equilibrium()
        out["equilibrium_tendon_forces"] = dict(zip(names, m.tendon_forces(z_e).tolist()))
        out["equilibrium_shift_max"] = float(np.max(np.abs(z_e - m.z0)))
    s_pr = printed_prestress_scale(m)
    if s_pr is not None:
        out["printed_stress_prestress_scale"] = s_pr
    s_bar = printed_bar_load_prestress_scale(m, mesh_n=mesh_n)
    if s_bar is not None:
        out["printed_bar_load_prestress_scale"] = s_bar
    ref = dissertation_com_frequencies(system.name)
    if ref is not None and K == default_membrane_modes(system):
        src, com = ref
        k = min(n, len(com))
        out["dissertation"] = {"source": src, "COM": com[:k],
                               "highest_hz": HIGHEST_COM_FREQUENCY.get(system.name)}
        out["relative_difference"] = (f[:k] / np.array(com[:k]) - 1).tolist()
    return out


def format_summary(r: dict) -> str:
    """Text table of a :func:`modal_summary` result: ours beside the printed COM column."""
    lines = [f"COM of {r['system']}: {r['sizes']['n_z']} coordinates (nq = {r['sizes']['n_q']}, "
             f"K = {r['membrane_modes']}), prestress x{r['prestress_scale']:g}, rest lengths "
             f"from the {r.get('rest_lengths_source', 'design')}"]
    forces = r.get("design_tendon_forces") or r.get("equilibrium_tendon_forces") or {}
    if forces:
        lines.append("tendon forces [N]: " + shorten((f"{k}={v:.4g}" for k, v in forces.items()), 6))
    if "printed_stress_prestress_scale" in r:
        lines.append(f"prestress implied by the printed tendon stress: x{r['printed_stress_prestress_scale']:.4f}"
                     " (--prestress-scale in the Python API, docs/com.md)")
    if "printed_bar_load_prestress_scale" in r:
        lines.append(f"prestress implied by the printed stage-1 bar load: x{r['printed_bar_load_prestress_scale']:.4f}")
    ref = r.get("dissertation", {}).get("COM", [])
    lines.append(f"{'mode':>4} {'ours [Hz]':>10} {'printed':>10} {'rel.diff':>9}")
    for i, f in enumerate(r["freq_hz"]):
        if i < len(ref):
            lines.append(f"{i + 1:>4} {f:>10.4f} {ref[i]:>10.4f} {f / ref[i] - 1:>+9.2%}")
        else:
            lines.append(f"{i + 1:>4} {f:>10.4f}")
    return "\n".join(lines)


def frequency_study(system, *, K_values, prestress_scales=(1.0,), modes: int = 12,
                    mesh_n: int = 10) -> list[dict]:
    """Frequencies vs number of membrane modes K and prestress factor (rows of dicts)."""
    rows = []
    for s in prestress_scales:
        for K in K_values:
            log.info("frequency study %s: prestress x%g, K = %d", system.name, s, K)
            f, m = com_frequencies(system, membrane_modes=K, prestress_scale=s, mesh_n=mesh_n)
            rows.append({"prestress_scale": s, "K": K, "freq_hz": f[:modes].tolist(),
                         "highest_hz": float(f[-1])})
    return rows
