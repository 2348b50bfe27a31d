"""Every registered model of one system side by side: the natural frequencies of each about its
equilibrium (eq. 5.32) and their relative differences to a reference model (the shell-beam-cable
model, the most complete one, by default)."""
from __future__ import annotations

import time

import numpy as np

from tmfem.errors import InputError
from tmfem.models.registry import all_models


def compare_model_frequencies(system, *, modes: int = 12, mesh: int = 10, tendon_elements: int = 3,
                              backend="scipy", reference: str = "sbc", progress=None) -> dict:
    """The ``modes`` lowest natural frequencies [Hz] of every registered model of ``system``,
    each built with its registry defaults on an FE membrane mesh ``mesh`` with
    ``tendon_elements`` truss elements per tendon, and each model's relative difference to
    ``reference`` (JSON-able). ``progress(name)`` before each model."""
    if not (isinstance(modes, int) and modes >= 1):
        raise InputError(f"--modes: expected an integer >= 1, found {modes!r}")
    specs = all_models()
    if reference not in specs:
        raise InputError(f"compare: expected a reference model of {sorted(specs)}, found "
                         f"{reference!r}")
    freq, times, sizes = {}, {}, {}
    for name, spec in specs.items():
        if progress:
            progress(name.upper())
        t0 = time.perf_counter()
        options = {o.name: o.default for o in spec.options}
        options.update({k: v for k, v in (("mesh", mesh), ("tendon_elements", tendon_elements))
                        if k in options})
        model = spec.build(system, options, backend if spec.uses_backend else None)
        k = min(modes, model.max_modes)
        freq[name] = model.modes(k=k, at=model.equilibrium()).freq_hz
        times[name] = time.perf_counter() - t0
        sizes[name] = model.describe()
    ref = freq[reference]
    n = min(len(f) for f in freq.values())
    return {"system": system.name, "modes": modes, "reference": reference,
            "ours": {k: v.tolist() for k, v in freq.items()},
            "vs_reference": {k: (v[:n] / ref[:n] - 1).tolist() for k, v in freq.items()
                             if k != reference},
            "max_abs_vs_reference": {k: float(np.abs(v[:n] / ref[:n] - 1).max())
                                     for k, v in freq.items() if k != reference},
            "settings": {"mesh_n": mesh, "tendon_elements": tendon_elements, "models": sizes},
            "time_s": times}


def format_model_frequencies(r: dict) -> str:
    """Text table of :func:`compare_model_frequencies`."""
    names = list(r["ours"])
    ref = r["reference"]
    others = [m for m in names if m != ref]
    lines = [f"{r['system']}: natural frequencies [Hz] of the models (FE mesh "
             f"{r['settings']['mesh_n']}, {r['settings']['tendon_elements']} elements/tendon)",
             f"{'mode':>4} " + " ".join(f"{m.upper():>9}" for m in names)
             + " " + " ".join(f"{m.upper() + '/' + ref.upper():>9}" for m in others)]
    for i in range(max(len(v) for v in r["ours"].values())):
        row = f"{i + 1:>4} " + " ".join(f"{r['ours'][m][i]:9.4f}" if i < len(r["ours"][m])
                                        else f"{'':9}" for m in names)
        row += " " + " ".join(f"{100 * r['vs_reference'][m][i]:+8.2f}%"
                              if i < len(r["vs_reference"][m]) else f"{'':9}" for m in others)
        lines.append(row)
    lines.append(f"largest |model / {ref.upper()} - 1|: " + ", ".join(
        f"{m.upper()} {100 * v:.2f} %" for m, v in r["max_abs_vs_reference"].items()))
    lines.append("times [s]: " + ", ".join(f"{k} {v:.2f}" for k, v in r["time_s"].items()))
    return "\n".join(lines)
