"""Result summaries both finite-element models report: bar loads against the Euler load, the
design checks of 6.2 and the rows printed beside the dissertation's values."""
from __future__ import annotations

import numpy as np


def critical_loads(system) -> np.ndarray:
    """Euler critical load [N] of every bar (eq. 5.31), system bar order."""
    return np.array([system.bar.euler_critical_load(l) for l in system.l.ravel()])


def bar_loads(system, bar_force) -> dict:
    """Bar loads (compression positive) of bar axial forces ``bar_force`` (system bar order):
    the largest, the smallest Euler critical load (eq. 5.31) and, for M >= 2, the largest of
    each stage (Table 6.5)."""
    load = -np.asarray(bar_force, dtype=float)
    Fcrit = critical_loads(system)
    out = {"bar_load_max": float(load.max()), "bar_critical_load": float(Fcrit.min())}
    if system.M >= 2:
        out["bar_load_by_stage"] = [float(v) for v in load.reshape(system.M, system.N).max(axis=1)]
    return out


def design_checks(system, *, sigma_p1, von_mises, tendon_stress, tendon_yield, tendon_slack,
                  bar_force) -> list:
    """The checks of the equilibrium design at a computed state: membrane peaks against the
    yield stress (eqs. 5.29-5.30), tendon stresses against theirs (6.2), no slack tendon
    (3.18), bar loads below the Euler critical load (eq. 5.31). Each a dict (check, value,
    limit, unit, ok, equation)."""
    checks = []

    def check(name, value, limit, ok, eq, unit):
        checks.append({"check": name, "value": float(value), "limit": float(limit), "unit": unit,
                       "ok": bool(ok), "equation": eq})

    mat = system.membrane
    if mat.yield_stress:
        check("membrane max sigma_p1 <= yield", sigma_p1, mat.yield_stress,
              sigma_p1 <= mat.yield_stress, "5.29", "Pa")
        check("membrane max von Mises <= yield", von_mises, mat.yield_stress,
              von_mises <= mat.yield_stress, "5.30", "Pa")
    ty = np.asarray(tendon_yield, dtype=float)
    if np.any(np.isfinite(ty)):
        s = np.asarray(tendon_stress)
        k = int(np.nanargmax(s / ty))
        ok = np.isfinite(ty)
        check("tendon stress <= yield", s[k], ty[k], np.all(s[ok] <= ty[ok]), "6.2", "Pa")
    slack = np.asarray(tendon_slack, dtype=bool)
    check("no slack tendon", int(slack.sum()), 0, not slack.any(), "3.18", "slack tendons")
    load = -np.asarray(bar_force, dtype=float)
    Fcrit = critical_loads(system)
    k = int(np.argmax(load / Fcrit))
    check("bar load <= Euler critical load", load[k], Fcrit[k], np.all(load <= Fcrit), "5.31", "N")
    return checks


def check_lines(checks) -> list:
    """One text line per check of :func:`design_checks`, stresses in MPa, forces in N."""
    def amount(c, v):
        unit = c.get("unit", "")
        return f"{v / 1e6:.4g} MPa" if unit == "Pa" else f"{v:.4g} {unit}".rstrip()
    return [f"check {c['check']:36s} {'ok' if c['ok'] else 'VIOLATED'}  "
            f"({amount(c, c['value'])} vs {amount(c, c['limit'])}, eq. {c['equation']})" for c in checks]


def printed_lines(r: dict, model: str) -> list:
    """The rows of :func:`printed_rows` under a header: ``model``'s values, and beside them a
    column of printed values only when the system's ``[printed]`` table gives any."""
    rows = printed_rows(r)
    has_printed = any(np.isfinite(c) for _, _, c in rows)
    return ([f"{'':32s} {model:>12s}" + (f" {'printed':>12s}" if has_printed else "")]
            + [f"{a:32s} {b:12.4g} {c:12.4g}" if np.isfinite(c) else f"{a:32s} {b:12.4g}"
               for a, b, c in rows])


def printed_rows(r: dict) -> list:
    """(quantity, ours, printed or NaN) rows of a static summary ``r`` beside the printed
    Table 6.3/6.5 values in ``r["printed"]``: membrane peaks [MPa], the largest tendon stress
    [MPa], bar loads (per stage for M >= 2) and the critical load [N]."""
    pr = r.get("printed", {})
    nan = np.nan
    rows = [("membrane max sigma_p1 [MPa]", r["membrane_max_sigma_p1"] / 1e6,
             pr.get("membrane_max_sigma_p1", nan) / 1e6),
            ("membrane max von Mises [MPa]", r["membrane_max_von_mises"] / 1e6,
             pr.get("membrane_max_von_mises", nan) / 1e6),
            ("tendon max stress [MPa]", r["tendon_stress_max"] / 1e6,
             pr.get("tendon_max_stress", nan) / 1e6)]
    if "bar_load_by_stage" in r:
        rows += [(f"bar load, stage {i + 1} [N]", v, pr.get(f"bar_load_stage{i + 1}", nan))
                 for i, v in enumerate(r["bar_load_by_stage"])]
    else:
        rows.append(("bar load [N]", r["bar_load_max"], pr.get("bar_load", nan)))
    rows.append(("bar critical load [N]", r["bar_critical_load"], pr.get("bar_critical_load", nan)))
    return rows
