"""Backends at scale: 1-4 MTC static (from the undeformed membrane) + 12 modes, scipy vs PETSc.

    .venv/bin/python benchmarks/bench_backends.py [--meshes 40,80,160] [--configs scipy,petsc,petsc2]

Configurations (each run in a fresh process, so that peak memory is per run):
  scipy    the embedded backend (SuperLU symmetric mode with nested dissection, ARPACK)
  petsc    PETSc/SLEPc on 1 rank (MUMPS Cholesky; eigen: SLEPc Krylov-Schur
           shift-invert); the model assembles through tmfem.fem.distributed (one rank:
           all elements)
  petsc2   the same under ``mpiexec -n 2``: each rank evaluates and assembles half of the
           membrane elements into one parallel matrix; MUMPS on both ranks; eigen: SLEPc
           on the parallel factors (``petscP``: P ranks)
Each configuration runs the path ``--backend`` runs: the scipy backend's statics are tmfem's
trust-region Newton on its factorisations (timed by a wrapper), the PETSc configurations'
are PETSc's SNES (:mod:`tmfem.solvers.petsc_snes`), whose factorisations and solves are
timed by PETSc's event log (wall time, also in the CPU columns).
Columns: free DOFs, iterations of the static solve on the finest mesh, time per iteration
(static time over all iterations, mesh sequencing from n = 10 included), static time, eigen
time, time inside the backend's factorisations (incl. MUMPS/SuperLU analysis; their number)
and solves, CPU time of rank 0 (static + eigen: the wall times of a shared machine grow with
its load, printed in the header and per row), peak resident memory per rank (max over
ranks), first frequency. A second table splits rank 0's static time by phase
(:class:`PhaseTimer`: element kernels and assembly, pattern set-up, interpolation, model
builds, factorisations, solves, the rest: trust-region algebra, MPI waits), a third the PETSc
configurations' eigen time (PETSc's event log: factorisation, shift-invert solves and their
number, orthogonalisation).
OPENBLAS_NUM_THREADS=1 is set for every run (2 threads were slower on 2 cores).
--mpi-yield: petsc2's waiting ranks yield the core (Open MPI ``--mca mpi_yield_when_idle 1``;
helps on a loaded machine: busy-waiting takes the core from the working rank and other jobs).
Targets (one thread): 78k DOF static + 12 modes < 3 s; 1.2 M DOF < 150 s and < 8 GB on one
rank. The memory per rank of 2-rank runs: benchmarks/bench_memory_ranks.py.
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


class TimedBackend:
    """A backend wrapper that adds up the time spent in factorisations and solves."""

    def __init__(self, inner):
        self.inner, self.name = inner, inner.name
        self.distributed_assembly = getattr(inner, "distributed_assembly", False)
        if hasattr(inner, "solve_equilibrium"):       # the SNES statics, as --backend petsc
            self.solve_equilibrium = inner.solve_equilibrium
        self.t_factor = self.t_solve = self.t_eig = 0.0
        self.c_factor = self.c_solve = 0.0          # CPU time of this process
        self.n_factor = 0
        self.mumps = None

    def release_retired(self):
        if hasattr(self.inner, "release_retired"):
            self.inner.release_retired()

    def factorize(self, A):
        t, c = time.perf_counter(), time.process_time()
        solve = self.inner.factorize(A)
        self.t_factor += time.perf_counter() - t
        self.c_factor += time.process_time() - c
        self.n_factor += 1
        self.mumps = mumps_work(self.inner) or self.mumps

        def timed(b):
            t, c = time.perf_counter(), time.process_time()
            x = solve(b)
            self.t_solve += time.perf_counter() - t
            self.c_solve += time.process_time() - c
            return x
        return timed

    def eigsh(self, K, M, k, sigma):
        t = time.perf_counter()
        out = self.inner.eigsh(K, M, k, sigma)
        self.t_eig += time.perf_counter() - t
        return out


def mumps_work(backend) -> dict | None:
    """Work of the last MUMPS factorisation of a PETSc backend: elimination flops and factor
    entries of this rank (RINFO(3), INFO(9)) and of all ranks (RINFOG(3), INFOG(9))."""
    cache = getattr(backend, "_cache", None)
    if not cache:
        return None
    entry = max(cache.values(), key=lambda e: e.serial)
    pc = entry.ksp.getPC()
    if pc.getFactorSolverType() != "mumps":
        return None
    F = pc.getFactorMatrix()

    def count(v):                      # MUMPS: a negative count is in millions
        return float(-v * 1e6 if v < 0 else v)
    return dict(flops=F.getMumpsRinfo(3), flops_total=F.getMumpsRinfog(3),
                entries=count(F.getMumpsInfo(9)), entries_total=count(F.getMumpsInfog(9)))


#: the columns of the second table (rank 0's static time by phase)
PHASES = ("model", "patterns", "interp", "build", "factor", "solve", "rest")

#: PETSc log events of the eigen split (third table): the factorisation of K - sigma M, the
#: shift-invert solves, SLEPc's orthogonalisation of the Krylov basis
EIGEN_EVENTS = {"factor": ("MatCholFctrSym", "MatCholFctrNum", "MatLUFactorSym", "MatLUFactorNum"),
                "numeric": ("MatCholFctrNum", "MatLUFactorNum"),
                "solves": ("MatSolve",), "orthogonalize": ("BVOrthogonalizeV",)}


def petsc_events() -> dict:
    """(count, wall s) of this rank's PETSc log events of :data:`EIGEN_EVENTS` so far."""
    from tmfem.solvers.petsc_loader import petsc_modules
    PETSc, _ = petsc_modules()
    out = {}
    for key, names in EIGEN_EVENTS.items():
        infos = [PETSc.Log.Event(name).getPerfInfo() for name in names]
        out[key] = (sum(i["count"] for i in infos), sum(i["time"] for i in infos))
    return out


class PhaseTimer:
    """CPU and wall time of this process inside the model-side calls of a run, by phase
    (wrapped methods; the calls of a phase do not nest): ``model`` the residual, tangent
    and energy evaluations (element kernels and assembly), ``patterns`` the set-up of the
    assemblers' sparsity patterns (once per mesh, and the mass), ``interp`` the mesh
    sequencing's interpolation, ``build`` the models of the sequencing levels."""

    def __init__(self):
        from tmfem.fem.distributed import DistributedElements
        from tmfem.models.mtc.model import MTCModel
        from tmfem.solvers.distributed import DistributedAssembler
        self.cpu, self.wall = {}, {}
        self._saved = []
        for phase, targets in {"model": [(DistributedElements, "residual"),
                                         (DistributedElements, "energy"),
                                         (MTCModel, "residual"), (MTCModel, "energy")],
                               "patterns": [(DistributedAssembler, "__init__")],
                               "interp": [(MTCModel, "interpolate_from")],
                               "build": [(MTCModel, "__init__")]}.items():
            self.cpu[phase] = self.wall[phase] = 0.0
            for cls, name in targets:
                self._wrap(phase, cls, name)

    def _wrap(self, phase, cls, name):
        inner = getattr(cls, name)
        self._saved.append((cls, name, inner))

        def timed(*a, **k):
            c, t = time.process_time(), time.perf_counter()
            try:
                return inner(*a, **k)
            finally:
                self.cpu[phase] += time.process_time() - c
                self.wall[phase] += time.perf_counter() - t
        setattr(cls, name, timed)


def system_1_4(rest_length: float):
    from tmfem.system import load_preset
    return load_preset("1-4", as_printed=True).with_rest_lengths({"S1": rest_length})


def run_one(mesh: int, config: str, rest_length: float, sequence: int) -> dict:
    """One configuration on one mesh (in this process); rank 0's dict, max memory over ranks."""
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.backends import get_backend
    size, comm = 1, None
    if config != "scipy":
        from tmfem.solvers.distributed import comm_world
        comm = comm_world()
        size = comm.size
    if config == "scipy":
        inner = get_backend("scipy")
    else:
        from tmfem.solvers.petsc import PetscBackend
        inner = PetscBackend()
        inner.PETSc.Log.begin()            # the eigen split (PETSc's own event log)
    be = TimedBackend(inner)
    system = system_1_4(rest_length)
    t0 = time.perf_counter()
    m = MTCModel(system, mesh_n=mesh, tendon_elements=3, backend=be)
    phases = PhaseTimer()
    start = petsc_events() if comm is not None else None
    t1, c1 = time.perf_counter(), time.process_time()
    res = m.equilibrium(sequence=sequence or None)
    t2, c2 = time.perf_counter(), time.process_time()
    cpu_phases, wall_phases = dict(phases.cpu), dict(phases.wall)     # of the static solve
    before = petsc_events() if comm is not None else None
    if before is not None:             # the SNES' factorisations and solves (PETSc's log)
        be.n_factor = before["numeric"][0] - start["numeric"][0]
        be.t_factor = be.c_factor = before["factor"][1] - start["factor"][1]
        be.t_solve = be.c_solve = before["solves"][1] - start["solves"][1]
        be.mumps = mumps_work(inner)
    f_static, c_static, s_static, cs_static = be.t_factor, be.c_factor, be.t_solve, be.c_solve
    modes = m.modes(k=12, at=res)
    t3, c3 = time.perf_counter(), time.process_time()
    eigen_split = None
    if before is not None:
        after = petsc_events()
        eigen_split = {k: (after[k][0] - before[k][0], after[k][1] - before[k][1]) for k in after}
    its = (res.level_iterations or [res.iterations])[-1]
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    mumps = be.mumps
    if comm is not None:
        MAX = __import__("mpi4py").MPI.MAX
        rss = comm.allreduce(rss, op=MAX)
        if mumps is not None:          # the largest rank's share of the work
            mumps = dict(mumps, flops=comm.allreduce(mumps["flops"], op=MAX),
                         entries=comm.allreduce(mumps["entries"], op=MAX))
    return dict(config=config, ranks=size, mesh=f"4x{mesh}x{mesh}", dofs=m.ndof, build_s=t1 - t0,
                iterations=its, total_iterations=res.iterations, s_per_it=(t2 - t1) / res.iterations,
                static_s=t2 - t1, eigen_s=t3 - t2, factor_s=be.t_factor, n_factor=be.n_factor,
                solve_s=be.t_solve, cpu_factor_s=be.c_factor, cpu_solve_s=be.c_solve,
                static_factor_s=f_static, static_cpu_factor_s=c_static, static_solve_s=s_static,
                static_cpu_solve_s=cs_static, cpu_s=c3 - c1, cpu_static_s=c2 - c1,
                cpu_eigen_s=c3 - c2, cpu_phases=cpu_phases, wall_phases=wall_phases, rss_mb=rss,
                f1_hz=float(modes.freq_hz[0]), load=os.getloadavg()[0], mumps=mumps,
                eigen_split=eigen_split)


def launch(mesh: int, config: str, args) -> dict:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "ORTE_")) or "ALLOW_RUN_AS_ROOT" in k}
    env["OPENBLAS_NUM_THREADS"] = "1"
    cmd = [sys.executable, HERE, "--run", str(mesh), config, "--rest-length", str(args.rest_length),
           "--sequence", str(args.sequence)]
    ranks = int(config[5:] or 1) if config.startswith("petsc") else 1     # petscP: P ranks
    if ranks > 1:
        cmd = ([shutil.which("mpiexec"), "--allow-run-as-root", "--oversubscribe", "-n", str(ranks)]
               + (["--mca", "mpi_yield_when_idle", "1"] if args.mpi_yield else []) + cmd)
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        return dict(config=config, mesh=f"4x{mesh}x{mesh}", error=p.stderr.strip().splitlines()[-1:])
    return json.loads(p.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="40,80,160")
    ap.add_argument("--configs", default="scipy,petsc,petsc2")
    ap.add_argument("--rest-length", type=float, default=1.5025,
                    help="rest length of the S tendons [m] (the value Tables 6.3/6.6 imply)")
    ap.add_argument("--sequence", type=int, default=10, help="coarsest mesh of the mesh sequencing")
    ap.add_argument("--mpi-yield", action="store_true",
                    help="petsc2: Open MPI's waiting ranks yield the core (--mca mpi_yield_when_idle 1) "
                         "instead of busy-waiting")
    ap.add_argument("--run", nargs=2, metavar=("MESH", "CONFIG"), help=argparse.SUPPRESS)
    ap.add_argument("--json", action="store_true", help="one JSON document of all rows")
    args = ap.parse_args(argv)
    if args.run:
        from tmfem.cli import rank_report
        from tmfem.solvers.distributed import mpi_main
        if args.run[1] == "scipy":
            print(json.dumps(run_one(int(args.run[0]), "scipy", args.rest_length, args.sequence)))
            return 0
        return mpi_main(lambda: json.dumps(run_one(int(args.run[0]), args.run[1], args.rest_length,
                                                   args.sequence)),
                        report=rank_report())
    rows = []
    if not args.json:
        print(f"# 1-4 MTC, static from the undeformed membrane + 12 modes; {os.cpu_count()} cpus, "
              f"load average {os.getloadavg()[0]:.2f} (wall times grow with it; CPU s is rank 0's)")
        print("# eigen: scipy ARPACK shift-invert; petsc SLEPc Krylov-Schur shift-invert on MUMPS; "
              "petsc2 MPI waiting: "
              + ("yield (--mca mpi_yield_when_idle 1)" if args.mpi_yield else "busy (Open MPI default)"))
        print(f"{'config':>7s} {'mesh':>11s} {'dofs':>8s} {'its':>4s} {'s/it':>7s} {'static s':>9s} "
              f"{'eigen s':>8s} {'factor s':>9s} {'n':>3s} {'solve s':>8s} {'CPU s':>7s} "
              f"{'RSS MB/rank':>11s} {'f1 [Hz]':>9s} load")
    for mesh in [int(v) for v in args.meshes.split(",")]:
        for config in args.configs.split(","):
            row = launch(mesh, config, args)
            rows.append(row)
            if args.json:
                continue
            if "error" in row:
                print(f"{config:>7s} {row['mesh']:>11s}  error: {row['error']}", flush=True)
                continue
            print(f"{config:>7s} {row['mesh']:>11s} {row['dofs']:8d} {row['iterations']:4d} "
                  f"{row['s_per_it']:7.3f} {row['static_s']:9.2f} {row['eigen_s']:8.2f} "
                  f"{row['factor_s']:9.2f} {row['n_factor']:3d} {row['solve_s']:8.2f} "
                  f"{row['cpu_s']:7.2f} {row['rss_mb']:11.0f} {row['f1_hz']:9.6f} "
                  f"{row['load']:.1f}", flush=True)
    if args.json:
        print(json.dumps(rows))
        return 0
    print("\n# where rank 0's time went (wall s; CPU s in brackets): static = model (kernels,"
          " assembly) + patterns + interp + build + factor + solve + rest; eigen")
    print(f"{'config':>7s} {'mesh':>11s} {'static':>16s} "
          + " ".join(f"{p:>15s}" for p in PHASES) + f" {'eigen':>16s}")
    for row in rows:
        if "error" in row:
            continue
        w, c = row["wall_phases"], row["cpu_phases"]
        w = dict(w, factor=row["static_factor_s"], solve=row["static_solve_s"])
        c = dict(c, factor=row["static_cpu_factor_s"], solve=row["static_cpu_solve_s"])
        w["rest"] = row["static_s"] - sum(w.values())
        c["rest"] = row["cpu_static_s"] - sum(c.values())
        print(f"{row['config']:>7s} {row['mesh']:>11s} {row['static_s']:7.2f} ({row['cpu_static_s']:6.2f}) "
              + " ".join(f"{w[p]:6.2f} ({c[p]:6.2f})" for p in PHASES)
              + f" {row['eigen_s']:7.2f} ({row['cpu_eigen_s']:6.2f})")
    split = [row for row in rows if row.get("eigen_split")]
    if split:
        print("\n# rank 0's eigen time (wall s) in PETSc's event log: the factorisation of K - sigma M,"
              " the shift-invert solves (their number), SLEPc's orthogonalisation; rest: Rayleigh-Ritz,"
              " gathers, set-up")
        print(f"{'config':>7s} {'mesh':>11s} {'eigen':>7s} {'factor':>7s} {'solves':>7s} {'n':>4s} "
              f"{'orthog':>7s} {'rest':>7s}")
        for row in split:
            e = row["eigen_split"]
            rest = row["eigen_s"] - e["factor"][1] - e["solves"][1] - e["orthogonalize"][1]
            print(f"{row['config']:>7s} {row['mesh']:>11s} {row['eigen_s']:7.2f} {e['factor'][1]:7.2f} "
                  f"{e['solves'][1]:7.2f} {e['solves'][0]:4d} {e['orthogonalize'][1]:7.2f} {rest:7.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
