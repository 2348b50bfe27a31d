"""The three models side by side (dissertation 6.4, Tables 6.6/6.7): the natural frequencies of
the shell-beam-cable (SBC), membrane-truss-cable (MTC) and control-oriented (COM) models of one
system, beside the three printed columns when the system's file carries them
(``[printed.frequencies_hz]``), and the model-to-model differences (relative to the SBC model;
6.4 states "less than 3 %" for 1-4, 6.4.1, and "less than 1 %" for 2-3, 6.4.2: the files'
``stated_model_difference``).

Each model is taken at the prestress the file names (docs/validation/errata.md for the presets):

* the FE models at the file's ``[report] implied_rest_lengths`` when it gives them (1-4:
  r_1^S = 1.5025 m, which Tables 6.3 and 6.6 imply; the printed 1.529 m of Table 6.2 leaves the
  system nearly unstressed), else at the designed rest lengths;
* the COM at the prestress of the printed tendon stress when the file says
  ``[report] com_prestress = "printed-tendon-stress"`` (1-4: 1.2903 x its designed one,
  :func:`tmfem.reference.com_modal.printed_prestress_scale`), else at the designed one.

Meshes as in 6.4: N x 10 x 10 membrane elements, one beam per bar (SBC), 3 truss elements per
tendon, K of ``[models.com]`` membrane modes in the COM (5 for 1-4, 4 for 2-3).

Modes are compared by shape, not by order: each SBC mode is paired with the MTC and COM modes
of the same shape (:mod:`tmfem.reference.mode_pairing`: MAC on the bar-end and membrane
translations the three models share, :mod:`tmfem.reference.shared_shapes`), and the model
differences of the pairs are given beside the differences by order. An SBC mode without a
counterpart (for example the bending of slender bars, which the MTC and COM models, with
straight or rigid bars, do not have) is named with the bars' share of its strain energy.
The printed tables compare by order; at their mesh the presets' pairing is the identity (the
test suite checks it), so both agree there.

The models compared are those that apply to the system (:func:`applicable_models`): all three
for an M-N system; the SBC and COM models for a 1-N(D) system, whose tendons are attached at
H_1j along the bars, where the MTC model (truss bars, nodes only at the bar ends) has no node,
so the MTC model is left out and the result says why (``left_out``).
"""
from __future__ import annotations

import csv
import logging
import time
from pathlib import Path

import numpy as np

from tmfem.errors import InputError
from tmfem.io.atomic import atomic_open
from tmfem.reference.mode_pairing import CLUSTER_TOLERANCE, MAC_THRESHOLD, pair_modes
from tmfem.reference.shared_shapes import beam_energy_share, com_shared_shapes, fe_shared_shapes
from tmfem.reference.tables import printed_frequencies

log = logging.getLogger(__name__)

MODELS = ("SBC", "MTC", "COM")


def loaded_system(system):
    """``system`` (a System, or a preset name: the preset loader) for the comparison."""
    if isinstance(system, str):
        from tmfem.system import load_preset
        system = load_preset(system)
    return system


def left_out_models(system) -> dict:
    """The models that cannot represent ``system``, each with the reason (module docstring)."""
    if loaded_system(system).deployable:
        return {"MTC": "the MTC model cannot represent a 1-N(D) system (tendons attached at H_1j "
                       "along the bars, where its truss bars have no node)"}
    return {}


def applicable_models(system) -> tuple:
    """The models of :data:`MODELS` that apply to ``system``, the SBC reference first."""
    out = left_out_models(system)
    return tuple(m for m in MODELS if m not in out)


def compared_system(system):
    """``system`` for a comparison that needs all three models (``--vibrate``): a system that
    one of them cannot represent is refused with the reason."""
    system = loaded_system(system)
    for m, why in left_out_models(system).items():
        raise InputError(f"compare --vibrate {system.name}: {why}; expected an M-N system (the "
                         f"frequencies, `tmfem compare` without --vibrate, compare the models that apply)")
    return system


def fe_system(system):
    """The system the FE models analyse: the file's ``[report] implied_rest_lengths`` when it
    gives them, else the system itself (module docstring)."""
    system = loaded_system(system)
    rest = system.problem.report.implied_rest_lengths
    return system.with_rest_lengths(rest) if rest else system


def com_model(system, *, mesh_n: int = 10):
    """The control-oriented model of the comparison (module docstring; K the file's)."""
    from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes
    from tmfem.post.com import printed_prestress_scale
    s = loaded_system(system)
    K = default_membrane_modes(s)
    m = ControlOrientedModel(s, membrane_modes=K, mesh_n=mesh_n)
    if s.problem.report.com_prestress == "printed-tendon-stress":
        m = ControlOrientedModel(s, membrane_modes=K, mesh_n=mesh_n,
                                 prestress_scale=printed_prestress_scale(m))
    return m


def fe_models(system, *, mesh_n: int = 10, tendon_elements: int = 3, backend="scipy") -> dict:
    """The FE models of the comparison that apply (:func:`applicable_models`: the SBC model,
    and the MTC model for an M-N system) on the same mesh."""
    from tmfem.models.mtc.model import MTCModel
    from tmfem.models.sbc.model import SBCModel
    s = fe_system(system)
    kinds = {"SBC": SBCModel, "MTC": MTCModel}
    return {k: kinds[k](s, mesh_n=mesh_n, tendon_elements=tendon_elements, backend=backend)
            for k in applicable_models(s) if k in kinds}


#: MTC and COM modes computed beyond ``modes`` for the pairing only: the partner of an SBC mode
#: near the top of the band, or the other half of a degenerate pair that the last mode cuts,
#: is then among them (the tables show the ``modes`` lowest)
PAIRING_EXTRA = 4


def model_frequencies(system, *, modes: int = 12, mesh_n: int = 10, tendon_elements: int = 3,
                      backend="scipy", progress=None) -> dict:
    """Natural frequencies [Hz] of the models of ``system`` that apply (module docstring):
    ``freq_hz`` by model (the ``modes`` lowest), the modes' ``shared_shapes`` by model (columns,
    :mod:`tmfem.reference.shared_shapes`; the MTC and COM models with :data:`PAIRING_EXTRA`
    more modes, whose frequencies are ``pairing_hz``), the bars' share of the SBC modes'
    strain energy (``sbc_beam_energy_share``), wall times, and the settings.
    ``progress(label)`` before each model."""
    from tmfem.models.com.linearize import linearize
    out, times, shapes = {}, {}, {}
    fe = fe_models(system, mesh_n=mesh_n, tendon_elements=tendon_elements, backend=backend)
    for key, m in fe.items():
        if progress:
            progress(key)
        t0 = time.perf_counter()
        res = m.equilibrium()
        k = modes if key == "SBC" or modes >= m.max_modes else min(modes + PAIRING_EXTRA, m.max_modes)
        md = m.modes(k=k, at=res)
        out[key] = md.freq_hz
        times[key] = time.perf_counter() - t0
        shapes[key] = fe_shared_shapes(m, md)
        if key == "SBC":
            beam_share = beam_energy_share(m, res.state, md)
    if progress:
        progress("COM")
    t0 = time.perf_counter()
    com = com_model(system, mesh_n=mesh_n)
    lin = linearize(com)
    md = lin.modes(modes + PAIRING_EXTRA)
    out["COM"] = md.freq_hz
    times["COM"] = time.perf_counter() - t0
    shapes["COM"] = com_shared_shapes(com, lin.z_e, md.shapes, mesh_nodes=fe["SBC"].topology.n_mesh)
    return {"freq_hz": {k: np.asarray(out[k][:modes], dtype=float) for k in out}, "time_s": times,
            "shared_shapes": shapes, "pairing_hz": {k: np.asarray(v, dtype=float) for k, v in out.items()},
            "sbc_beam_energy_share": beam_share,
            "settings": {"mesh_n": mesh_n, "tendon_elements": tendon_elements,
                         "backend": {k: m.backend.name for k, m in fe.items()},
                         "rest_lengths": fe["SBC"].rest_lengths.tolist(),
                         "com_membrane_modes": com.K, "com_prestress_scale": com.prestress_scale}}


def compare_frequencies(system, *, modes: int = 12, **kwargs) -> dict:
    """The models that apply (JSON-able; ``models``, and ``left_out``: the others with the
    reason): per mode ours per model, each model against the SBC model and its largest
    difference; with the file's printed columns also those, ours against them, the printed
    model-to-model differences and the bound the source states.
    ``kwargs``: :func:`model_frequencies`."""
    if not (isinstance(modes, int) and modes >= 1):
        raise InputError(f"--modes: expected an integer >= 1, found {modes!r}")
    system = loaded_system(system)
    models = applicable_models(system)
    r = model_frequencies(system, modes=modes, **kwargs)
    ours = r["freq_hz"]
    n = min(len(v) for v in ours.values())
    vs_sbc_ours = {k: ours[k][:n] / ours["SBC"][:n] - 1 for k in models[1:]}
    pairs = paired_modes(r)
    out = {"system": system.name, "modes": modes, "models": list(models),
           "left_out": left_out_models(system), "source": None,
           "ours": {k: v.tolist() for k, v in ours.items()},
           "vs_SBC": {"ours": {k: v.tolist() for k, v in vs_sbc_ours.items()}},
           "max_abs_vs_SBC": {"ours": {k: float(np.abs(v).max()) for k, v in vs_sbc_ours.items()},
                              "paired": {k: _max_abs(pairs[k]["vs_SBC"]) for k in models[1:]}},
           "mode_pairs": pairs,
           "printed": None, "ours_vs_printed": None, "stated_bound": None, "stated": None,
           "settings": r["settings"], "time_s": r["time_s"]}
    printed = printed_frequencies(system)
    if printed and all(k in printed for k in models):
        n = min(modes, len(printed["SBC"]), n)
        pr = {k: np.array(printed[k][:n]) for k in models}
        vs_sbc_printed = {k: pr[k] / pr["SBC"] - 1 for k in models[1:]}
        out.update({"source": printed.get("source", "printed"),
                    "printed": {k: v.tolist() for k, v in pr.items()},
                    "ours_vs_printed": {k: (ours[k][:n] / pr[k] - 1).tolist() for k in models},
                    "stated_bound": printed.get("stated_model_difference"),
                    "stated": printed.get("stated_model_difference_source")})
        out["vs_SBC"]["printed"] = {k: v.tolist() for k, v in vs_sbc_printed.items()}
        out["max_abs_vs_SBC"]["printed"] = {k: float(np.abs(v).max())
                                            for k, v in vs_sbc_printed.items()}
    return out


def paired_modes(r: dict) -> dict:
    """The modes of the other models (MTC, COM: those computed) paired with each SBC mode by
    shape (module docstring) from the result of :func:`model_frequencies` (JSON-able): per
    model the 1-based partner ``mode``
    (None: no counterpart), its ``mac``, its frequency ``freq_hz`` and its difference
    ``vs_SBC`` = f / f_SBC - 1 (the partner may be one of the :data:`PAIRING_EXTRA` modes
    above the table), the model's modes of the table paired with no SBC mode (``unpaired``)
    and whether the pairing is the identity; the bars' share of each SBC mode's strain energy
    (``SBC_beam_energy_fraction``); ``SBC_unpaired``: the SBC modes without a counterpart in
    any other model."""
    f, shapes = r["pairing_hz"], r["shared_shapes"]
    others = _others(r["freq_hz"])
    out = {"rule": {"mac_threshold": MAC_THRESHOLD, "cluster_tolerance": CLUSTER_TOLERANCE,
                    "vector": "translations of the bar ends and of the membrane mesh nodes"}}
    for k in others:
        p = pair_modes(shapes["SBC"], shapes[k], reference_hz=f["SBC"], other_hz=f[k])
        out[k] = {"mode": [None if j is None else j + 1 for j in p.partner], "mac": p.mac,
                  "freq_hz": [None if j is None else float(f[k][j]) for j in p.partner],
                  "vs_SBC": [None if j is None else float(f[k][j] / f["SBC"][i] - 1)
                             for i, j in enumerate(p.partner)],
                  "unpaired": [j + 1 for j in p.unpaired_other if j < len(r["freq_hz"][k])],
                  "identity": p.is_identity}
    share = r["sbc_beam_energy_share"]
    out["SBC_beam_energy_fraction"] = [float(v) for v in share]
    out["SBC_unpaired"] = [{"mode": i + 1, "freq_hz": float(f["SBC"][i]),
                            "without": [k for k in others if out[k]["mode"][i] is None],
                            "beam_energy_fraction": float(share[i])}
                           for i in range(len(f["SBC"]))
                           if any(out[k]["mode"][i] is None for k in others)]
    return out


def _others(by_model) -> list:
    """The models of ``by_model`` (a dict keyed by model) compared with the SBC model, in the
    order of :data:`MODELS`."""
    return [m for m in MODELS[1:] if m in by_model]


def _and(names) -> str:
    """"A", "A and B", "A, B and C"."""
    names = list(names)
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def left_out_lines(r: dict) -> list[str]:
    """One line per model left out of the comparison, with the reason."""
    return [f"{m} model left out: {why}" for m, why in r.get("left_out", {}).items()]


def _max_abs(values) -> float | None:
    """Largest |v| of the values that are not None (None when there are none)."""
    v = [abs(x) for x in values if x is not None]
    return max(v) if v else None


#: above this share of its strain energy in the bars an SBC mode is called a bar mode
BAR_MODE_SHARE = 0.5


def pairing_notes(r: dict) -> list[str]:
    """Lines of text on the pairing: the rule, the unpaired modes of each model."""
    p = r["mode_pairs"]
    rule = p["rule"]
    others = _others(p)
    lines = [f"modes paired by shape: MAC of the {rule['vector']} (no mass weighting), one-to-one "
             f"assignment, pairs below MAC {rule['mac_threshold']:g} dropped; {_and(others)} modes within "
             f"{100 * rule['cluster_tolerance']:g} % in frequency compared as one span"]
    for u in p["SBC_unpaired"]:
        share = u["beam_energy_fraction"]
        kind = (f"the bars bend: {100 * share:.0f} % of its strain energy in the bars" if share > BAR_MODE_SHARE
                else f"{100 * share:.0f} % of its strain energy in the bars")
        lines.append(f"SBC mode {u['mode']} ({u['freq_hz']:.4f} Hz): no counterpart in "
                     f"{' or '.join(u['without'])} among the computed modes ({kind})")
    for k in others:
        if p[k]["unpaired"]:
            lines.append(f"{k} modes {p[k]['unpaired']}: paired with no SBC mode among the computed modes")
    return lines


def _paired_table(r: dict) -> list[str]:
    """The paired modes: SBC mode, and per model its paired mode, frequency, MAC, difference."""
    p = r["mode_pairs"]
    others = _others(p)
    lines = [f"{'mode':>4} {'SBC ours':>9} " + " ".join(f"{m:>4} {m + ' ours':>9} {'MAC':>5} {m + '/SBC':>8}"
                                                        for m in others)]
    for i, f in enumerate(r["ours"]["SBC"]):
        row = f"{i + 1:>4} {f:9.4f}"
        for m in others:
            j = p[m]["mode"][i]
            row += (f" {'-':>4} {'':9} {p[m]['mac'][i]:5.2f} {'none':>8}" if j is None else
                    f" {j:>4} {p[m]['freq_hz'][i]:9.4f} {p[m]['mac'][i]:5.2f} {100 * p[m]['vs_SBC'][i]:+7.2f}%")
        lines.append(row)
    mx = r["max_abs_vs_SBC"]["paired"]
    lines.append("largest |model / SBC - 1| of the pairs: " + ", ".join(
        f"{m} {'-' if mx[m] is None else f'{100 * mx[m]:.2f} %'}" for m in others))
    return lines + pairing_notes(r)


def format_compare(r: dict) -> str:
    """Text table of :func:`compare_frequencies` (the printed columns when there are some)."""
    s = r["settings"]
    models, others = list(r["ours"]), _others(r["ours"])
    head = (f"{r['system']}: {_and(models)} natural frequencies [Hz]"
            + (f" beside {r['source']}" if r["printed"] else "")
            + f" (mesh {s['mesh_n']}, {s['tendon_elements']} elements/tendon, backend "
            + ", ".join(f"{k} {v}" for k, v in s["backend"].items()) + ", COM K = "
            f"{s['com_membrane_modes']}, prestress x{s['com_prestress_scale']:.4f})")
    if not r["printed"]:
        lines = [head] + left_out_lines(r) + _paired_table(r)
        lines.append("times [s]: " + ", ".join(f"{k} {v:.2f}" for k, v in r["time_s"].items()))
        return "\n".join(lines)
    n = len(r["printed"]["SBC"])
    lines = [head] + left_out_lines(r) + [
             f"{'mode':>4} " + " ".join(f"{m + ' ours':>9} {m + ' pr.':>9} {'diff':>7}" for m in models)
             + "".join(f" {m + '/SBC':>8} {'pr.':>7}" for m in others)]
    for i in range(len(r["ours"]["SBC"])):
        row = f"{i + 1:>4} "
        if i < n:
            row += " ".join(f"{r['ours'][m][i]:9.4f} {r['printed'][m][i]:9.4f} "
                            f"{100 * r['ours_vs_printed'][m][i]:+6.2f}%" for m in models)
            row += " " + " ".join(f"{100 * r['vs_SBC']['ours'][m][i]:+7.2f}% "
                                  f"{100 * r['vs_SBC']['printed'][m][i]:+6.2f}%" for m in others)
        else:
            row += " ".join(f"{r['ours'][m][i]:9.4f} {'':9} {'':7}" for m in models)
        lines.append(row)
    mx = r["max_abs_vs_SBC"]
    lines.append("largest |model / SBC - 1|: " + "; ".join(
        f"{kind} " + ", ".join(f"{m} {100 * mx[kind][m]:.2f} %" for m in others) for kind in ("ours", "printed"))
                 + (f" (stated, {r['stated']})" if r["stated"] else ""))
    if all(r["mode_pairs"][m]["identity"] for m in others):
        lowest = min(min(r["mode_pairs"][m]["mac"]) for m in others)
        lines.append(f"modes paired by shape: mode i with mode i in every model (smallest MAC {lowest:.2f}), "
                     "so the comparison by order above is the paired one")
    else:
        lines += ["modes paired by shape (the printed table compares by order):"] + _paired_table(r)
    lines.append("times [s]: " + ", ".join(f"{k} {v:.2f}" for k, v in r["time_s"].items()))
    return "\n".join(lines)


def write_compare_csv(path, r: dict) -> Path:
    """One row per mode: ours and printed per model, the differences of :func:`compare_frequencies`
    (without printed values: ours and the differences to the SBC model)."""
    p = r["mode_pairs"]
    models, others = list(r["ours"]), _others(r["ours"])

    def paired(i):
        """The paired columns of SBC mode i ("" where there is no pair)."""
        return [x for m in others for x in
                ("" if p[m]["mode"][i] is None else p[m]["mode"][i], p[m]["mac"][i],
                 "" if p[m]["mode"][i] is None else p[m]["freq_hz"][i],
                 "" if p[m]["mode"][i] is None else p[m]["vs_SBC"][i])]

    paired_cols = [f"{m}_{c}" for m in others for c in ("paired_mode", "mac", "paired_hz", "paired_vs_SBC")]
    if not r["printed"]:
        with atomic_open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["mode"] + [f"{m}_ours_hz" for m in models] + [f"{m}_vs_SBC" for m in others] + paired_cols)
            for i in range(len(r["vs_SBC"]["ours"][others[0]])):
                w.writerow([i + 1] + [r["ours"][m][i] for m in models]
                           + [r["vs_SBC"]["ours"][m][i] for m in others] + paired(i))
        return Path(path)
    n = len(r["printed"]["SBC"])
    cols = (["mode"] + [f"{m}_ours_hz" for m in models] + [f"{m}_printed_hz" for m in models]
            + [f"{m}_vs_printed" for m in models] + [f"{m}_vs_SBC" for m in others]
            + [f"{m}_vs_SBC_printed" for m in others] + paired_cols)
    with atomic_open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for i in range(len(r["ours"]["SBC"])):
            has = i < n
            vals = ([r["ours"][m][i] for m in models]
                    + [r["printed"][m][i] if has else "" for m in models]
                    + [r["ours_vs_printed"][m][i] if has else "" for m in models]
                    + [r["vs_SBC"]["ours"][m][i] if has else "" for m in others]
                    + [r["vs_SBC"]["printed"][m][i] if has else "" for m in others])
            w.writerow([i + 1] + vals + paired(i))
    return Path(path)
