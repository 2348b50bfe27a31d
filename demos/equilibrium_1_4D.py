"""1-4(D) deployable system (7.4.1): our designs beside Tables 7.2 and 7.3.

Run: .venv/bin/python demos/equilibrium_1_4D.py   (also used by demos/equilibrium_1_6D.py)
k_H is not printed (reconstructed: 0.25); the printed final psi = 30 deg is read as 24 deg
(docs/validation/errata.md). The "as printed" column block evaluates the printed final configuration.
"""
import numpy as np

from tmfem.equilibrium.symmetric import membrane_delta_system
from tmfem.system import load_preset
from tmfem.reference.tables import (PRINTED, comparison_row as row, fit_rest_lengths, format_comparison,
                          symmetric_prestress, with_symmetric)


def deployable_table(name: str, table: str) -> str:
    P = PRINTED[table]
    s0, s1 = load_preset(f"{name}-initial"), load_preset(name)
    x, _ = fit_rest_lengths(lambda x: [with_symmetric(s0, k_H=x[0]), with_symmetric(s1, k_H=x[0])],
                            [0.3], [P["initial"]["rest"], P["final"]["rest"]], bounds=([0.05], [0.6]))
    rows = [row("k_H (least squares, both configurations)", "not printed", float(x[0]))]
    for s, cfg in ((s0, "initial"), (s1, "final")):
        c = P[cfg]
        p = symmetric_prestress(s)
        rest = p.as_dict(p.rest)
        rows += [row(f"{cfg}: theta", c["theta_deg"], float(np.degrees(s.symmetric.theta[0])), "deg"),
                 row(f"{cfg}: psi", c["psi_deg"], float(np.degrees(s.symmetric.psi[0])), "deg"),
                 row(f"{cfg}: Delta (eq. 3.22)", None, p.Delta * 1e3, "mm"),
                 row(f"{cfg}: F_Delta", None, p.F_Delta, "N")]
        rows += [row(f"{cfg}: rest length {g}", c["rest"][g], rest[g], "m") for g in ("SL", "SU")]
    sp = load_preset(name, as_printed=True)
    rows.append(row("final as printed: Delta (eq. 3.22)", None, membrane_delta_system(sp) * 1e3, "mm"))
    crit = s1.bar.euler_critical_load(float(s1.l[0, 0]))
    rows.append(row("bar critical load (eq. 5.31, d = 30 mm)", PRINTED["7.2"]["bar_critical_load"]
                    if name == "1-4D" else PRINTED["7.4"]["bar_critical_load"], crit, "N"))
    return format_comparison(rows, f"{name}: Table {table} vs tmfem (k_H = {s1.k_H}, mesh N x 10 x 10)")


if __name__ == "__main__":
    print(deployable_table("1-4D", "7.3"))
