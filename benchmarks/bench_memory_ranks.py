"""Memory per rank: 1-4 MTC static + 12 modes with the PETSc backend on 1 and 2 ranks.

    .venv/bin/python benchmarks/bench_memory_ranks.py [--meshes 80,160] [--ranks 1,2]

Each rank count runs in a fresh job (``mpiexec --allow-run-as-root --oversubscribe -n P``,
OPENBLAS_NUM_THREADS=1), so that the peak resident memory is that of the run. Printed per run:
free DOFs, wall time per phase (build: the model and its mesh; static: the equilibrium from
the undeformed membrane with mesh sequencing; modes: 12 modes about it), and for every rank
its resident memory (VmRSS of /proc/self/status) after start-up (Python, numpy, PETSc, MPI
loaded) and after each phase, its peak (``ru_maxrss``) and MUMPS' own memory for the
factorisation of the statics on the rank (INFO(22) effectively used, INFO(16) allocated).
Last: the ratio of the largest 2-rank (P-rank) peak to the 1-rank peak on the same mesh (a
model whose memory divides over ranks gives about 1/P plus the start-up's share; target for
2 ranks: at most 0.6), and the ratio that the start-up and MUMPS alone leave
(:func:`floor_ratio`: everything else divided exactly), which bounds what tmfem's own data
can reach.

``--petsc-memory`` runs every job a second time with PETSc's ``-memory_view -malloc_debug``
and prints the largest memory PETSc itself allocated on a rank (``PetscMalloc``: matrices,
vectors, the KSP, SNES and EPS objects and PETSc's copies of the matrices for MUMPS; not
MUMPS' own factor and work space, not numpy's arrays): PETSc's share of the peak and how it
divides; and the ratio the run would have if all of tmfem's own memory divided exactly, the
libraries' parts as measured (:func:`model_ratio`): the lowest that a change of tmfem's data
structures could reach. (Debug allocation changes the resident memory and the time, so the
first run's figures stand alone.)
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import time

HERE = os.path.abspath(__file__)
sys.path.insert(0, os.path.dirname(HERE))

PHASES = ("start", "build", "static", "modes")


def status_mb(key: str = "VmRSS") -> float:
    """A memory figure of this process from /proc/self/status [MB]: ``VmRSS`` (resident),
    ``RssFile`` (its file-backed part: pages of the shared libraries and modules loaded)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def vm_rss_mb() -> float:
    """Current resident memory of this process [MB] (VmRSS of /proc/self/status)."""
    return status_mb("VmRSS")


def peak_rss_mb() -> float:
    """Peak resident memory of this process so far [MB] (ru_maxrss, KiB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def run_one(mesh: int, rest_length: float, sequence: int) -> dict:
    """One run in this process (every rank); rank 0 returns the rows of all ranks."""
    from bench_backends import system_1_4
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.distributed import comm_world
    from tmfem.solvers.petsc import PetscBackend
    comm = comm_world()
    rss, peak, wall = {"start": vm_rss_mb()}, {"start": peak_rss_mb()}, {}
    files = status_mb("RssFile")
    system = system_1_4(rest_length)

    def phase(name, t0):
        wall[name] = time.perf_counter() - t0
        rss[name], peak[name] = vm_rss_mb(), peak_rss_mb()

    t = time.perf_counter()
    m = MTCModel(system, mesh_n=mesh, tendon_elements=3, backend=PetscBackend())
    phase("build", t)
    t = time.perf_counter()
    res = m.equilibrium(sequence=sequence or None)
    phase("static", t)
    mumps = m.backend.factor_memory_mb()
    t = time.perf_counter()
    modes = m.modes(k=12, at=res)
    phase("modes", t)
    mine = dict(rank=comm.rank, rss_mb=rss, peak_mb=peak, wall_s=wall, mumps_mb=mumps,
                libraries_mb=status_mb("RssFile") - files)
    ranks = comm.gather(mine, root=0)
    return dict(mesh=f"4x{mesh}x{mesh}", n=mesh, ranks=comm.size, dofs=m.ndof,
                f1_hz=float(modes.freq_hz[0]), per_rank=ranks)


def divided_ratio(run: dict, ref: dict, fixed) -> tuple[int, float]:
    """(P, bound) of a P-rank run against the reference (1-rank) run: its busiest rank's peak
    if all but ``fixed(run)`` [MB] (what a rank holds whatever the rank count) divided
    exactly over the ranks,

        bound = (fixed_P + (peak_1 - fixed_1) / P) / peak_1."""
    peak_1 = ref["per_rank"][0]["peak_mb"]["modes"]
    P = run["ranks"]
    return P, (fixed(run) + (peak_1 - fixed(ref)) / P) / peak_1


def floor_ratio(run: dict, ref: dict) -> tuple[int, float]:
    """:func:`divided_ratio` with fixed = start + mumps: the start-up's resident memory
    (Python, numpy, PETSc, MPI: on every rank; the busiest rank's) and MUMPS' memory
    effectively used (INFO(22), its busiest rank): what the start-up and MUMPS' own
    parallel overhead alone leave of the ratio."""
    def fixed(run):
        busiest = max(run["per_rank"], key=lambda r: r["peak_mb"]["modes"])
        return busiest["rss_mb"]["start"] + max(r["mumps_mb"]["used"] for r in run["per_rank"])
    return divided_ratio(run, ref, fixed)


def model_ratio(run: dict, ref: dict) -> tuple[int, float]:
    """:func:`divided_ratio` of runs with PETSc's memory measured (``--petsc-memory``), with
    fixed = start + libraries + mumps + petsc: the busiest rank's peak if all of tmfem's own
    memory (numpy arrays, the heap it leaves) divided exactly over the ranks and the
    libraries' parts stayed as measured; libraries the file-backed pages loaded after
    start-up (RssFile's growth: MUMPS', SLEPc's code, the same on every rank), mumps MUMPS'
    memory effectively used (INFO(22)) and petsc PETSc's own (``PetscMalloc``, largest over
    the job), busiest ranks: the lowest ratio that any change of tmfem's own data
    structures could reach (each part's largest over the run, so an estimate)."""
    def fixed(run):
        rows = run["per_rank"]
        return (max(r["rss_mb"]["start"] + r["libraries_mb"] for r in rows)
                + max(r["mumps_mb"]["used"] for r in rows) + run["petsc_malloc_mb"]["max"])
    return divided_ratio(run, ref, fixed)


#: PETSc's options of the ``--petsc-memory`` runs: its memory summary at the end of the job,
#: with PetscMalloc's usage tracked
PETSC_MEMORY_OPTIONS = "-memory_view -malloc_debug"


def petsc_malloc_mb(stdout: str) -> dict | None:
    """The largest memory PETSc allocated (``PetscMalloc``) on the busiest and on the least
    busy rank over the job [MB], from ``-memory_view``'s summary on ``stdout``; None when
    the summary has no such line (tracking off)."""
    for line in stdout.splitlines():
        if line.startswith("Maximum (over computational time) space PetscMalloc()ed:"):
            words = line.split()
            return {"max": float(words[words.index("max") + 1]) / 2**20,
                    "min": float(words[words.index("min") + 1]) / 2**20}
    return None


def launch(mesh: int, ranks: int, args, *, petsc_memory: bool = False) -> dict:
    """One job of ``ranks`` ranks on the 4 x mesh x mesh membrane: its result (:func:`run_one`),
    or ``{"error": ...}``; with ``petsc_memory`` run under :data:`PETSC_MEMORY_OPTIONS`,
    ``{"petsc_malloc_mb": ...}`` of :func:`petsc_malloc_mb` only."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "ORTE_")) or "ALLOW_RUN_AS_ROOT" in k}
    env["OPENBLAS_NUM_THREADS"] = "1"
    if petsc_memory:
        env["PETSC_OPTIONS"] = f"{env.get('PETSC_OPTIONS', '')} {PETSC_MEMORY_OPTIONS}".strip()
    cmd = [shutil.which("mpiexec"), "--allow-run-as-root", "--oversubscribe", "-n", str(ranks),
           sys.executable, HERE, "--run", str(mesh), "--rest-length", str(args.rest_length),
           "--sequence", str(args.sequence)]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        return dict(mesh=f"4x{mesh}x{mesh}", ranks=ranks,
                    error=(p.stderr.strip().splitlines() or ["exit %d" % p.returncode])[-1])
    if petsc_memory:
        return {"petsc_malloc_mb": petsc_malloc_mb(p.stdout)}
    return json.loads(next(line for line in p.stdout.splitlines() if line.startswith("{")))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="80,160", help="n of the 4xnxn membrane meshes")
    ap.add_argument("--ranks", default="1,2", help="rank counts (the first one is the reference)")
    ap.add_argument("--rest-length", type=float, default=1.5025,
                    help="rest length of the S tendons [m] (the value Tables 6.3/6.6 imply)")
    ap.add_argument("--sequence", type=int, default=10, help="coarsest mesh of the mesh sequencing")
    ap.add_argument("--run", type=int, metavar="MESH", help=argparse.SUPPRESS)
    ap.add_argument("--petsc-memory", action="store_true",
                    help="run every job again under PETSc's -memory_view -malloc_debug and print "
                         "the largest memory PETSc allocated per rank")
    ap.add_argument("--json", action="store_true", help="one JSON document of all runs")
    args = ap.parse_args(argv)
    if args.run:
        from tmfem.cli import rank_report
        from tmfem.solvers.distributed import mpi_main
        return mpi_main(lambda: json.dumps(run_one(args.run, args.rest_length, args.sequence)),
                        report=rank_report())
    rank_counts = [int(v) for v in args.ranks.split(",")]
    runs = []
    if not args.json:
        print(f"# 1-4 MTC static + 12 modes, --backend petsc; {os.cpu_count()} cpus, "
              f"load average {os.getloadavg()[0]:.2f}")
        print("# memory: VmRSS [MB] after start-up / build / static / modes, and peak (ru_maxrss);"
              " time: wall s per phase (rank 0)")
        print("# mumps: MUMPS' memory of the statics' factorisation on the rank [MB], effectively "
              "used / allocated (INFO(22) / INFO(16))")
        print(f"{'mesh':>11s} {'dofs':>8s} {'P':>2s} {'rank':>4s} "
              + " ".join(f"{p:>7s}" for p in PHASES) + f" {'peak':>7s} {'mumps':>9s} "
              + " ".join(f"{p + ' s':>8s}" for p in PHASES[1:]))
    for mesh in [int(v) for v in args.meshes.split(",")]:
        ref, ref_run = None, None
        for ranks in rank_counts:
            run = launch(mesh, ranks, args)
            runs.append(run)
            if args.petsc_memory and "error" not in run:
                tracked = launch(mesh, ranks, args, petsc_memory=True)
                if "error" in tracked:
                    tracked["error"] = f"the {PETSC_MEMORY_OPTIONS} run: {tracked['error']}"
                run.update(tracked)
            if "error" in run:
                if not args.json:
                    print(f"4x{mesh}x{mesh}".rjust(11) + f" P={ranks} error: {run['error']}",
                          flush=True)
                continue
            peak = max(r["peak_mb"]["modes"] for r in run["per_rank"])
            run["peak_mb"] = peak
            if ref is None:
                ref, ref_run = peak, run
            run["ratio"] = peak / ref
            if args.json:
                continue
            w = run["per_rank"][0]["wall_s"]
            for r in run["per_rank"]:
                print(f"{run['mesh']:>11s} {run['dofs']:8d} {ranks:2d} {r['rank']:4d} "
                      + " ".join(f"{r['rss_mb'][p]:7.0f}" for p in PHASES)
                      + f" {r['peak_mb']['modes']:7.0f} "
                      + f"{r['mumps_mb']['used']:4.0f}/{r['mumps_mb']['allocated']:<4.0f} "
                      + " ".join(f"{w[p]:8.2f}" for p in PHASES[1:]), flush=True)
        if not args.json:
            ratios = ", ".join(f"P={r['ranks']}: {r['ratio']:.2f}" for r in runs
                               if r.get("mesh") == f"4x{mesh}x{mesh}" and "ratio" in r)
            print(f"# 4x{mesh}x{mesh}: peak per rank / {rank_counts[0]}-rank peak: {ratios}",
                  flush=True)
            bounds = [floor_ratio(r, ref_run) for r in runs if r.get("mesh") == f"4x{mesh}x{mesh}"
                      and "ratio" in r and r is not ref_run]
            if bounds:
                print(f"# 4x{mesh}x{mesh}: the ratio if all but the start-up and MUMPS divided exactly "
                      "over the ranks: " + ", ".join(f"P={p}: {b:.2f}" for p, b in bounds), flush=True)
            petsc = [(r["ranks"], r["petsc_malloc_mb"]) for r in runs if r.get("mesh") == f"4x{mesh}x{mesh}"
                     and r.get("petsc_malloc_mb")]
            if petsc and ref_run.get("petsc_malloc_mb"):
                bounds = [model_ratio(r, ref_run) for r in runs if r.get("mesh") == f"4x{mesh}x{mesh}"
                          and r.get("petsc_malloc_mb") and r is not ref_run]
                libraries = max(r["libraries_mb"] for r in ref_run["per_rank"])
                print(f"# 4x{mesh}x{mesh}: the ratio if all of tmfem's own memory divided exactly "
                      f"(start-up, libraries loaded after it ({libraries:.0f} MB on 1 rank), MUMPS "
                      "and PETSc as measured): "
                      + ", ".join(f"P={p}: {b:.3f}" for p, b in bounds), flush=True)
            if petsc:
                one = petsc[0][1]["max"]
                print(f"# 4x{mesh}x{mesh}: PETSc's own memory (PetscMalloc, largest over the job, "
                      f"{PETSC_MEMORY_OPTIONS} runs), busiest / least busy rank: "
                      + ", ".join(f"P={p}: {m['max']:.0f} / {m['min']:.0f} MB ({m['max'] / one:.2f})"
                                  for p, m in petsc), flush=True)
    if args.json:
        print(json.dumps(runs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
