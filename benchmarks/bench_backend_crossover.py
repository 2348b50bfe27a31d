"""Where the PETSc backend overtakes scipy: 1-4 MTC static + 12 modes, both backends.

    .venv/bin/python benchmarks/bench_backend_crossover.py [--meshes 5,10,20,40] [--rounds 2]

For each membrane mesh 4 x n x n, a fresh process per run (so that PETSc's initialisation is
part of the PETSc time, as in a CLI call) builds the MTC model of the 1-4 system, solves the
static equilibrium from the undeformed membrane and computes 12 modes, once with
``backend="scipy"`` and once with ``backend="petsc"``, alternating ``--rounds`` times (the
machine's load drifts: compare runs made side by side). Prints per mesh the free dofs and the
best total time of each backend (build + static + modes, the import of tmfem excluded), and
the crossover: the smallest mesh from which PETSc was faster, with the dof count that
``tmfem.solvers.backends.AUTO_CROSSOVER_DOFS`` should be near. OPENBLAS_NUM_THREADS=1.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

HERE = os.path.abspath(__file__)


def run_one(mesh: int, backend: str) -> dict:
    """One static solve + 12 modes in this process: dofs and seconds per phase."""
    t0 = time.perf_counter()
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    m = MTCModel(load_preset("1-4"), mesh_n=mesh, backend=backend)
    t1 = time.perf_counter()
    st = m.equilibrium()
    t2 = time.perf_counter()
    m.modes(k=12, at=st)
    t3 = time.perf_counter()
    return dict(dofs=m.ndof, build_s=t1 - t0, static_s=t2 - t1, eigen_s=t3 - t2, total_s=t3 - t0)


def launch(mesh: int, backend: str) -> dict:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    p = subprocess.run([sys.executable, HERE, "--run", str(mesh), backend], capture_output=True,
                       text=True, env=env)
    if p.returncode != 0:
        raise SystemExit(f"mesh {mesh} {backend}: {p.stderr.strip().splitlines()[-1:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="5,10,20,40")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--run", nargs=2, metavar=("MESH", "BACKEND"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.run:
        print(json.dumps(run_one(int(args.run[0]), args.run[1])))
        return 0
    print(f"# 1-4 MTC, static from the undeformed membrane + 12 modes; best of {args.rounds} "
          f"alternating runs; load average {os.getloadavg()[0]:.2f}")
    print(f"{'mesh':>10s} {'dofs':>7s} {'scipy s':>8s} {'petsc s':>8s} {'petsc build s':>14s} "
          f"{'scipy build s':>14s} faster")
    crossover = None
    for mesh in [int(v) for v in args.meshes.split(",")]:
        best = {}
        for _ in range(args.rounds):
            for backend in ("scipy", "petsc"):
                row = launch(mesh, backend)
                if backend not in best or row["total_s"] < best[backend]["total_s"]:
                    best[backend] = row
        s, p = best["scipy"], best["petsc"]
        faster = "petsc" if p["total_s"] < s["total_s"] else "scipy"
        if faster == "petsc" and crossover is None:
            crossover = (mesh, s["dofs"])
        print(f"{'4x%dx%d' % (mesh, mesh):>10s} {s['dofs']:7d} {s['total_s']:8.2f} {p['total_s']:8.2f} "
              f"{p['build_s']:14.2f} {s['build_s']:14.2f} {faster}", flush=True)
    if crossover is None:
        print("crossover: scipy was faster at every mesh measured")
    else:
        print(f"crossover: PETSc faster from 4x{crossover[0]}x{crossover[0]} ({crossover[1]} free dofs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
