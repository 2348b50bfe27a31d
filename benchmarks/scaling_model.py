"""Scaling model of the PETSc backend: time and memory per rank predicted for 16-64 ranks at 5-20 M dofs.

    .venv/bin/python benchmarks/scaling_model.py [--meshes 40,80] [--ranks 1,2]
        [--dofs 5e6,1e7,2e7] [--predict-ranks 16,32,64] [--json]

It runs the 1-4 MTC problem (static from the undeformed membrane with mesh sequencing, then 12
modes; ``bench_backends.py``'s ``petsc`` runs, each in a fresh ``mpiexec -n P`` job with one
BLAS thread) on two meshes and the given rank counts, and fits, per phase, the cost per rank

    q(n, P) = q_1(n_b) (n / n_b)^e / P^s,

with n the free dofs, n_b the larger measured mesh, q_1 the CPU seconds of the phase on one
rank, e the growth exponent from the two meshes on one rank (1 for work per element,
~1.2-1.5 for the sparse factorisation), and s the division exponent: the share of the
phase's work that the busiest of P_m ranks does, w_max / w_total = P_m^-s, measured at n_b
on the largest rank count P_m (s = 1: the work divides evenly; s = 0: one rank does it all).
The phases: ``model`` (element kernels and assembly) and ``patterns`` (the sparsity-pattern
set-up, once per mesh): the membrane elements split evenly over the ranks, s = 1;
``factor`` (the MUMPS factorisations of the static solve): w = MUMPS' elimination flops
(RINFO(3) of the busiest rank, RINFOG(3) in all); ``solve`` (its triangular solves) and
``eigen`` (12 modes: one factorisation of K - sigma M and ~50 shift-invert solves, which
dominate): w = the factor entries each rank reads (INFO(9), INFOG(9)). The work shares are
independent of the machine's load, which a 2-core machine shared with other jobs makes the
times of 2 ranks useless for; the time model is therefore a *work-balance bound*: the
communication and the parallel efficiency of MUMPS' dense kernels come on top (on this
machine a second rank sped up the factorisation 1.2-1.5x where the work balance allows
2^s; ``mumps_scaling.py``).

Memory per rank (peak resident set): M(n, P) = M_0 + R(n) + D(n) / P^s_D, with M_0 the
start-up of a rank (Python, numpy, PETSc, MPI), R the part every rank holds whole (the state
vectors, the gathered eigenvectors: O(n) per rank) and D the part that divides (matrices,
factors, element arrays): with M_1 and M_Pm the 1- and P_m-rank peaks less M_0,
R = (P_m M_Pm - M_1) / (P_m - 1) and D = M_1 - R (D taken to divide as 1/P), each
extrapolated in n with its own exponent from the two meshes. The measured peaks fall in the
static solve; the modes add, on every rank, the k = 12 eigenvectors gathered whole and one
product with them (``tmfem.solvers.eigen.lowest_modes``): E = 2 x 8 n k bytes, which the
prediction adds (M_0 + R + D / P + E: at the measured sizes E is 15 MB, at 20 M dofs 3.7 GB,
more than all the rest on 64 ranks). The memory is that of the
backend as the CLI runs it (SNES; ``bench_memory_ranks.py``), the times those of
``bench_backends.py`` (the same SNES path, its factorisations and solves timed by PETSc's
event log).

A model from two ranks on one machine predicts 64 ranks on a cluster only as far as its
division exponents carry over: run it on the cluster with ``--ranks 1,4,16`` (the largest
count sets s) to measure them there. The prediction table prints which phase stops scaling
first (the smallest s: its share of the time grows with P).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

PHASES = ("model", "patterns", "factor", "solve", "eigen")

#: modes of the benchmark; their vectors are held whole on every rank, two copies at the peak
K_MODES = 12


def phase_costs(row: dict) -> dict:
    """CPU seconds of rank 0 by phase (module docstring) of one ``bench_backends`` row."""
    c = row["cpu_phases"]
    return {"model": c["model"] + c["build"] + c["interp"], "patterns": c["patterns"],
            "factor": row["static_cpu_factor_s"], "solve": row["static_cpu_solve_s"],
            "eigen": row["cpu_eigen_s"]}


def run_rows(meshes, ranks, args) -> list:
    """The ``bench_backends`` rows (fresh jobs) of every mesh and rank count, each with the
    peak and start-up memory per rank of a ``bench_memory_ranks`` run (the SNES path of the
    backend as the CLI runs it)."""
    import bench_backends
    import bench_memory_ranks
    opts = argparse.Namespace(rest_length=args.rest_length, sequence=args.sequence, mpi_yield=False)
    rows = []
    for mesh in meshes:
        for p in ranks:
            row = bench_backends.launch(mesh, "petsc" if p == 1 else f"petsc{p}", opts)
            mem = bench_memory_ranks.launch(mesh, p, opts)
            for r in (row, mem):
                if "error" in r:
                    raise SystemExit(f"4x{mesh}x{mesh} on {p} rank(s): {r['error']}")
            row["costs"] = phase_costs(row)
            row["peak_mb"] = max(r["peak_mb"]["modes"] for r in mem["per_rank"])
            row["start_mb"] = max(r["rss_mb"]["start"] for r in mem["per_rank"])
            rows.append(row)
    return rows


def fit(rows: list) -> dict:
    """Growth exponents e, division exponents s and the reference values at the larger mesh
    (module docstring)."""
    one = sorted((r for r in rows if r["ranks"] == 1), key=lambda r: r["dofs"])
    a, b = one[0], one[-1]
    pm = max(r["ranks"] for r in rows)
    bp = next(r for r in rows if r["ranks"] == pm and r["dofs"] == b["dofs"])
    lg = math.log(b["dofs"] / a["dofs"])
    out = {"n_a": a["dofs"], "n_b": b["dofs"], "P_m": pm, "phases": {}}
    w = bp["mumps"]

    def division(total, busiest):
        return min(1.0, max(0.0, math.log(total / busiest) / math.log(pm))) if pm > 1 else 1.0
    s_factor = division(w["flops_total"], w["flops"])
    s_solve = division(w["entries_total"], w["entries"])
    out["mumps"] = dict(w, s_factor=s_factor, s_solve=s_solve)
    for ph in PHASES:
        qa, qb = a["costs"][ph], b["costs"][ph]
        e = math.log(qb / qa) / lg if qa > 0 and qb > 0 else 1.0
        s = {"factor": s_factor, "solve": s_solve, "eigen": s_solve}.get(ph, 1.0)
        out["phases"][ph] = dict(q_a=qa, q_b=qb, e=e, s=s)
    m0 = b["start_mb"]
    # peaks: R + D + M0 on one rank, R + D / Pm + M0 on Pm ranks (per rank)
    mem = {}
    for r1 in (a, b):
        rp = next((r for r in rows if r["ranks"] == pm and r["dofs"] == r1["dofs"]), None)
        m1 = r1["peak_mb"] - m0
        mp = (rp["peak_mb"] if rp else r1["peak_mb"]) - m0
        R = max(0.0, (pm * mp - m1) / (pm - 1)) if pm > 1 else 0.0
        mem[r1["dofs"]] = dict(R=R, D=max(m1 - R, 1e-9), M1=r1["peak_mb"], MP=mp + m0)
    ma, mb = mem[a["dofs"]], mem[b["dofs"]]
    out["memory"] = dict(M0=m0, R_b=mb["R"], D_b=mb["D"],
                         e_R=math.log(max(mb["R"], 1e-9) / max(ma["R"], 1e-9)) / lg if ma["R"] > 0 else 1.0,
                         e_D=math.log(mb["D"] / ma["D"]) / lg, ratio=mb["MP"] / mb["M1"])
    return out


def predict(model: dict, n: float, P: int) -> dict:
    """Time by phase [s], total, and memory per rank [MB] at n dofs on P ranks (the
    eigenvectors E of the modes included in what every rank holds whole)."""
    nb = model["n_b"]
    t = {ph: f["q_b"] * (n / nb) ** f["e"] / P ** f["s"] for ph, f in model["phases"].items()}
    m = model["memory"]
    R = m["R_b"] * (n / nb) ** m["e_R"]
    D = m["D_b"] * (n / nb) ** m["e_D"] / P
    E = 2 * 8 * n * K_MODES / 2**20
    return dict(time=t, total=sum(t.values()), mem_mb=m["M0"] + R + D + E, replicated_mb=R + E,
                divided_mb=D, eigenvectors_mb=E)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="40,80", help="n of the two 4xnxn meshes measured")
    ap.add_argument("--ranks", default="1,2", help="rank counts measured (1 first)")
    ap.add_argument("--dofs", default="5e6,1e7,2e7", help="dofs of the prediction")
    ap.add_argument("--predict-ranks", default="16,32,64", help="ranks of the prediction")
    ap.add_argument("--rest-length", type=float, default=1.5025)
    ap.add_argument("--sequence", type=int, default=10)
    ap.add_argument("--json", action="store_true", help="the fit and the prediction as JSON")
    args = ap.parse_args(argv)
    meshes = [int(v) for v in args.meshes.split(",")]
    ranks = [int(v) for v in args.ranks.split(",")]
    if len(meshes) != 2 or ranks[0] != 1:
        raise SystemExit("--meshes: two meshes; --ranks: 1 first")
    rows = run_rows(meshes, ranks, args)
    model = fit(rows)
    table = [dict(dofs=float(n), ranks=p, **predict(model, float(n), p))
             for n in (float(v) for v in args.dofs.split(","))
             for p in (int(v) for v in args.predict_ranks.split(","))]
    if args.json:
        print(json.dumps(dict(fit=model, prediction=table)))
        return 0
    print(f"# 1-4 MTC static (mesh sequencing) + 12 modes, PETSc backend; {os.cpu_count()} cpus, "
          f"load average {os.getloadavg()[0]:.2f}; CPU s of rank 0")
    print(f"# measured: {model['n_a']} and {model['n_b']} dofs on 1 rank, {model['n_b']} on "
          f"{model['P_m']} ranks")
    print(f"{'phase':>9s} {'s @ n_a':>9s} {'s @ n_b':>9s} {'e (n^e)':>8s} {'s (P^-s)':>9s}")
    for ph, f in model["phases"].items():
        print(f"{ph:>9s} {f['q_a']:9.3f} {f['q_b']:9.3f} {f['e']:8.2f} {f['s']:9.2f}")
    w = model["mumps"]
    print(f"# MUMPS on {model['P_m']} ranks at n_b: busiest rank {w['flops'] / w['flops_total']:.2f} of the "
          f"flops, {w['entries'] / w['entries_total']:.2f} of the factor entries "
          f"({w['entries_total'] / 1e6:.1f} M)")
    m = model["memory"]
    print(f"# memory at n_b: start-up {m['M0']:.0f} MB, whole on every rank {m['R_b']:.0f} MB "
          f"(~n^{m['e_R']:.2f}), divided {m['D_b']:.0f} MB (~n^{m['e_D']:.2f}); "
          f"{model['P_m']}-rank / 1-rank peak {m['ratio']:.2f}")
    print(f"\n{'dofs':>8s} {'P':>3s} " + " ".join(f"{ph + ' s':>10s}" for ph in PHASES)
          + f" {'total s':>9s} {'MB/rank':>8s} {'whole MB':>9s} {'of it E':>8s}")
    for r in table:
        print(f"{r['dofs']:8.2g} {r['ranks']:3d} " + " ".join(f"{r['time'][ph]:10.1f}" for ph in PHASES)
              + f" {r['total']:9.1f} {r['mem_mb']:8.0f} {r['replicated_mb']:9.0f}"
              + f" {r['eigenvectors_mb']:8.0f}")
    worst = min(model["phases"], key=lambda ph: model["phases"][ph]["s"])
    print(f"# stops scaling first: {worst} (s = {model['phases'][worst]['s']:.2f}); the memory every "
          f"rank holds whole grows as n^{m['e_R']:.2f} whatever P; times are a work-balance bound "
          f"(communication comes on top)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
