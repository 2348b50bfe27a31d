"""Natural frequencies of the control-oriented model beside Tables 6.6 and 6.7 (COM column).

For each system: the COM linearised about its equilibrium (eq. 5.33) with the dissertation's
number of membrane modes (K = 5 for 1-4, 4 for 2-3), once with the prestress designed from
the geometry (eq. 3.22, linear plane-stress FE, 4 x 10 x 10 / 3 x 10 x 10 mesh) and once
with the prestress implied by the printed maximum tendon stress (Tables 6.3 / 6.5) and once
with the prestress implied by the printed stage-1 bar load (14.53 / 14.48 N, the calibration
of the MTC comparison); then the frequencies vs K.

    .venv/bin/python demos/com_frequencies.py [--systems 1-4 2-3] [--k-study 1 2 3 4 5 6 8]
"""
from __future__ import annotations

import argparse

from tmfem.errors import TmfemError
from tmfem.models.com.model import default_membrane_modes
from tmfem.reference.com_modal import (dissertation_com_frequencies, frequency_study, modal_summary)
from tmfem.system import load_preset


def plot_study(rows, path, *, title: str, reference=None) -> str:
    """Frequencies vs K (one marker column per K, one panel per prestress factor)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scales = sorted({r["prestress_scale"] for r in rows})
    fig, axes = plt.subplots(1, len(scales), figsize=(5 * len(scales), 4), sharey=True, squeeze=False)
    for ax, sc in zip(axes[0], scales):
        for r in (r for r in rows if r["prestress_scale"] == sc):
            ax.plot([r["K"]] * len(r["freq_hz"]), r["freq_hz"], "o", ms=4, color="C0")
        if reference:
            for f in reference:
                ax.axhline(f, color="C3", lw=0.6, alpha=0.6)
        ax.set_xlabel("membrane modes K")
        ax.set_title(f"prestress x{sc:.4f}")
    axes[0][0].set_ylabel("frequency [Hz] (first 12)")
    fig.suptitle(title + (" (red: printed COM column)" if reference else ""))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


def table(name: str, k_study, plot_dir=None) -> None:
    system = load_preset(name)
    K = default_membrane_modes(system)
    r1 = modal_summary(system, modes=12, membrane_modes=K)
    s = r1.get("printed_stress_prestress_scale")
    r2 = modal_summary(system, modes=12, membrane_modes=K, prestress_scale=s) if s else None
    sb = r1.get("printed_bar_load_prestress_scale")
    r3 = modal_summary(system, modes=12, membrane_modes=K, prestress_scale=sb) if sb else None
    ref = dissertation_com_frequencies(system)
    print(f"\n{name}: COM with K = {K} membrane modes, {r1['sizes']['n_z']} coordinates")
    forces = sorted({round(float(v), 4) for v in r1['design_tendon_forces'].values()})
    print(f"designed prestress: tendon forces {forces} N")
    if s:
        print(f"prestress implied by the printed tendon stress: x{s:.4f}")
    if sb:
        print(f"prestress implied by the printed stage-1 bar load: x{sb:.4f}")
    hdr = f"{'mode':>4} {'printed':>9} {'designed':>9} {'rel.':>7}"
    if r2:
        hdr += f" {'printed-stress':>14} {'rel.':>7}"
    if r3:
        hdr += f" {'printed-load':>12} {'rel.':>7}"
    print(hdr)
    com = ref[1] if ref else []
    for i in range(12):
        p = com[i] if i < len(com) else float("nan")
        f1 = r1["freq_hz"][i]
        line = f"{i + 1:>4} {p:>9.4f} {f1:>9.4f} {f1 / p - 1:>+7.2%}"
        if r2:
            f2 = r2["freq_hz"][i]
            line += f" {f2:>14.4f} {f2 / p - 1:>+7.2%}"
        if r3:
            f3 = r3["freq_hz"][i]
            line += f" {f3:>12.4f} {f3 / p - 1:>+7.2%}"
        print(line)
    hp = ref[2] if ref else None
    print(f"highest COM frequency: printed {hp}, designed {r1['highest_hz']:.4f}"
          + (f", printed-stress {r2['highest_hz']:.4f}" if r2 else "")
          + (f", printed-load {r3['highest_hz']:.4f}" if r3 else ""))
    if k_study:
        print(f"\nfrequencies [Hz] vs K ({name})")
        rows = frequency_study(system, K_values=k_study, prestress_scales=[1.0] + ([s] if s else []))
        for row in rows:
            print(f"  x{row['prestress_scale']:.4f} K={row['K']:2d}: "
                  + " ".join(f"{f:.4f}" for f in row["freq_hz"]) + f"  (highest {row['highest_hz']:.4f})")
        if plot_dir:
            from pathlib import Path
            Path(plot_dir).mkdir(parents=True, exist_ok=True)
            print("plot:", plot_study(rows, Path(plot_dir) / f"com_frequencies_vs_K_{name}.png",
                                      title=f"{name} COM", reference=com))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--systems", nargs="+", default=["1-4", "2-3"])
    ap.add_argument("--k-study", nargs="*", type=int, default=[1, 2, 3, 4, 5, 6, 8])
    ap.add_argument("--plot-dir", default=None, help="write PNG plots of the K study here")
    a = ap.parse_args()
    for name in a.systems:
        try:
            table(name, a.k_study, a.plot_dir)
        except TmfemError as exc:
            print(f"\n{name}: cannot build the COM: {exc}")


if __name__ == "__main__":
    main()
