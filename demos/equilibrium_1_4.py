"""1-4 symmetric system (6.2.1): our equilibrium design beside Tables 6.2 and 6.3.

Run: .venv/bin/python demos/equilibrium_1_4.py
The printed r_1^S = 1.529 m contradicts the printed tendon stress (see docs/validation/errata.md).
"""

from tmfem.equilibrium.design import design_equilibrium
from tmfem.equilibrium.symmetric import r1_1N
from tmfem.system import load_preset
from tmfem.reference.tables import PRINTED, comparison_row as row, format_comparison


def main():
    s = load_preset("1-4")
    d = design_equilibrium(s, mesh_n=10)
    P2, P3 = PRINTED["6.2"], PRINTED["6.3"]
    c = s.symmetric
    EA, A = s.tendon_EA[0], s.tendon_section(s.tendons[0]).area
    L = d.tendon_lengths[0]
    T_stress = P3["tendon_max_stress"] * A
    rows = [
        row("r_1 (eq. 3.33)", P2["r1"], float(r1_1N(l1=c.l[0], theta1=c.theta[0], psi1=c.psi[0], N=4)), "m"),
        row("|S_1| (eq. 3.29)", None, float(L), "m"),
        row("Delta (eq. 3.22)", None, d.Delta * 1e3, "mm"),
        row("F_Delta (plane-stress FE, 4x10x10)", None, d.F_Delta, "N"),
        row("r_1^S (design)", P2["rest_S1"], float(d.rest_lengths[0]), "m"),
        row("r_1^S implied by 37.98 MPa (eqs. 3.8-3.9)", P2["rest_S1"], float(EA * L / (T_stress + EA)), "m"),
        row("tendon stress (design)", P3["tendon_max_stress"] / 1e6, float(d.tendon_stress.max()) / 1e6, "MPa"),
        row("tendon stress at printed r_1^S", P3["tendon_max_stress"] / 1e6,
            float(EA * (L - P2["rest_S1"]) / P2["rest_S1"] / A) / 1e6, "MPa"),
        row("bar load", P3["bar_load"], float(d.bar_loads.max()), "N"),
        row("bar critical load (eq. 5.31, E = 200 GPa)", P3["bar_critical_load"], float(d.bar_critical.max()), "N"),
        row("max sigma_p1 (eq. 5.29, mesh-dependent)", P3["membrane_max_sigma_p1"] / 1e6,
            d.membrane_max_principal / 1e6, "MPa"),
        row("max sigma_v (eq. 5.30, mesh-dependent)", P3["membrane_max_von_mises"] / 1e6,
            d.membrane_max_von_mises / 1e6, "MPa"),
    ]
    print(format_comparison(rows, "1-4 system: Tables 6.2 / 6.3 vs tmfem (membrane mesh 4 x 10 x 10)"))


if __name__ == "__main__":
    main()
