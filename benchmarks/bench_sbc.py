"""Speed of the SBC model: static + 12 modes of the 1-4 system at growing membrane meshes.

    .venv/bin/python benchmarks/bench_sbc.py [--meshes 10,20,40]

For each mesh 4 x n x n prints the free DOFs, model build time, trust-region Newton
iterations from the undeformed membrane (no mesh sequencing yet), time per iteration, static
time, modal time (12 modes, shift-invert), their sum, and the MTC model's static + modal time
on the same mesh (with its default mesh sequencing) for the ratio. Issue 10 targets: the
paper's mesh (4 x 10 x 10) under 2 s beyond import; no worse than 3x the MTC model.
"""
from __future__ import annotations

import argparse
import os
import time


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="10,20,40")
    ap.add_argument("--rest-length", type=float, default=1.5025,
                    help="rest length of the S tendons [m] (default: the value Tables 6.3/6.6 imply)")
    args = ap.parse_args(argv)
    from tmfem.models.mtc.model import MTCModel
    from tmfem.models.mtc.spec import sequence_of
    from tmfem.models.sbc.model import SBCModel
    from tmfem.system import load_preset

    system = load_preset("1-4", as_printed=True).with_rest_lengths({"S1": args.rest_length})
    print(f"load average {os.getloadavg()[0]:.2f}, OPENBLAS_NUM_THREADS="
          f"{os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}")
    print(f"{'mesh':>9s} {'dofs':>6s} {'build':>6s} {'its':>4s} {'s/it':>6s} {'static':>7s} "
          f"{'modal':>6s} {'total':>6s} {'f1 [Hz]':>8s} {'MTC total':>9s} {'ratio':>6s}")
    for n in [int(v) for v in args.meshes.split(",")]:
        t0 = time.perf_counter()
        m = SBCModel(system, mesh_n=n, tendon_elements=3)
        tb = time.perf_counter() - t0
        res = m.solve_static()
        t1 = time.perf_counter()
        modes = m.modes(res.state, k=12)
        tm = time.perf_counter() - t1
        total = time.perf_counter() - t0
        t2 = time.perf_counter()
        mtc = MTCModel(system, mesh_n=n, tendon_elements=3)
        rm = mtc.solve_static(sequence=sequence_of(n, None))
        mtc.modes(rm.x, k=12)
        tmtc = time.perf_counter() - t2
        print(f"4x{n}x{n:<4d} {m.ndof:6d} {tb:6.2f} {res.iterations:4d} {res.time / res.iterations:6.3f} "
              f"{res.time:7.2f} {tm:6.2f} {total:6.2f} {modes.freq_hz[0]:8.4f} {tmtc:9.2f} "
              f"{total / tmtc:6.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
