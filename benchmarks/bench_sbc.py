"""Speed of the SBC model: static + 12 modes of the 1-4 system at growing membrane meshes.

    .venv/bin/python benchmarks/bench_sbc.py [--meshes 10,20,40] [--predictor mtc|none] [--repeat 3]

For each mesh 4 x n x n prints the SBC model's free DOFs, build time, iterations (MTC
predictor + SBC Newton, or the SBC trust-region iteration alone from the undeformed
membrane with ``--predictor none``), static time, modal time (12 modes, shift-invert) and
their sum beside the MTC model's free DOFs, static and modal times (its default mesh
sequencing) on the same mesh, and the ratio of the totals (build included in both);
``--repeat N`` alternates N runs of both models and reports the best time of each.
Targets: the paper's mesh (4 x 10 x 10) under 2 s beyond import; no worse than 3x the MTC model.
"""
from __future__ import annotations

import argparse
import os
import time


def run_sbc(SBCModel, system, n, predictor):
    """(dofs, build, iterations, static, modal, total [s], f1 [Hz]) of the SBC model."""
    t0 = time.perf_counter()
    m = SBCModel(system, mesh_n=n, tendon_elements=3)
    tb = time.perf_counter() - t0
    res = m.equilibrium(predictor=predictor)
    t1 = time.perf_counter()
    modes = m.modes(k=12, at=res)
    t2 = time.perf_counter()
    return (m.ndof, tb, f"{res.predictor_iterations}+{res.iterations}", t1 - t0 - tb, t2 - t1,
            t2 - t0, float(modes.freq_hz[0]))


def run_mtc(MTCModel, system, n, sequence_of):
    """(dofs, static, modal, total [s], f1 [Hz]) of the MTC model (build in the total)."""
    t0 = time.perf_counter()
    mtc = MTCModel(system, mesh_n=n, tendon_elements=3)
    t1 = time.perf_counter()
    rm = mtc.equilibrium(sequence=sequence_of(n, None))
    t2 = time.perf_counter()
    mm = mtc.modes(k=12, at=rm.x)
    t3 = time.perf_counter()
    return mtc.ndof, t2 - t1, t3 - t2, t3 - t0, float(mm.freq_hz[0])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="10,20,40")
    ap.add_argument("--rest-length", type=float, default=1.5025,
                    help="rest length of the S tendons [m] (default: the value Tables 6.3/6.6 imply)")
    ap.add_argument("--predictor", default="mtc", choices=("mtc", "none"))
    ap.add_argument("--repeat", type=int, default=1,
                    help="runs per mesh; every time is the best of them (a shared machine's load)")
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
        best = None
        for _ in range(args.repeat):
            # alternate the two models so that both see the same load on a shared machine
            row = (*run_sbc(SBCModel, system, n, args.predictor), *run_mtc(MTCModel, system, n, sequence_of))
            best = row if best is None else tuple(min(a, b) if isinstance(a, float) else a
                                                  for a, b in zip(best, row))
        dofs, tb, its, ts, tm, total, f1, mdofs, mts, mtm, mtotal, mf1 = best
        print(f"4x{n}x{n:<4d} | {dofs:8d} {tb:6.2f} {its:>6s} {ts:7.2f} {tm:6.2f} {total:6.2f} "
              f"{f1:8.4f} | {mdofs:8d} {mts:7.2f} {mtm:6.2f} {mtotal:6.2f} {mf1:8.4f} | "
              f"{total / mtotal:5.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
