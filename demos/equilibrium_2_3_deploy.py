"""2-3 deployment system (7.4.3): our designs beside Tables 7.6 and 7.7.

Run: .venv/bin/python demos/equilibrium_2_3_deploy.py
r_2, z_2, sigma_2 are not printed; the presets carry the reconstructed rule
(sigma_2 = psi_2 - psi_1, z_2 = 0.7 l cos theta, Delta = 1 mm; docs/validation/errata.md).
"""
import numpy as np

from tmfem.system import load_preset
from tmfem.reference.tables import PRINTED, comparison_row as row, format_comparison, symmetric_prestress


def main():
    P = PRINTED["7.7"]
    rows = []
    for name, cfg in (("2-3-deploy-initial", "initial"), ("2-3-deploy", "final")):
        s = load_preset(name)
        c = s.symmetric
        p = symmetric_prestress(s)
        rest = p.as_dict(p.rest)
        rows += [row(f"{cfg}: theta", P[cfg]["theta_deg"], float(np.degrees(c.theta[0])), "deg"),
                 row(f"{cfg}: sigma_2 (reconstructed)", "not printed", float(np.degrees(c.sigma[1])), "deg"),
                 row(f"{cfg}: z_2 (reconstructed)", "not printed", float(c.z[1]), "m"),
                 row(f"{cfg}: r_2 (reconstructed)", "not printed", float(c.r[1]), "m"),
                 row(f"{cfg}: Delta (eq. 3.22)", None, p.Delta * 1e3, "mm"),
                 row(f"{cfg}: F_Delta", None, p.F_Delta, "N"),
                 row(f"{cfg}: null-vector margin (> 0: taut)", None, p.margin)]
        rows += [row(f"{cfg}: rest length {g}", r, rest[g], "m") for g, r in P[cfg]["rest"].items()]
    s = load_preset("2-3-deploy")
    rows.append(row("bar critical load (eq. 5.31, d = 30 mm)", PRINTED["7.6"]["bar_critical_load"],
                    s.bar.euler_critical_load(1.8), "N"))
    print(format_comparison(rows, "2-3 deployment: Table 7.7 vs tmfem (mesh 3 x 10 x 10)"))


if __name__ == "__main__":
    main()
