"""Cost of the control-oriented model's set-up against the inputs that scale it: the stages
(through the n_q coordinates, n_q = 2N + 5N(M - 1)) and the membrane modes K.

Each size is built in a fresh process (``ControlOrientedModel`` of the M-stage towers of
tests/cli/test_hostile_budget.py, rest lengths 0.95 of the tendon lengths, so that the
set-up itself is timed and not the design's checks); the process reports its CPU time
(all threads, not the wall time: the machines are shared) and its peak resident memory.
The script prints the measurements, the least-squares fit of

    t = t0 + a n_q^p + b K^2            [CPU s]
    m = m0 + c n_q^2 + d K^2        [bytes]

and the estimates of :mod:`tmfem.resources` (``com_setup_seconds``, ``com_setup_bytes``)
beside each measurement, so that the constants there can be checked against this machine.

    .venv/bin/python benchmarks/bench_com_setup.py [--sizes 2:4 2:10 ...]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import curve_fit

ROOT = Path(__file__).resolve().parents[1]
SIZES = ["2:4", "2:10", "2:20", "2:40", "8:4", "16:20", "32:4", "64:4", "128:4"]

CHILD = """
import json, resource, sys, time
from tests.cli.test_hostile_budget import stages
from tmfem.models.com.model import ControlOrientedModel
from tmfem.system.spec import system_from_dict
M, K = int(sys.argv[1]), int(sys.argv[2])
d = stages(M)
d.pop("monitor", None)
system = system_from_dict(d, "tower")
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
c0 = time.process_time()
ControlOrientedModel(system, membrane_modes=K, rest_lengths=0.95 * system.tendon_lengths())
print(json.dumps({"M": M, "K": K, "n_q": len(system.q_names), "cpu_s": time.process_time() - c0,
                  "base_bytes": base,
                  "peak_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}))
"""


def measure(M: int, K: int) -> dict:
    p = subprocess.run([sys.executable, "-c", CHILD, str(M), str(K)], capture_output=True,
                       text=True, cwd=ROOT, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def main():
    from tmfem.resources import com_setup_bytes, com_setup_seconds
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", nargs="+", default=SIZES, help="M:K pairs")
    args = ap.parse_args()
    rows = []
    print(f"{'M':>4} {'K':>3} {'n_q':>5} {'CPU s':>7} {'est. s':>7} {'peak GB':>8} {'est. GB':>8}")
    for size in args.sizes:
        M, K = map(int, size.split(":"))
        r = measure(M, K)
        rows.append(r)
        print(f"{M:4d} {K:3d} {r['n_q']:5d} {r['cpu_s']:7.2f} "
              f"{com_setup_seconds(n_q=r['n_q'], K=K):7.2f} {r['peak_bytes'] / 1e9:8.3f} "
              f"{com_setup_bytes(n_q=r['n_q'], K=K) / 1e9:8.3f}", flush=True)
    nq = np.array([r["n_q"] for r in rows], float)
    K = np.array([r["K"] for r in rows], float)
    t = np.array([r["cpu_s"] for r in rows])
    m = np.array([r["peak_bytes"] for r in rows], float)
    (t0, a, p, b), _ = curve_fit(lambda X, t0, a, p, b: t0 + a * X[0] ** p + b * X[1] ** 2,
                                 (nq, K), t, p0=(0.5, 2e-4, 1.5, 2e-3),
                                 bounds=([0, 0, 0.5, 0], [10, 1, 3, 1]))
    A = np.column_stack([np.ones_like(nq), nq**2, K**2])
    (m0, c, d), *_ = np.linalg.lstsq(A, m, rcond=None)
    print(f"fit: t = {t0:.3g} + {a:.3g} n_q^{p:.3f} + {b:.3g} K^2 [CPU s]")
    print(f"fit: m = {m0 / 1e9:.3g} GB + {c:.3g} n_q^2 + {d:.3g} K^2 [bytes]")


if __name__ == "__main__":
    main()
