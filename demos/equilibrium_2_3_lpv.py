"""2-3 system of ch. 8 (LPV): the reconstructed design over the grid of 8.3.

Run: .venv/bin/python demos/equilibrium_2_3_lpv.py
Table 8.1 does not print r_1, r_2, z_2, sigma_2, r_mb; we assume the 7.4.3 design and its
rule (docs/validation/errata.md) and check that every grid point is a symmetric equilibrium.
"""
import numpy as np

from tmfem.equilibrium.design import design_equilibrium
from tmfem.equilibrium.symmetric_map import equilibrium_map
from tmfem.system import load_preset
from tmfem.reference.tables import PRINTED, comparison_row as row, deployment_bases, format_comparison


def main():
    P = PRINTED["8.1"]
    s = load_preset("2-3-lpv")
    emap = equilibrium_map(s, theta=np.radians(P["theta_grid_deg"]), psi=np.radians(P["psi_grid_deg"]),
                           bases=deployment_bases(s))
    print("grid of 8.3: feasible (positive null vector and Delta > 0), LP margin")
    print("theta \\ psi " + "".join(f"{p:>10.2f}" for p in P["psi_grid_deg"]))
    for a, th in enumerate(P["theta_grid_deg"]):
        print(f"{th:11.2f} " + "".join(f"{('yes' if emap.feasible[a, b] else 'NO'):>4} {emap.margin[a, b]:5.3f}"
                                       for b in range(len(P["psi_grid_deg"]))))
    d = design_equilibrium(s, mesh_n=10)
    c = s.symmetric
    rows = [row("theta_0", P["theta0_deg"], float(np.degrees(c.theta[0])), "deg"),
            row("psi_0 (eq. 5.97, relative)", P["psi0_deg"], float(np.degrees(c.psi[0])), "deg"),
            row("r_1 (assumed, 7.4.3)", "not printed", float(c.r[0]), "m"),
            row("sigma_2 (assumed, 7.4.3)", "not printed", float(np.degrees(c.sigma[1])), "deg"),
            row("z_2 (rule)", "not printed", float(c.z[1]), "m"),
            row("r_2 (rule, Delta = 1 mm)", "not printed", float(c.r[1]), "m"),
            row("r_mb (assumed, 7.4.3)", "not printed", float(s.r_mb), "m"),
            row("Delta", None, d.Delta * 1e3, "mm"),
            row("max tendon stress (static, initial)", None, float(d.tendon_stress.max()) / 1e6, "MPa"),
            row("bar critical load (eq. 5.31)", P["bar_critical_load"], float(d.bar_critical.max()), "N")]
    rows += [row(f"rest length {g} (design)", None, v, "m")
             for g, v in d.group_values(d.rest_lengths).items()]
    print(format_comparison(rows, "2-3 LPV system (ch. 8), initial configuration"))


if __name__ == "__main__":
    main()
