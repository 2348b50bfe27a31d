"""Speed of the SBC model: static + 12 modes of the 1-4 system at growing membrane meshes.

    .venv/bin/python benchmarks/bench_sbc.py [--meshes 10,20,40] [--predictor mtc|none]

For each mesh 4 x n x n prints the SBC model's free DOFs, build time, iterations (MTC
predictor + SBC Newton, or the SBC trust-region iteration alone from the undeformed
membrane with ``--predictor none``), static time, modal time (12 modes, shift-invert) and
their sum beside the MTC model's free DOFs, static and modal times (its default mesh
sequencing) on the same mesh, and the ratio of the totals (build included in both). Issue 10
targets: the paper's mesh (4 x 10 x 10) under 2 s beyond import; no worse than 3x the MTC model.
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
    ap.add_argument("--predictor", default="mtc", choices=("mtc", "none"))
    args = ap.parse_args(argv)
    from tmfem.models.mtc.model import MTCModel
    from tmfem.models.mtc.spec import sequence_of
    from tmfem.models.sbc.model import SBCModel
    from tmfem.system import load_preset

    system = load_preset("1-4", as_printed=True).with_rest_lengths({"S1": args.rest_length})
    print(f"load average {os.getloadavg()[0]:.2f}, OPENBLAS_NUM_THREADS="
          f"{os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}, predictor {args.predictor}")
    print(f"{'mesh':>9s} | {'SBC dofs':>8s} {'build':>6s} {'its':>6s} {'static':>7s} {'modal':>6s} "
          f"{'total':>6s} {'f1 [Hz]':>8s} | {'MTC dofs':>8s} {'static':>7s} {'modal':>6s} "
          f"{'total':>6s} {'f1 [Hz]':>8s} | {'ratio':>5s}")
    for n in [int(v) for v in args.meshes.split(",")]:
        t0 = time.perf_counter()
        m = SBCModel(system, mesh_n=n, tendon_elements=3)
        tb = time.perf_counter() - t0
        res = m.solve_static(predictor=args.predictor)
        t1 = time.perf_counter()
        modes = m.modes(res.state, k=12, tangent=res.tangent)
        tm = time.perf_counter() - t1
        total = time.perf_counter() - t0
        t2 = time.perf_counter()
        mtc = MTCModel(system, mesh_n=n, tendon_elements=3)
        t3 = time.perf_counter()
        rm = mtc.solve_static(sequence=sequence_of(n, None))
        t4 = time.perf_counter()
        mm = mtc.modes(rm.x, k=12)
        t5 = time.perf_counter()
        its = f"{res.predictor_iterations}+{res.iterations}"
        print(f"4x{n}x{n:<4d} | {m.ndof:8d} {tb:6.2f} {its:>6s} {res.time:7.2f} {tm:6.2f} {total:6.2f} "
              f"{modes.freq_hz[0]:8.4f} | {mtc.ndof:8d} {t4 - t3:7.2f} {t5 - t4:6.2f} {t5 - t2:6.2f} "
              f"{mm.freq_hz[0]:8.4f} | {total / (t5 - t2):5.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
