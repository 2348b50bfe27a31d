"""The 2-3 deployment (7.4, Table 7.7) on a finite-element plant beside the same deployment on
the control-oriented model (issue 15, docs/guides/fe-plant.md): from two CSVs of ``tmfem deploy``
(same controller, same dt), the deviation of the FE run from the COM run over time (largest
bar-angle difference [mrad], largest stage-2 base-position difference [mm]), each run's
tracking error |q - q_d| and the smallest rest-length margin |tendon| - r.

    tmfem deploy --preset 2-3-deploy --controller adaptive-hinf --pfl-at reference --csv com.csv
    tmfem deploy --preset 2-3-deploy --controller adaptive-hinf --plant mtc --plant-mesh 10 --csv mtc.csv
    .venv/bin/python demos/fe_deployment_deviation.py com.csv mtc.csv [--times 0.5,1,2,5,10,15,17.5,20]
"""
from __future__ import annotations

import argparse
import csv

import numpy as np


def read(path):
    """Columns of a deployment CSV by name (units stripped), numeric ones as arrays."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    head = [h.split(" [")[0] for h in rows[0]]
    cols = {}
    for j, h in enumerate(head):
        vals = [r[j] for r in rows[1:]]
        try:
            cols[h] = np.array(vals, dtype=float)
        except ValueError:
            cols[h] = np.array(vals)
    return cols


def groups(cols):
    """Names of the bar angles (theta, psi) and base positions (x, y, z) of the CSV."""
    q = [h for h in cols if h.split("_")[0] in ("theta", "psi", "x", "y", "z")
         and not h.endswith("_ref")]
    ang = [h for h in q if h.startswith(("theta", "psi"))]
    return ang, [h for h in q if h not in ang]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("com_csv")
    ap.add_argument("fe_csv")
    ap.add_argument("--times", default="0.5,1,2,5,10,15,17.5,20")
    a = ap.parse_args()
    c, f = read(a.com_csv), read(a.fe_csv)
    n = min(c["t"].size, f["t"].size)
    if not np.allclose(c["t"][:n], f["t"][:n]):
        raise SystemExit("the two runs have different time grids")
    ang, pos = groups(c)
    t = c["t"][:n]
    dev_a = np.max(np.abs(np.column_stack([f[h][:n] - c[h][:n] for h in ang])), axis=1)
    dev_p = np.max(np.abs(np.column_stack([f[h][:n] - c[h][:n] for h in pos])), axis=1)
    for name, run in ((a.com_csv, c), (a.fe_csv, f)):
        err = np.max(np.abs(np.column_stack([run[h][:n] - run[h + "_ref"][:n] for h in ang])),
                     axis=1)
        pfl = run["controller"][:n] == "adaptive-pfl"
        tendons = [h[2:] for h in run if h.startswith("r_")]
        margin = np.min(np.column_stack([run["L_" + k][:n] - run["r_" + k][:n] for k in tendons]))
        print(f"{name}: bar-angle tracking error max {1e3 * np.max(err[pfl]):.2f} mrad over the PFL "
              f"phase (to {t[pfl][-1]:.2f} s), {1e3 * err[-1]:.2f} mrad at {t[-1]:g} s; smallest "
              f"rest-length margin {1e3 * margin:.3f} mm")
    print("t [s] | second - first, bar angles [mrad] | second - first, stage-2 bases [mm]")
    for tt in (float(s) for s in a.times.split(",")):
        k = min(int(round(tt / (t[1] - t[0]))), n - 1)
        print(f"{t[k]:g} | {1e3 * dev_a[k]:.2f} | {1e3 * dev_p[k]:.2f}")
    print(f"max | {1e3 * dev_a.max():.2f} (at {t[np.argmax(dev_a)]:g} s) | "
          f"{1e3 * dev_p.max():.2f} (at {t[np.argmax(dev_p)]:g} s)")


if __name__ == "__main__":
    main()
