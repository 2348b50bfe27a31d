"""Element benchmarks of dissertation 4.5.3-4.5.4 and closed-form vibration checks.

    .venv/bin/python demos/element_benchmarks.py [--out out/element_benchmarks] [--fine]

Prints, for each benchmark, our numbers beside the closed form (the dissertation gives
these results only as figures 4.8, 4.10-4.12, without numbers), and writes PNG plots and
CSV tables into --out. --fine adds the 80 x 80 membrane mesh (about a minute).
"""
from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

from tmfem.reference.element_benchmarks import (beaded_string_modes, prestressed_square_membrane_modes,
                                          square_membrane, taut_string_modes, two_bar_arch)


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def arch(out: Path, plt):
    print("\n== 4.5.3 two-bar arch (arc length, 2 truss elements) ==")
    cases = [
        ("as printed: a=2500 mm, b=5 mm, EA=50 N", dict(a=2.5, b=0.005, EA=50.0)),
        ("b=5 mm, EA=5e7 N (E in N/mm^2?)", dict(a=2.5, b=0.005, EA=5e7)),
        ("b=25 mm, EA=5e7 N", dict(a=2.5, b=0.025, EA=5e7)),
        ("steep 65 deg (ONSAS), EA=5.25e8 N", dict(a=0.845237, b=1.812616, EA=210e9 * 2.5e-3)),
    ]
    print(f"{'case':40s} {'P*_FE [N]':>13s} {'P*_Green [N]':>13s} {'P*_eng [N]':>13s} "
          f"{'max|P-P_G|/P*':>14s} steps")
    fig, axes = plt.subplots(1, len(cases), figsize=(4 * len(cases), 3.4))
    rows = []
    for (name, kw), ax in zip(cases, axes):
        r = two_bar_arch(**kw)
        L = r.limits
        dev = np.max(np.abs(r.P - r.P_green)) / L["P_green"]
        print(f"{name:40s} {r.P_max_fe:13.6e} {L['P_green']:13.6e} {L['P_eng']:13.6e} {dev:14.2e} {r.steps}")
        rows.append([name, r.P_max_fe, L["P_green"], L["P_eng"], dev])
        vv = np.linspace(0, r.v.max(), 400)
        from tmfem.reference.element_benchmarks import arch_load_engineering, arch_load_green
        ax.plot(vv / kw["b"], arch_load_green(vv, **kw) / L["P_green"], "k-", lw=1, label="Green (closed form)")
        ax.plot(vv / kw["b"], arch_load_engineering(vv, **kw) / L["P_green"], "r--", lw=1, label="engineering strain")
        ax.plot(r.v / kw["b"], r.P / L["P_green"], "o", ms=2.5, label="truss FE, arc length")
        ax.set_title(name, fontsize=8)
        ax.set_xlabel("v / b")
        ax.axhline(0, color="0.7", lw=0.5)
    axes[0].set_ylabel("P / P*_Green")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "arch.png", dpi=120)
    with open(out / "arch.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "P_limit_fe_N", "P_limit_green_N", "P_limit_eng_N", "max_dev_rel"])
        w.writerows(rows)
    print("The element follows the Green-strain (total-Lagrangian) curve; the steep arch separates "
          "Green from engineering strain by a factor ~2 in the limit load.")


def membrane(out: Path, plt, fine: bool):
    print("\n== 4.5.4 square membrane under corner forces (F = 2.749 N diagonal, Fw = 0.1 N at B) ==")
    ns = (5, 10, 20, 40) if fine else (5, 10, 20)
    res = {}
    for n in ns:
        t = time.perf_counter()
        res[n] = square_membrane(n=n)
        log(f"  square membrane {2 * n}x{2 * n}: {time.perf_counter() - t:.1f} s")
    r = res[10]
    xs = np.round(np.arange(0.0, 2.0001, 0.2), 6)
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.4))
    with open(out / "square_membrane.csv", "w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(["mesh", "y_m", "x_m", "w_m"])
        for k, y in enumerate((0.4, 1.0, 1.6)):
            meshes = ", ".join(f"{2 * n}x{2 * n}" for n in ns)
            print(f"\nw [mm] along y = {y} m (Figure {4.10 + 0.01 * k:.2f}); columns: mesh {meshes}, "
                  "linearised (20x20)")
            print("  x [m] " + "".join(f"{2*n}x{2*n}".rjust(10) for n in ns) + "   linear".rjust(10))
            for x in xs:
                vals = [np.interp(x, *res[n].lines[y]) * 1e3 for n in ns]
                sel = np.flatnonzero(np.isclose(r.model.mesh.p[1], y) & np.isclose(r.model.mesh.p[0], x))
                lin = r.w_linear[sel[0]] * 1e3
                print(f"  {x:5.2f} " + "".join(f"{v:10.4f}" for v in vals) + f"{lin:10.4f}")
            for n in ns:
                xx, ww = res[n].lines[y]
                axes[k].plot(xx, ww * 1e3, label=f"{2*n}x{2*n}")
                wr.writerows([[f"{2*n}x{2*n}", y, a_, b_] for a_, b_ in zip(xx, ww)])
            xx, _ = r.lines[y]
            sel = [np.flatnonzero(np.isclose(r.model.mesh.p[1], y) & np.isclose(r.model.mesh.p[0], x))[0] for x in xx]
            axes[k].plot(xx, r.w_linear[sel] * 1e3, "k:", label="linearised 20x20")
            axes[k].set_title(f"y = {y} m")
            axes[k].set_xlabel("x [m]")
    axes[0].set_ylabel("w [mm]")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "square_membrane.png", dpi=120)
    # mesh convergence of the deflections (corner singularities make it slow)
    pts = np.array([0.4, 0.8, 1.2, 1.6])
    ch = []
    for a_, b_ in zip(ns[:-1], ns[1:]):
        d = max(np.max(np.abs(np.interp(pts, *res[a_].lines[y]) - np.interp(pts, *res[b_].lines[y])))
                for y in (0.4, 1.0, 1.6))
        ch.append(d)
    h = np.array([1.0 / n for n in ns[:-1]])
    rate = np.polyfit(np.log(h), np.log(ch), 1)[0] if len(ch) > 1 else float("nan")
    B = {n: res[n].u[2, res[n].model.mesh.corners[2]] for n in ns}
    print("\nmax change of w on the three lines between successive meshes [mm]: "
          + ", ".join(f"{c * 1e3:.4f}" for c in ch) + f"  (fitted rate in h: {rate:.2f})")
    print("w at the loaded corner B [mm]: " + ", ".join(f"{2*n}x{2*n}: {B[n]*1e3:.3f}" for n in ns)
          + "  (grows like log(1/h): point load on a membrane)")
    st = r.model.stresses(r.model.X + r.u)
    print(f"20x20: sigma_p1 max {st.principal[0].max() / 1e6:.3f} MPa, sigma_p3 min "
          f"{st.principal[2].min() / 1e6:.3f} MPa (compression next to the supported corners), "
          f"Newton iterations per Fw step {r.newton_iterations}")


def vibrations(out: Path, plt):
    print("\n== prestressed square membrane, clamped edges, a = 1 m, strain 1e-3 ==")
    hs, errs = [], []
    for n in (2, 4, 8, 16):
        d = prestressed_square_membrane_modes(n=n, k=6)
        e = np.max(np.abs(d["freq_fe"] / d["freq_exact"] - 1))
        hs.append(d["h"])
        errs.append(e)
        print(f"  mesh {2*n:3d}x{2*n:<3d} f [Hz] " + " ".join(f"{f:8.4f}" for f in d["freq_fe"])
              + f"   max rel err {e:.2e}")
    print("  closed form      " + " ".join(f"{f:8.4f}" for f in d["freq_exact"]))
    print(f"  fitted rate (np.polyfit on log h): {np.polyfit(np.log(hs), np.log(errs), 1)[0]:.2f} (expected 2)")

    print("\n== taut string (code_aster V5.02.138: F0 = 6171.05 N, f1 = 62.7323 Hz) ==")
    F0, f1 = 6171.050459855, 62.73227096292042
    for lumped in (False, True):
        hs, errs = [], []
        for n_el in (4, 8, 16, 32):
            d = taut_string_modes(n_el=n_el, length=1.0, tension=F0, mu=F0 / (4 * f1**2), EA=1e7, k=2,
                                  lumped=lumped)
            hs.append(d["h"])
            errs.append(abs(d["freq_fe"][0] / f1 - 1))
            print(f"  {'lumped' if lumped else 'consistent':10s} {n_el:3d} elements: f1 = {d['freq_fe'][0]:.5f} Hz "
                  f"(rel err {errs[-1]:.2e})")
        print(f"  fitted rate: {np.polyfit(np.log(hs), np.log(errs), 1)[0]:.2f} (expected 2)")

    print("\n== beaded string: 7 beads of 10 g, spacing 0.2 m, T = 100 N ==")
    d = beaded_string_modes(n_beads=7, spacing=0.2, tension=100.0, bead_mass=0.01, EA=1e6)
    print("  omega FE     " + " ".join(f"{w:9.4f}" for w in d["omega_fe"][::2]))
    print("  closed form  " + " ".join(f"{w:9.4f}" for w in d["omega_exact"][::2]))
    print(f"  max rel diff {np.max(np.abs(d['omega_fe'] / d['omega_exact'] - 1)):.1e} (each value is a y/z pair)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/element_benchmarks")
    ap.add_argument("--fine", action="store_true", help="add the 80x80 membrane mesh (slow)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    arch(out, plt)
    membrane(out, plt, args.fine)
    vibrations(out, plt)
    print(f"\nplots and CSV tables in {out}/")


if __name__ == "__main__":
    main()
