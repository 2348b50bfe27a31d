"""tmfem beside Kratos Multiphysics: the same 1-4 MTC problem, static + 12 modes, one thread each.

    .venv/bin/python benchmarks/bench_kratos.py [--meshes 10,20,40,80] [--rounds 1]
        [--kratos-python PATH] [--programs scipy,petsc,kratos] [--sequence N]

The problem: ``MTCModel(load_preset("1-4"), mesh_n=n)``, the static equilibrium from the
undeformed membrane (flat, unstressed; the tendon rest lengths pull the system into shape),
then the 12 lowest modes about it. The Kratos model is written from the tmfem model's own
arrays (:func:`export_model`): the same nodes (the bar tops *are* the membrane corners), the
same free dofs (the bar bases pinned), membrane ``MembraneElement3D4N`` (2 x 2 Gauss,
consistent mass, ``LinearElasticPlaneStress2DLaw``: plane-stress St.Venant-Kirchhoff, as
tmfem's), bars ``TrussElement3D2N``, tendon elements ``CableElement3D2N`` (tension only). No
external load acts (no gravity in either model).

A Kratos truss measures its Green-Lagrange strain from the distance L0 of its nodes in the
initial configuration, tmfem's from the rest length L. Both laws are S = E_mod E with the axial
force N = A S l / L_ref, so a Kratos element with YOUNG_MODULUS E' = EA (L0/L)^3 / A and
TRUSS_PRESTRESS_PK2 S_p = EA L0 (L0^2 - L^2) / (2 A L^3) gives the same force
N(l) = EA l (l^2 - L^2) / (2 L^3) and tangent at every length l, and DENSITY rho A L / (A L0)
the same mass (:func:`kratos_truss_properties`). A cable is slack where N < 0, as a tendon
where l < L.

The start from the undeformed membrane: a flat unstressed membrane has no transverse stiffness,
so Newton's method fails on it (tmfem regularises it with a mass-scaled trust region). Kratos
users prestress the membrane (``PRESTRESS_VECTOR``): the Kratos run solves with an isotropic
membrane prestress ``--membrane-prestress`` (default 10 kPa, between the median minor and major
principal membrane stresses of the equilibrium, about 5 and 50 kPa) that is then stepped down
to zero over ``--prestress-steps`` Newton solves (``ResidualBasedNewtonRaphsonStrategy``, the
fastest direct solver of the installed Kratos, residual criterion), so that the equilibrium reached is that
of the unprestressed model, tmfem's. Modes: ``EigensolverStrategy`` with LinearSolversApplication's
``spectra_sym_g_eigs_shift`` (shift-invert at -1 rad^2/s^2, as tmfem). The frequencies of the
two programs are compared: a ratio of times is printed only where they agree within
``--freq-tol``.

Each run is a fresh process (tmfem with the scipy and with the PETSc backend, then Kratos,
alternating ``--rounds`` times; the best of each is kept), OMP_NUM_THREADS=1 and
OPENBLAS_NUM_THREADS=1. tmfem solves as the CLI does (no mesh sequencing unless ``--sequence``);
a ``*`` marks the backend that ``--backend auto`` (the CLI's default) chooses at that size. The
table prints wall and CPU seconds (a loaded machine stretches the wall times; the load average
is printed per row), the Newton iterations (Kratos: per prestress step), the largest relative
difference of the ``--modes`` frequencies from tmfem's scipy run and the largest difference
of the equilibrium node positions [m]. Times exclude the imports; "build" is the model set-up
(tmfem: mesh and model; Kratos: the ModelPart from the exported arrays). Kratos runs in ``--kratos-python``
(default: this interpreter if it imports KratosMultiphysics); without Kratos only tmfem's
figures are printed.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.abspath(__file__)
KRATOS_PACKAGES = ("KratosMultiphysics==10.4.4 KratosStructuralMechanicsApplication==10.4.4 "
                   "KratosLinearSolversApplication==10.4.4")


# ---------------------------------------------------------------------------- the export
def export_model(model) -> dict:
    """The arrays of a Kratos model of an MTC model: nodes, elements, materials, supports.

    Kratos nodes are tmfem's independent nodes (1-based ids in that order); a bar top B_Mj
    attached to one membrane corner (point attachment) is that corner's node. Returns
    ``coords`` (3, nn) initial positions (the undeformed membrane start), ``quads`` (4, ne)
    membrane node ids, ``membrane`` [E, nu, rho, h], ``truss_conn`` (2, nt) node ids, ``truss_L``
    rest lengths, ``truss_EA``, ``truss_rhoA``, ``truss_cable`` (tension only), ``fixed`` node
    ids (all three translations), ``ndof`` (tmfem's free dofs, for the check).
    """
    from tmfem.errors import InputError
    topo = model.topology
    if topo.attachment != "point":
        raise InputError(f"Kratos export: expected the point attachment, found {topo.attachment!r}")
    node_id = topo.red_node.copy() + 1
    for top, (nodes, w) in zip(topo.top_nodes, topo.weights):
        if len(nodes) != 1 or w[0] != 1.0:
            raise InputError("Kratos export: expected each bar top on one membrane corner")
        node_id[top] = node_id[nodes[0]]
    if np.any(node_id < 1):
        raise InputError("Kratos export: found dependent nodes other than the bar tops")
    x0 = model.initial_positions("undeformed")
    trusses = [model.bars, model.tendons]
    mat = model.system.membrane
    return dict(
        coords=x0[:, topo.red_node >= 0], quads=node_id[topo.mesh.t],
        membrane=np.array([mat.E, mat.nu, mat.rho, mat.h]),
        truss_conn=np.concatenate([node_id[t.conn] for t in trusses], axis=1),
        truss_L=np.concatenate([t.L for t in trusses]),
        truss_EA=np.concatenate([t.EA for t in trusses]),
        truss_rhoA=np.concatenate([t.rhoA for t in trusses]),
        truss_cable=np.concatenate([t.tension_only for t in trusses]),
        fixed=np.unique(node_id[topo.fixed_nodes]), ndof=np.array(model.ndof))


def kratos_truss_properties(L0: np.ndarray, L: np.ndarray, EA: np.ndarray,
                            rhoA: np.ndarray) -> dict:
    """YOUNG_MODULUS, TRUSS_PRESTRESS_PK2 and DENSITY (CROSS_AREA 1) of Kratos trusses whose
    nodes are L0 apart that reproduce tmfem trusses of rest length L (module docstring):
    E' = EA (L0/L)^3, S_p = EA L0 (L0^2 - L^2) / (2 L^3), rho' = rhoA L / L0."""
    return dict(E=EA * (L0 / L) ** 3, prestress=EA * L0 * (L0 ** 2 - L ** 2) / (2.0 * L ** 3),
                rho=rhoA * L / L0)


def kratos_truss_force(l: np.ndarray, L0: np.ndarray, props: dict) -> np.ndarray:
    """Axial force of Kratos' TrussElement3D2N at length l: N = (E' E_GL + S_p) A l / L0 with
    E_GL = (l^2 - L0^2) / (2 L0^2), A = 1."""
    return (props["E"] * (l ** 2 - L0 ** 2) / (2.0 * L0 ** 2) + props["prestress"]) * l / L0


# ---------------------------------------------------------------------------- Kratos side
def kratos_run(path: str, *, k: int, prestress: float, steps: int, tol: float) -> dict:
    """Build, solve and take the modes of the exported model in Kratos (this process)."""
    import KratosMultiphysics as KM
    import KratosMultiphysics.LinearSolversApplication  # noqa: F401  (registers the solvers)
    import KratosMultiphysics.StructuralMechanicsApplication as SMA
    from KratosMultiphysics import eigen_solver_factory
    from KratosMultiphysics import python_linear_solver_factory
    KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
    d = dict(np.load(path))
    c0, t0 = time.process_time(), time.perf_counter()
    mp = KM.Model().CreateModelPart("mtc")
    mp.SetBufferSize(2)
    mp.ProcessInfo[KM.DOMAIN_SIZE] = 3
    mp.AddNodalSolutionStepVariable(KM.DISPLACEMENT)
    mp.AddNodalSolutionStepVariable(KM.REACTION)
    X = d["coords"]
    for i in range(X.shape[1]):
        mp.CreateNewNode(i + 1, X[0, i], X[1, i], X[2, i])
    for comp in "XYZ":
        KM.VariableUtils().AddDof(getattr(KM, "DISPLACEMENT_" + comp), getattr(KM, "REACTION_" + comp), mp)
    E, nu, rho, h = d["membrane"]
    pm = mp.GetProperties()[1]
    for var, v in ((KM.YOUNG_MODULUS, E), (KM.POISSON_RATIO, nu), (KM.DENSITY, rho), (KM.THICKNESS, h)):
        pm.SetValue(var, float(v))
    pm.SetValue(KM.CONSTITUTIVE_LAW, SMA.LinearElasticPlaneStress2DLaw())
    for e, q in enumerate(d["quads"].T):
        mp.CreateNewElement("MembraneElement3D4N", e + 1, [int(v) for v in q], pm)
    conn = d["truss_conn"]
    L0 = np.linalg.norm(X[:, conn[1] - 1] - X[:, conn[0] - 1], axis=0)
    tp = kratos_truss_properties(L0, d["truss_L"], d["truss_EA"], d["truss_rhoA"])
    ne = d["quads"].shape[1]
    for j in range(conn.shape[1]):
        p = mp.GetProperties()[j + 2]              # one set per element (own L0 / L)
        for var, v in ((KM.YOUNG_MODULUS, tp["E"][j]), (SMA.TRUSS_PRESTRESS_PK2, tp["prestress"][j]),
                       (KM.DENSITY, tp["rho"][j]), (SMA.CROSS_AREA, 1.0), (KM.POISSON_RATIO, 0.0)):
            p.SetValue(var, float(v))
        p.SetValue(KM.CONSTITUTIVE_LAW, SMA.TrussConstitutiveLaw())
        name = "CableElement3D2N" if d["truss_cable"][j] else "TrussElement3D2N"
        mp.CreateNewElement(name, ne + j + 1, [int(conn[0, j]), int(conn[1, j])], p)
    for nid in d["fixed"]:
        node = mp.GetNode(int(nid))
        for comp in "XYZ":
            node.Fix(getattr(KM, "DISPLACEMENT_" + comp))
    t1, c1 = time.perf_counter(), time.process_time()

    # converged when |r| <= tol |r_0| of the step, or |r| / n_dofs <= tol (1 N + sum |N|) / n_dofs
    # (Kratos' absolute residual is per dof; tmfem's test: |r| <= tol (1 N + sum of |member forces|))
    ndof = 3 * X.shape[1] - 3 * len(d["fixed"])
    if ndof != int(d["ndof"]):
        return dict(error=f"the Kratos model has {ndof} free dofs, tmfem's {int(d['ndof'])}")
    scale = 1.0 + np.sum(np.abs(kratos_truss_force(L0, L0, tp)))
    strategy = KM.ResidualBasedNewtonRaphsonStrategy(
        mp, KM.ResidualBasedIncrementalUpdateStaticScheme(), KM.ResidualCriteria(tol, tol * scale / ndof),
        KM.ResidualBasedBlockBuilderAndSolver(python_linear_solver_factory.CreateFastestAvailableDirectLinearSolver()),
        100, False, False, False)
    strategy.SetEchoLevel(0)
    strategy.Initialize()
    its = []
    for step, s in enumerate(np.linspace(prestress, 0.0, steps + 1) if steps else [0.0]):
        pm.SetValue(SMA.PRESTRESS_VECTOR, KM.Vector([float(s), float(s), 0.0]))
        mp.CloneTimeStep(float(step + 1))
        strategy.InitializeSolutionStep()
        strategy.Predict()
        ok = strategy.SolveSolutionStep()
        strategy.FinalizeSolutionStep()
        its.append(int(mp.ProcessInfo[KM.NL_ITERATION_NUMBER]))
        if not ok:
            return dict(error=f"Kratos Newton did not converge at membrane prestress {s:.4g} Pa "
                              f"(step {step + 1} of {steps + 1})", iterations=its)
    t2, c2 = time.perf_counter(), time.process_time()

    settings = KM.Parameters(json.dumps({"solver_type": "spectra_sym_g_eigs_shift", "number_of_eigenvalues": k,
                                         "max_iteration": 1000, "shift": -1.0, "echo_level": 0}))
    eig = SMA.EigensolverStrategy(mp, SMA.EigensolverDynamicScheme(),
                                  KM.ResidualBasedBlockBuilderAndSolver(eigen_solver_factory.ConstructSolver(settings)),
                                  0.0, 1.0, False, False)
    eig.Solve()
    lam = np.array(mp.ProcessInfo[SMA.EIGENVALUE_VECTOR])
    t3, c3 = time.perf_counter(), time.process_time()
    u = np.array([mp.GetNode(i + 1).GetSolutionStepValue(KM.DISPLACEMENT) for i in range(X.shape[1])]).T
    return dict(dofs=ndof, build_s=t1 - t0, static_s=t2 - t1, eigen_s=t3 - t2, cpu_s=c3 - c0,
                cpu_static_s=c2 - c1, cpu_eigen_s=c3 - c2,
                iterations=its, freq_hz=(np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi)).tolist(),
                x=(X + u).tolist(), load=os.getloadavg()[0])


# ---------------------------------------------------------------------------- tmfem side
def tmfem_run(mesh: int, backend: str, *, k: int, sequence: int | None = None,
              export: str | None = None) -> dict:
    """Build, solve and take the modes of the 1-4 MTC model in this process (``sequence``: the
    mesh sequencing of :meth:`MTCModel.equilibrium`, default none, as the CLI)."""
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    t0, c0 = time.perf_counter(), time.process_time()
    m = MTCModel(load_preset("1-4"), mesh_n=mesh, backend=backend)
    t1, c1 = time.perf_counter(), time.process_time()
    st = m.equilibrium(sequence=sequence)
    t2, c2 = time.perf_counter(), time.process_time()
    modes = m.modes(k=k, at=st)
    t3, c3 = time.perf_counter(), time.process_time()
    out = dict(dofs=m.ndof, backend=m.backend.name, build_s=t1 - t0, static_s=t2 - t1, eigen_s=t3 - t2,
               cpu_s=c3 - c0, cpu_static_s=c2 - c1, cpu_eigen_s=c3 - c2,
               iterations=st.level_iterations or [st.iterations],
               freq_hz=np.asarray(modes.freq_hz).tolist(), load=os.getloadavg()[0])
    if export:
        np.savez(export, **export_model(m))
        out["x"] = st.x[:, m.topology.red_node >= 0].tolist()
    return out


# ---------------------------------------------------------------------------- driver
def _env() -> dict:
    return dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")


def _launch(python: str, args: list) -> dict:
    p = subprocess.run([python, HERE, *args], capture_output=True, text=True, env=_env())
    lines = p.stdout.strip().splitlines()
    if p.returncode != 0 or not lines or not lines[-1].startswith("{"):
        return dict(error=(p.stderr.strip().splitlines() or ["no output"])[-1])
    return json.loads(lines[-1])


def kratos_python(option: str | None) -> str | None:
    """The interpreter that runs Kratos: ``option``, else this one if it imports Kratos."""
    python = option or sys.executable
    ok = subprocess.run([python, "-c", "import KratosMultiphysics.StructuralMechanicsApplication, "
                         "KratosMultiphysics.LinearSolversApplication"],
                        capture_output=True, env=_env()).returncode == 0
    return python if ok else None


def _best(rows: list) -> dict:
    good = [r for r in rows if "error" not in r]
    if not good:
        return rows[-1]
    return min(good, key=lambda r: r["build_s"] + r["static_s"] + r["eigen_s"])


def _total(r: dict) -> float:
    return r["build_s"] + r["static_s"] + r["eigen_s"]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="10,20,40,80", help="membrane meshes 4 x n x n")
    ap.add_argument("--rounds", type=int, default=1, help="alternating runs per program (best kept)")
    ap.add_argument("--kratos-python", help="interpreter with Kratos 10.4.4 installed")
    ap.add_argument("--programs", default="scipy,petsc,kratos",
                    help="what runs: tmfem's backends scipy and petsc, kratos (scipy always: the reference)")
    ap.add_argument("--modes", type=int, default=12)
    ap.add_argument("--sequence", type=int, help="tmfem's mesh sequencing from this coarsest mesh "
                    "(MTCModel.equilibrium(sequence=); default none, as the CLI)")
    ap.add_argument("--membrane-prestress", type=float, default=1e4,
                    help="initial isotropic membrane prestress of the Kratos run [Pa], stepped to zero")
    ap.add_argument("--prestress-steps", type=int, default=1)
    ap.add_argument("--kratos-tol", type=float, default=1e-9,
                    help="Kratos residual criterion (relative to the step's first residual, and absolute as tmfem's)")
    ap.add_argument("--freq-tol", type=float, default=1e-3,
                    help="largest relative frequency difference for which a time ratio is printed")
    ap.add_argument("--tmfem-run", nargs=2, metavar=("MESH", "BACKEND"), help=argparse.SUPPRESS)
    ap.add_argument("--export", help=argparse.SUPPRESS)
    ap.add_argument("--kratos-run", metavar="NPZ", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.tmfem_run:
        print(json.dumps(tmfem_run(int(args.tmfem_run[0]), args.tmfem_run[1], k=args.modes,
                                   sequence=args.sequence, export=args.export)))
        return 0
    if args.kratos_run:
        print(json.dumps(kratos_run(args.kratos_run, k=args.modes, prestress=args.membrane_prestress,
                                    steps=args.prestress_steps, tol=args.kratos_tol)))
        return 0

    programs = set(args.programs.split(",")) | {"scipy"}
    if not programs <= {"scipy", "petsc", "kratos"}:
        ap.error(f"--programs: expected names among scipy, petsc, kratos, found {args.programs!r}")
    kpy = kratos_python(args.kratos_python) if "kratos" in programs else None
    if kpy is None and "kratos" in programs:
        print(f"# Kratos is not installed for {args.kratos_python or sys.executable}: tmfem's figures only. "
              f"Install it into a virtual environment of its own (python3 -m venv ~/kratos-venv && "
              f"~/kratos-venv/bin/pip install numpy {KRATOS_PACKAGES}) and pass "
              f"--kratos-python ~/kratos-venv/bin/python")
    from tmfem.solvers.backends import choose_backend
    print(f"# 1-4 MTC, static from the undeformed membrane + {args.modes} modes; one thread each; best of "
          f"{args.rounds} alternating runs; {os.cpu_count()} cpus, load average {os.getloadavg()[0]:.2f}; "
          f"tmfem mesh sequencing: {f'from n = {args.sequence}' if args.sequence else 'none'}")
    print(f"{'mesh':>9s} {'dofs':>6s} {'program':>13s} {'build s':>8s} {'static s':>9s} {'eigen s':>8s} "
          f"{'total s':>8s} {'CPU s':>7s} {'CPU st':>7s} {'CPU eig':>7s} {'its':>9s} {'f1 [Hz]':>9s} "
          f"{'max df/f':>9s} {'max dx':>8s} load")
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in [int(v) for v in args.meshes.split(",")]:
            npz = os.path.join(tmp, f"mtc{mesh}.npz")
            runs = {"scipy": [], "petsc": [], "kratos": []}
            for r in range(args.rounds):
                for backend in ("scipy", "petsc"):
                    if backend not in programs:
                        continue
                    extra = ["--export", npz] if (r == 0 and backend == "scipy") else []
                    if args.sequence:
                        extra += ["--sequence", str(args.sequence)]
                    runs[backend].append(_launch(sys.executable, ["--tmfem-run", str(mesh), backend,
                                                                  "--modes", str(args.modes), *extra]))
                if kpy is not None and os.path.exists(npz):
                    runs["kratos"].append(_launch(kpy, [
                        "--kratos-run", npz, "--modes", str(args.modes),
                        "--membrane-prestress", str(args.membrane_prestress),
                        "--prestress-steps", str(args.prestress_steps), "--kratos-tol", str(args.kratos_tol)]))
            ref = runs["scipy"][0]
            best = {name: _best(rows) for name, rows in runs.items() if rows}
            default = choose_backend(n_dofs=ref.get("dofs", 0)) if "dofs" in ref else "scipy"
            for name, row in best.items():
                label = f"tmfem {name}" + ("*" if name == default else "") if name != "kratos" else "Kratos"
                if "error" in row:
                    print(f"{'4x%dx%d' % (mesh, mesh):>9s} {'':>6s} {label:>13s}  error: {row['error']}", flush=True)
                    continue
                df = dx = ""
                if name != "scipy" and "error" not in ref:
                    f, fr = np.array(row["freq_hz"]), np.array(ref["freq_hz"])
                    df = f"{np.max(np.abs(f - fr) / fr):9.2e}"
                    if name == "kratos" and "x" in ref:
                        dx = f"{np.max(np.abs(np.array(row['x']) - np.array(ref['x']))):8.1e}"
                print(f"{'4x%dx%d' % (mesh, mesh):>9s} {row['dofs']:6d} {label:>13s} {row['build_s']:8.2f} "
                      f"{row['static_s']:9.2f} {row['eigen_s']:8.2f} {_total(row):8.2f} {row['cpu_s']:7.2f} "
                      f"{row['cpu_static_s']:7.2f} {row['cpu_eigen_s']:7.2f} "
                      f"{','.join(map(str, row['iterations'])):>9s} {row['freq_hz'][0]:9.6f} {df:>9s} {dx:>8s} "
                      f"{row['load']:.1f}", flush=True)
            k = best.get("kratos")
            if k and "error" not in k and "error" not in ref:
                agree = np.max(np.abs(np.array(k["freq_hz"]) - np.array(ref["freq_hz"])) / np.array(ref["freq_hz"]))
                if agree > args.freq_tol:
                    print(f"{'':>9s} no ratio: the frequencies differ by {agree:.1e} (> --freq-tol "
                          f"{args.freq_tol:g}), not the same problem")
                else:
                    print(f"{'':>9s} Kratos / tmfem, total wall (CPU) time: " + ", ".join(
                        f"{b} {_total(k) / _total(best[b]):.1f}x ({k['cpu_s'] / best[b]['cpu_s']:.1f}x)"
                        for b in ("scipy", "petsc") if b in best and "error" not in best[b])
                        + f"; default backend ('auto'): {default}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
