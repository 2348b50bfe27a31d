"""2-3 symmetric system (6.2.2): the printed design of Table 6.4 checked against ch. 3.

Run: .venv/bin/python demos/equilibrium_2_3.py
As printed the design is not an equilibrium (docs/validation/errata.md); the table shows why.
"""
import numpy as np

from tmfem.equilibrium.symmetric import s1_length
from tmfem.system import load_preset
from tmfem.reference.tables import (PRINTED, comparison_row as row, format_comparison, symmetric_prestress,
                          top_radius_for_delta)


def main():
    P, P5 = PRINTED["6.4"], PRINTED["6.5"]
    s = load_preset("2-3", as_printed=True)
    p = symmetric_prestress(s)
    rows = [row("Delta (eq. 3.22; must be > 0)", None, p.Delta * 1e3, "mm"),
            row("null-vector margin (> 0: all taut)", None, p.margin)]
    rows += [row(f"T_{g} / F_Delta (null vector, 3.3.2)", None, float(v)) for g, v in zip(p.groups, p.per_F)]
    L = p.as_dict(p.length)
    rows += [row(f"tendon length |{g}| vs printed rest length", r, L[g], "m") for g, r in P["rest"].items()]
    rows += [row("|S_1| (eq. 3.29, stage 1 only)", P["rest"]["S1"],
                 float(s1_length(l1=2.5, theta1=np.radians(63), psi1=np.radians(20), r1=0.7, N=3)), "m"),
             row("z_2 = 0.7 l cos(theta) (Table 7.7 rule)", P["z2"], 0.7 * 2.5 * np.cos(np.radians(63)), "m"),
             row("sigma_2 = psi_2 - psi_1 (Table 7.7 rule)", P["sigma2_deg"], -46.45 - 20.0, "deg"),
             row("r_2 for Delta = 1 mm (Table 7.7 rule)", P["r"][1],
                 top_radius_for_delta(l_M=2.5, theta_M=np.radians(63), psi_rel=np.radians(20),
                                      r_mb=1.87, Delta=1e-3, N=3), "m"),
             row("bar critical load (eq. 5.31, E = 200 GPa, l = 2.5 m)", P5["bar_critical_load"],
                 s.bar.euler_critical_load(2.5), "N")]
    print(format_comparison(rows, "2-3 system: Table 6.4 as printed vs ch. 3 (mesh 3 x 10 x 10)"))


if __name__ == "__main__":
    main()
