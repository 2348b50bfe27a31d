"""MTC model of the 1-4 system: statics (6.2.1, Fig. 6.1, Table 6.3) and modes (Table 6.6).

    .venv/bin/python demos/mtc_1_4.py [--out DIR]

Prints, beside the dissertation's numbers, the equilibrium reached from the undeformed
membrane and the first 12 frequencies for three prestress levels:

* as printed: r_1^S = 1.529 m (Table 6.2);
* design: the rest lengths of tmfem.equilibrium's design (eq. 3.8 with F_Delta of the linear
  plane-stress membrane on the same mesh), i.e. the "consistent" preset;
* implied: r_1^S = 1.5025 m, the value the dissertation's own Tables 6.3 and 6.6 imply
  (docs/validation/errata.md, "MTC: 1-4 prestress implied by Tables 6.3 and 6.6").

With --out, writes the history of B_14 (Fig. 6.1) as PNG and CSV, the VTK of the equilibrium
and of the modes, and PNG renders.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from tmfem.models.mtc.model import MTCModel
from tmfem.reference.tables import FREQUENCIES
from tmfem.models.mtc.post import static_summary
from tmfem.post.mtc import model_cells
from tmfem.system import load_preset


def run_case(label, system, *, out=None):
    m = MTCModel(system, mesh_n=10, tendon_elements=3)
    res = m.equilibrium(start="undeformed", monitor=["B_14"])
    st = static_summary(m, res.x, result=res)
    modes = m.modes(k=12, at=res.x)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        h = res.monitor["B_14"]
        np.savetxt(out / f"history_B14_{label}.csv", np.column_stack([np.arange(len(h)), h]),
                   delimiter=",", header="iteration,x,y,z", comments="")
        from tmfem.post.plots import plot_histories
        d = 1e3 * (h - system.nodes()[:, system.node_index("B_14")])
        plot_histories(out / f"history_B14_{label}.png", np.arange(len(h)),
                       {"x - x_design": d[:, 0], "y - y_design": d[:, 1], "z - z_design": d[:, 2]},
                       ylabel="B_14 - design [mm]", xlabel="iteration", subplots=True,
                       title=f"1-4 MTC: iteration history of B_14 ({label}; Fig. 6.1)")
        from tmfem.post.mtc import plot_membrane_stress
        plot_membrane_stress(out / f"membrane_stress_{label}.png", m, res.x,
                             title=f"1-4 MTC membrane stresses, {label} (Figs. 6.3-6.4)")
        from tmfem.io.writer import write_modes
        write_modes(out / f"modes_{label}.vtu", res.x, model_cells(m),
                    m.topology.T @ modes.shapes, modes.freq_hz)
    return m, res, st, modes


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    printed = load_preset("1-4", as_printed=True)
    cases = [("as printed (r=1.529)", "printed", printed),
             ("design (eq. 3.8)", "design", load_preset("1-4")),
             ("implied (r=1.5025)", "implied", printed.with_rest_lengths({"S1": 1.5025}))]
    results = []
    for title, label, s in cases:
        print(f"... {title}", file=sys.stderr)
        results.append((title,) + run_case(label, s, out=args.out))
    ref = FREQUENCIES["1-4"]
    pr = printed.printed
    print("1-4 MTC statics (4 x 10 x 10 membrane, 3 elements per tendon), from the undeformed membrane")
    print(f"{'':30s}" + "".join(f"{t:>24s}" for t, *_ in results) + f"{'dissertation':>16s}")
    rows = [("rest length r_1^S [m]", lambda st: st["rest_lengths"]["S_11"], pr["rest_lengths"]["S1"]),
            ("Newton iterations", lambda st: st["iterations"], None),
            ("max |node - design| [mm]", lambda st: 1e3 * st["max_deviation_from_design"], None),
            ("Delta [mm] (design 1.264)", lambda st: 1e3 * np.mean(st["Delta"]), None),
            ("theta_1 [deg]", lambda st: st["theta_deg"][0], 60.0),
            ("psi_14 [deg]", lambda st: st["psi_deg"][3], 10.0),
            ("tendon stress [MPa]", lambda st: st["tendon_stress_max"] / 1e6, pr["tendon_max_stress"] / 1e6),
            ("bar load [N]", lambda st: st["bar_load_max"], pr["bar_load"]),
            ("max sigma_p1 [MPa]", lambda st: st["membrane_max_sigma_p1"] / 1e6, pr["membrane_max_sigma_p1"] / 1e6),
            ("max von Mises [MPa]", lambda st: st["membrane_max_von_mises"] / 1e6, pr["membrane_max_von_mises"] / 1e6)]
    for name, f, p in rows:
        printed_col = f"{'-':>16s}" if p is None else f"{p:16.4f}"      # '-': not printed
        print(f"{name:30s}" + "".join(f"{f(st):24.4f}" for _, _, _, st, _ in results) + printed_col)
    print()
    print(f"1-4 natural frequencies [Hz] ({ref['source']})")
    print(f"{'mode':>4s}" + "".join(f"{t:>24s}" for t, *_ in results) + f"{'MTC paper':>11s}{'SBC paper':>11s}")
    for i in range(12):
        print(f"{i + 1:4d}" + "".join(f"{md.freq_hz[i]:16.4f} ({100 * (md.freq_hz[i] / ref['MTC'][i] - 1):+5.1f}%)"
                                      for *_, md in results)
              + f"{ref['MTC'][i]:11.4f}{ref['SBC'][i]:11.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
