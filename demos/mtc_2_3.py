"""MTC model of the 2-3 system (6.2.2, Tables 6.4, 6.5, 6.7): what the printed data allow.

    .venv/bin/python demos/mtc_2_3.py

1. Table 6.4 as printed (`load_preset("2-3", as_printed=True)`): tendon lengths at the
   printed geometry against the printed rest lengths (most tendons would be slack), and the
   MTC static solve with them (it stops with a ConvergenceError naming the slack tendons).
2. The design Tables 6.5 and 6.7 belong to, the default of the preset `2-3`: the final 2-3
   configuration of Table 7.7 with the materials of Table 6.1 (stage-2 base checked against
   the Table 7.7 rest lengths by `tmfem.reference.designs.fit_stage2_base`), the prestress
   calibrated on the stage-1 bar load of Table 6.5 only; landing from the undeformed membrane
   (Figs. 6.5-6.7 nodes), Table 6.5 and Table 6.7 beside ours.
"""
from __future__ import annotations

import sys

import numpy as np

from tmfem.errors import ConvergenceError
from tmfem.models.mtc.model import MTCModel
from tmfem.reference.tables import FREQUENCIES
from tmfem.models.mtc.post import static_summary
from tmfem.system import load_preset


def main() -> int:
    s = load_preset("2-3", as_printed=True)
    L = s.tendon_lengths()
    print("Table 6.4 as printed: tendon length at the printed geometry vs printed rest length")
    seen = set()
    for t, l, r in zip(s.tendons, L, s.rest_lengths):
        if t.group in seen:
            continue
        seen.add(t.group)
        print(f"  {t.group:3s} |d| = {l:.4f} m   r = {r:.4f} m   strain {100 * (l / r - 1):+7.2f} %"
              f"{'   (slack)' if l < r else ''}")
    m = MTCModel(s, mesh_n=10, tendon_elements=3)
    try:
        m.equilibrium(start="undeformed", monitor=["B_11", "A_21", "B_21"])
        print("  MTC static solve converged (unexpected)")
    except ConvergenceError as exc:
        print(f"  {exc}")
    print()
    from tmfem.reference.designs import calibrate_on_bar_load, fit_stage2_base
    fit = fit_stage2_base()
    d = load_preset("2-3")
    c = d.symmetric
    print(f"Table 7.7 final configuration: stage-2 base fitted to its rest lengths r_2 = {fit['r2']:.5f} m, "
          f"z_2 = {fit['z2']:.5f} m (sigma_2 = -34.86 deg, eq. 5.97), F_Delta = {fit['F_Delta']:.3f} N, "
          f"Delta = {1e3 * fit['Delta']:.3f} mm; rest-length residuals {np.round(1e3 * fit['residual'], 3)} mm")
    print(f"  preset 2-3 (rule of 2-3-deploy): r_2 = {c.r[1]:.6f} m, z_2 = {c.z[1]:.6f} m")
    pr = s.printed
    m = MTCModel(d, mesh_n=10, tendon_elements=3, rest_lengths="mtc")
    k = calibrate_on_bar_load(m, pr["bar_load_stage1"])
    res = m.equilibrium(start="undeformed", monitor=["B_11", "A_21", "B_21"])
    st = static_summary(m, res.x, result=res)
    md = m.modes(k=12, at=res.x)
    ref = FREQUENCIES["2-3"]
    print(f"  with Table 6.1 materials, prestress x{k:.4f} (calibrated on the stage-1 bar load only): "
          f"{res.iterations} iterations from the undeformed membrane, lands "
          f"{1e3 * st['max_deviation_from_design']:.3f} mm from the design")
    rows = [("bar load stage 1 [N] (calibrated)", st["bar_load_by_stage"][0], pr["bar_load_stage1"]),
            ("bar load stage 2 [N]", st["bar_load_by_stage"][1], pr["bar_load_stage2"]),
            ("tendon max stress [MPa]", st["tendon_stress_max"] / 1e6, pr["tendon_max_stress"] / 1e6),
            ("membrane max sigma_p1 [MPa]", st["membrane_max_sigma_p1"] / 1e6, pr["membrane_max_sigma_p1"] / 1e6),
            ("membrane max von Mises [MPa]", st["membrane_max_von_mises"] / 1e6, pr["membrane_max_von_mises"] / 1e6)]
    print(f"  {'':36s} {'ours':>10s} {'Table 6.5':>10s}")
    for a, b, c in rows:
        print(f"  {a:36s} {b:10.3f} {c:10.3f}")
    print(f"  {'mode':>4s} {'ours [Hz]':>10s} {'MTC 6.7':>9s} {'SBC 6.7':>9s} {'diff':>8s}")
    for i in range(12):
        print(f"  {i + 1:4d} {md.freq_hz[i]:10.4f} {ref['MTC'][i]:9.4f} {ref['SBC'][i]:9.4f} "
              f"{100 * (md.freq_hz[i] / ref['MTC'][i] - 1):+7.3f}%")
    return 0


if __name__ == "__main__":
    sys.exit(main())
