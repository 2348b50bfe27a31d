"""PETSc/SLEPc backend (tmfem.solvers.petsc) against the scipy backend, and MPI runs.

Source of every expected number: an independent formulation -- the scipy backend (SuperLU,
ARPACK/LAPACK) on the same matrices, the residual of the linear system itself, and the
serial run for the 2-rank run. The PETSc backend's model statics are SNES solves
(tmfem.solvers.petsc_snes; their options and reasons: tests/solvers/test_petsc_snes.py).
"""
import json
from dataclasses import replace
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from tmfem.errors import BackendUnavailable, ConvergenceError, InputError

ROOT = Path(__file__).resolve().parents[2]


def test_missing_petsc4py_raises_backend_unavailable_naming_the_command(monkeypatch):
    # source: the install contract (a missing backend names the command that installs it)
    monkeypatch.setitem(sys.modules, "petsc4py", None)
    from tmfem.solvers.backends import get_backend
    with pytest.raises(BackendUnavailable, match="make install"):
        get_backend("petsc")


try:
    import petsc4py  # noqa: F401
    import slepc4py  # noqa: F401
    HAVE_PETSC = True
except ImportError:
    HAVE_PETSC = False
needs_petsc = pytest.mark.skipif(not HAVE_PETSC, reason="petsc4py/slepc4py not importable "
                                 "(install: make install, i.e. scripts/install_petsc.sh)")


@pytest.fixture(scope="module")
def models():
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    return {p: MTCModel(load_preset(p), mesh_n=n) for p, n in (("1-4", 6), ("2-3", 4))}


@pytest.fixture(scope="module")
def equilibria(models):
    # scipy reference: the model's own static solver from the design
    return {p: m.equilibrium(start="design") for p, m in models.items()}


@needs_petsc
@pytest.mark.parametrize("preset", ["1-4", "2-3"])
def test_tangent_solves_agree(models, equilibria, preset):
    from tmfem.solvers.backends import get_backend
    m = models[preset]
    _, K = m.residual(m.reduce(equilibria[preset].x))
    Kf = K[m.free][:, m.free]
    b = np.random.default_rng(1).standard_normal((Kf.shape[0], 2))
    xs = get_backend("scipy").factorize(Kf)(b)
    xp = get_backend("petsc").factorize(Kf)(b)
    assert xp.shape == b.shape
    assert np.linalg.norm(Kf @ xp - b) <= 1e-10 * np.linalg.norm(b) * 1e3
    assert np.linalg.norm(xp - xs) <= 1e-9 * np.linalg.norm(xs)


@needs_petsc
def test_lu_for_unsymmetric_and_refactorisation_of_a_pattern():
    from tmfem.solvers.backends import get_backend
    be = get_backend("petsc")
    n = 300
    A = sp.diags([-np.ones(n - 1), 4 * np.ones(n), -2 * np.ones(n - 1)], [-1, 0, 1]).tocsr()
    b = np.linspace(0, 1, n)
    solve = be.factorize(A)
    x = solve(b)
    assert np.linalg.norm(A @ x - b) <= 1e-12 * np.linalg.norm(b)
    # same pattern, new values: the old solve refuses (no silent use of the new factors)
    solve2 = be.factorize(2.0 * A)
    assert np.allclose(solve2(b), x / 2, rtol=1e-12, atol=0)
    with pytest.raises(InputError, match="earlier factorisation"):
        solve(b)


@needs_petsc
def test_singular_matrix_is_the_scipy_error_type():
    from tmfem.solvers.backends import SingularMatrix, get_backend
    n = 40
    A = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tolil()
    A[7, :] = 0
    A[:, 7] = 0
    for name in ("scipy", "petsc"):
        with pytest.raises(SingularMatrix, match="singular"):
            get_backend(name).factorize(A.tocsr())(np.ones(n))


@needs_petsc
def test_iterative_cg_gamg_meets_the_unpreconditioned_tolerance(models, equilibria):
    from tmfem.solvers.petsc import PetscBackend
    m = models["1-4"]
    _, K = m.residual(m.reduce(equilibria["1-4"].x))
    Kf = sp.csr_matrix(K[m.free][:, m.free])
    Mf = m.mass()[m.free][:, m.free]
    A = Kf + 10.0 * Mf                       # SPD (K_T at a stable equilibrium, plus mass)
    b = np.random.default_rng(2).standard_normal(A.shape[0])
    for rtol in (1e-6, 1e-10):
        x = PetscBackend(solver="iterative", rtol=rtol).factorize(A)(b)
        assert np.linalg.norm(A @ x - b) <= rtol * np.linalg.norm(b) * 1.0001
    with pytest.raises(InputError, match="'iterative' only"):
        PetscBackend(rtol=1e-8)


@needs_petsc
@pytest.mark.parametrize("options, solver, reason", [
    ("-ksp_type foo", "linear solver", "PETSc error 86: Unable to find requested KSP type foo"),
    ("-pc_type foo", "linear solver", "PETSc error 86: Unable to find requested PC type foo"),
    ("-pc_factor_mat_solver_type foo", "linear solve", "PETSc error 92: Could not locate solver "
     "type foo"),
    ("-eps_type foo", "eigen", "PETSc error 86: Unknown EPS type given: foo"),
    ("-st_type foo", "eigen", "PETSc error 86: Unable to find requested ST type foo"),
    ("-st_pc_factor_mat_solver_type foo", "eigen", "PETSc error 92: Could not locate solver "
     "type foo"),
    ("-eps_nev -2", "eigen", "PETSc error 63: Illegal value of nev. Must be > 0"),
    ("-mat_mumps_icntl_7 99", "linear solve", "PETSc error 63: Valid values are 0=AMD"),
])
def test_petsc_options_that_petsc_refuses_are_input_errors(options, solver, reason):
    # source: PETSc's own refusal (error code and reason) of a type, a factorisation package
    # it does not have or a value out of range (MUMPS reads its options at the
    # factorisation), named as bad input in the solver that read it, not a traceback
    from tmfem.solvers.petsc import PetscBackend
    n = 20
    K = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tocsr()
    be = PetscBackend(options=options)
    with pytest.raises(InputError, match=f"^{solver} .*expected .* in the PETSc options, found "
                                         f"{reason}"):
        if solver == "eigen":
            be.eigsh(K, sp.identity(n, format="csr"), 3, 0.0)
        else:
            be.factorize(K)(np.ones(n))


@needs_petsc
def test_petsc_options_are_honoured():
    # an unpreconditioned CG capped at 2 iterations cannot solve a 200-dof Laplacian: the
    # options reach the KSP (from options=, and from PETSC_OPTIONS in a fresh process)
    from tmfem.solvers.petsc import PetscBackend
    n = 200
    A = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tocsr()
    b = np.ones(n)
    be = PetscBackend(solver="iterative", options="-pc_type none -ksp_max_it 2")
    with pytest.raises(ConvergenceError, match="DIVERGED_ITS"):
        be.factorize(A)(b)
    # options do not leak into the next backend
    x = PetscBackend(solver="iterative").factorize(A)(b)
    assert np.linalg.norm(A @ x - b) <= 1e-10 * np.linalg.norm(b) * 1.0001
    code = ("import numpy as np, scipy.sparse as sp; from tmfem.solvers.backends import get_backend\n"
            f"n={n}; A=sp.diags([-np.ones(n-1),2*np.ones(n),-np.ones(n-1)],[-1,0,1]).tocsr()\n"
            "get_backend('petsc').factorize(A)(np.ones(n))")
    env = dict(os.environ, PETSC_OPTIONS="-ksp_type cg -pc_type none -ksp_max_it 2 "
               "-ksp_error_if_not_converged 0")
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert p.returncode != 0 and "DIVERGED_ITS" in p.stderr
    with pytest.raises(InputError, match="'-name value' pairs"):
        PetscBackend(options="ksp_type cg")


@pytest.fixture(scope="module")
def petsc_runs():
    # the model on the PETSc backend: statics from the undeformed membrane (the trust-region
    # continuation) and 12 modes, every factorisation and eigensolve through the backend
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    out = {}
    for p, n in (("1-4", 6), ("2-3", 4)):
        m = MTCModel(load_preset(p), mesh_n=n, backend="petsc")
        st = m.equilibrium()
        out[p] = (m, st, m.modes(k=12, at=st.x))
    return out


@needs_petsc
@pytest.mark.parametrize("preset", ["1-4", "2-3"])
def test_static_equilibrium_and_frequencies_agree(models, petsc_runs, preset):
    m = models[preset]
    assert m.backend.name == "scipy"
    ms, sts, mds = petsc_runs[preset]
    assert ms.backend.name == "petsc"
    st = m.equilibrium()
    x0 = m.initial_positions("undeformed")
    u_scipy, u_petsc = st.x - x0, sts.x - x0
    assert np.linalg.norm(u_petsc - u_scipy) <= 1e-9 * np.linalg.norm(u_scipy)
    md = m.modes(k=12, at=st.x)
    assert np.allclose(mds.freq_hz, md.freq_hz, rtol=1e-8, atol=0)


@needs_petsc
@pytest.mark.parametrize("preset", ["1-4", "2-3"])
def test_repeated_pairs_are_full_m_orthonormal_pairs(models, equilibria, preset):
    from tmfem.solvers.petsc import PetscBackend
    m = models[preset]
    _, K = m.residual(m.reduce(equilibria[preset].x))
    Kf, Mf = K[m.free][:, m.free], m.mass()[m.free][:, m.free]
    # the backend's own eigenpairs (before lowest_modes' Rayleigh-Ritz) vs scipy's
    w, V = PetscBackend().eigsh(Kf, Mf, 12, -1.0)
    from tmfem.solvers.backends import ScipyBackend
    # reference: ARPACK shift-invert (a start vector forces it below 600 dofs; the dense
    # generalised eigh has an absolute error ~ eps lambda_max = 8e-9 rad^2/s^2 here,
    # 1.5e-8 relative on the lowest eigenvalue 0.67, where shift-invert agrees to 2e-10)
    ws, W = ScipyBackend().eigsh(Kf, Mf, 12, -1.0, v0=np.ones(Kf.shape[0]))
    o = np.argsort(ws)
    ws, W = ws[o], W[:, o]
    W = W / np.sqrt(np.einsum("ij,ij->j", W, Mf @ W))
    assert np.allclose(w, ws, rtol=1e-8, atol=0)
    assert np.allclose(V.T @ (Mf @ V), np.eye(12), atol=1e-10)
    assert np.linalg.norm(Kf @ V - Mf @ V * w) <= 1e-8 * np.linalg.norm(Kf @ V)
    gaps = np.abs(np.diff(ws)) <= 1e-6 * np.abs(ws[1:])
    assert gaps.any(), "expected at least one repeated pair (cyclic symmetry)"
    # each cluster: the same M-orthogonal projector from both backends
    start = 0
    for j in range(1, 13):
        if j == 12 or not gaps[j - 1]:
            Pp = V[:, start:j] @ (V[:, start:j].T @ Mf)
            Ps = W[:, start:j] @ (W[:, start:j].T @ Mf)
            assert np.abs(Pp - Ps).max() <= 1e-6
            start = j


MPIEXEC = shutil.which("mpiexec")
needs_mpi = pytest.mark.skipif(not (HAVE_PETSC and MPIEXEC), reason="petsc4py or mpiexec missing "
                               "(install: make install)")


def _mpirun(n, *args, timeout=120, program=None):
    # this pytest process initialised MPI as a singleton, which puts Open MPI's own variables
    # into os.environ: a child mpiexec that sees them thinks it is nested and exits
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "ORTE_")) or "ALLOW_RUN_AS_ROOT" in k}
    program = program or [sys.executable, str(ROOT / "tests" / "mpi" / "fe_distributed.py")]
    cmd = [MPIEXEC, "--allow-run-as-root", "--oversubscribe", "-n", str(n), *program, *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=ROOT, env=env)


@needs_mpi
@pytest.mark.slow
def test_cli_under_two_ranks_prints_once_and_refuses_scipy():
    # source: the same command on 1 process (rank-0 output must be the serial document)
    tmfem = [sys.executable, "-m", "tmfem"]
    argv = ["modal", "--model", "mtc", "--preset", "2-3", "--mesh", "4", "--modes", "4", "--json"]
    p2 = _mpirun(2, *argv, "--backend", "petsc", program=tmfem)
    assert p2.returncode == 0, p2.stderr
    p1 = subprocess.run(tmfem + argv, capture_output=True, text=True, cwd=ROOT)
    d2, d1 = json.loads(p2.stdout), json.loads(p1.stdout)     # exactly one document
    assert np.allclose(d2["freq_hz"], d1["freq_hz"], rtol=1e-8, atol=0)
    p = _mpirun(2, *argv, "--backend", "scipy", program=tmfem)
    assert p.returncode == 2 and p.stderr.count("expected --backend petsc") == 1


def test_a_command_without_backend_under_mpiexec_is_refused_as_serial(monkeypatch, capsys):
    # under mpiexec (2 ranks launched) a command that has no --backend runs on one process:
    # refused before any work, without advice to pass an option it does not have
    import tmfem.cli as cli
    monkeypatch.setattr(cli, "_mpi_size", lambda: 2)
    assert cli.main(["equilibrium", "--preset", "2-3"]) == 2
    err = capsys.readouterr().err
    assert err.count("`tmfem equilibrium`, which runs on one process: run it without mpiexec") == 1
    assert "--backend scipy" not in err


@pytest.fixture(scope="module")
def design_run(once):
    """run(n): tests/mpi/fe_distributed.py on the 1-4 at mesh 6 from the design under n ranks,
    one run per n shared by the tests that read it."""
    return lambda n: once(("fe_distributed", n, "1-4", "6", "--start", "design"),
                          lambda: _mpirun(n, "1-4", "6", "--start", "design"))


@needs_mpi
def test_one_and_two_ranks_agree(models, equilibria, design_run):
    # source: the scipy model's own static solve from the design and its 12 modes; the
    # PETSc model assembles rank by rank (each rank its share of the membrane elements)
    runs = {}
    for n in (1, 2):
        p = design_run(n)
        assert p.returncode == 0, p.stderr
        lines = p.stdout.strip().splitlines()
        assert len(lines) == 1          # one document, from rank 0 only
        runs[n] = json.loads(lines[0])
        assert runs[n]["ranks"] == n and runs[n]["distributed"]
    m = models["1-4"]
    x0 = m.reduce(m.initial_positions("design"))
    xs = m.reduce(equilibria["1-4"].x)
    for n in (1, 2):
        x = np.array(runs[n]["x"])
        assert np.linalg.norm(x - xs) <= 1e-9 * np.linalg.norm(xs - x0)
    assert np.allclose(runs[2]["omega2"], runs[1]["omega2"], rtol=2e-8, atol=0)
    ref = m.modes(k=12, at=equilibria["1-4"].x)
    assert np.allclose(runs[2]["omega2"], ref.omega2, rtol=2e-8, atol=0)


@needs_mpi
@pytest.mark.parametrize("ranks", [2, pytest.param(3, marks=pytest.mark.slow)])
def test_model_on_petsc_under_ranks_agrees(models, ranks):
    # source: the scipy model (its trust-region continuation and ARPACK); the SNES
    # continuation from the undeformed membrane and the SLEPc modes under 2 and 3 ranks
    # (distributed assembly, MUMPS) reach the same equilibrium and frequencies
    p = _mpirun(ranks, "1-4", "6")
    assert p.returncode == 0, p.stderr
    run = json.loads(p.stdout.strip())
    m = models["1-4"]
    st = m.equilibrium()
    x0 = m.reduce(m.initial_positions("undeformed"))
    xs = m.reduce(st.x)
    assert np.linalg.norm(np.array(run["x"]) - xs) <= 1e-9 * np.linalg.norm(xs - x0)
    assert np.allclose(run["omega2"], m.modes(k=12, at=st.x).omega2, rtol=2e-8, atol=0)


@pytest.fixture(scope="module")
def sequenced_8():
    # the scipy model's own sequenced static solve (levels 4 -> 8) and its 12 modes
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    m = MTCModel(load_preset("1-4"), mesh_n=8)
    st = m.equilibrium(sequence=4)
    return m, st, m.modes(k=12, at=st.x)


@needs_mpi
@pytest.mark.parametrize("ranks", [1, 2])
def test_mesh_sequencing_under_ranks_agrees_with_scipy(sequenced_8, ranks):
    # source: the scipy model's own sequenced static solve (levels 4 -> 8) and its modes; the
    # PETSc levels build, solve and release their distributed matrices on every rank
    p = _mpirun(ranks, "1-4", "8", "--sequence", "4")
    assert p.returncode == 0, p.stderr
    run = json.loads(p.stdout.strip())
    m, st, md = sequenced_8
    x0 = m.reduce(m.initial_positions("undeformed"))
    xs = m.reduce(st.x)
    assert np.linalg.norm(np.array(run["x"]) - xs) <= 1e-9 * np.linalg.norm(xs - x0)
    assert np.allclose(run["omega2"], md.omega2, rtol=2e-8, atol=0)


@needs_petsc
def test_released_distributed_elements_free_their_matrices(models):
    # source: PETSc's own handle of a destroyed object (0); petsc4py 3.18 frees an object on
    # destroy() only, so a level that is done must destroy its matrices itself
    from tmfem.fem.distributed import for_backend
    from tmfem.fem.element import State
    from tmfem.solvers.petsc import PetscBackend
    m = models["1-4"]
    dist = for_backend(PetscBackend(), m.elements, State(x=m.initial_positions("design")),
                       m.topology.T, m.free)
    _, K = dist.residual(State(x=m.initial_positions("design")))
    M = dist.mass()
    mats = [K.mat, M.mat]
    assert all(A.handle != 0 for A in mats)
    dist.release()
    assert all(A.handle == 0 for A in mats)
    assert dist.mass() is not M             # a later use assembles afresh


@needs_mpi
def test_rank_local_pattern_changes_neither_hang_nor_mislead():
    # source: the residual of the linear systems; rank 1's rows change pattern, rank 0's do
    # not (the pattern cache and the symmetry test must agree over the ranks)
    cmd = [MPIEXEC, "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable,
           str(ROOT / "tests" / "mpi" / "pattern_cache.py")]
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "ORTE_")) or "ALLOW_RUN_AS_ROOT" in k}
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=env)
    assert p.returncode == 0, p.stderr
    assert max(json.loads(p.stdout)) <= 1e-12


@needs_mpi
def test_a_tangent_that_one_rank_still_holds_is_refilled_on_no_rank():
    # source: the first tangent's Frobenius norm at the same configuration. Rank 1 holds the
    # first tangent: every rank assembles a new one (one rank refilling while another
    # creates are different collective calls: the job would hang to the timeout)
    p = _mpirun(2, "1-4", "4", timeout=60,
                program=[sys.executable, str(ROOT / "tests" / "mpi" / "tangent_reuse.py")])
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    assert doc["new"] == [True, True]
    assert doc["second"] == pytest.approx(doc["first"], rel=1e-14)


@needs_mpi
@pytest.mark.slow
def test_failure_on_one_rank_one_error_nonzero_exit():
    # non-finite element matrices on rank 1: caught collectively, one message from rank 0
    p = _mpirun(2, "1-4", "4", "--nan-rank", "1")
    assert p.returncode != 0
    assert p.stderr.count("error: ") == 1 and "non-finite entries" in p.stderr
    assert p.stdout.strip() == ""
    # an exception in rank 1 only while rank 0 waits in a collective call: aborted, no hang
    p = _mpirun(2, "1-4", "4", "--fail-rank", "1", timeout=60)
    assert p.returncode != 0
    assert p.stderr.count("error: rank 1 of 2: FloatingPointError") == 1


# ---------------------------------------------------------------- CLI under mpiexec: output
def _cli_in_rank_dirs(tmp_path, n, *argv, timeout=120):
    """``tmfem ARGV`` under ``mpiexec -n n``, each rank r in its own working directory
    tmp_path/rank<r> (relative output paths then show which ranks wrote files)."""
    return _mpirun(n, str(tmp_path), *argv, timeout=timeout,
                   program=[sys.executable, str(ROOT / "tests" / "mpi" / "in_rank_dir.py")])


def _written(tmp_path, rank):
    d = tmp_path / f"rank{rank}"
    return sorted(str(p.relative_to(d)) for p in d.rglob("*") if p.is_file())


@needs_mpi
def test_cli_static_writes_each_output_once_from_rank_0(tmp_path):
    # source: the same command on 1 process (1 rank of the same distributed assembly): the
    # document rank 0 prints must be its, displacements to 1e-9
    argv = ["static", "--preset", "2-3", "--mesh", "4", "--backend", "petsc", "--json",
            "--monitor", "B_11,A_21,B_21", "--vtk", "out/s.vtu"]
    p = _cli_in_rank_dirs(tmp_path, 2, *argv)
    assert p.returncode == 0, p.stderr
    d2 = json.loads(p.stdout)                  # exactly one document on stdout
    assert _written(tmp_path, 0) == ["out/s.vtu"] and _written(tmp_path, 1) == []
    assert p.stderr.count("tmfem static: 2-3") == 1       # progress line from rank 0 only
    p1 = subprocess.run([sys.executable, "-m", "tmfem", *argv[:-2]], capture_output=True,
                        text=True, cwd=tmp_path)
    d1 = json.loads(p1.stdout)
    assert d2["iterations"] == d1["iterations"]
    for lab, h1 in d1["monitor"].items():      # start -> equilibrium of the monitored nodes
        u1 = np.subtract(h1[-1], h1[0])
        u2 = np.subtract(d2["monitor"][lab][-1], d2["monitor"][lab][0])
        assert np.linalg.norm(u2 - u1) <= 1e-9 * np.linalg.norm(u1)
    assert np.allclose(list(d2["tendon_force"].values()), list(d1["tendon_force"].values()),
                       rtol=1e-9, atol=0)


@needs_mpi
@pytest.mark.slow
def test_cli_converge_writes_csv_and_plot_once_from_rank_0(tmp_path):
    # source: the serial scipy run of the same study (frequencies to 1e-8)
    conv = ["converge", "--preset", "2-3", "--mesh", "2,3", "--tendon-elements", "1",
            "--modes", "3", "--json", "--csv", "c.csv", "--plot", "c.png"]
    p = _cli_in_rank_dirs(tmp_path, 2, *conv, "--backend", "petsc")
    assert p.returncode == 0, p.stderr
    assert _written(tmp_path, 0) == ["c.csv", "c.png"] and _written(tmp_path, 1) == []
    assert (tmp_path / "rank0" / "c.csv").read_text().count("\n") == 3   # header + 2 rows
    rows2 = json.loads(p.stdout)["rows"]
    p1 = subprocess.run([sys.executable, "-m", "tmfem", *conv[:-4]], capture_output=True,
                        text=True, cwd=tmp_path)
    rows1 = json.loads(p1.stdout)["rows"]
    for r1, r2 in zip(rows1, rows2, strict=True):
        f1, f2 = ([r[f"f{i}"] for i in (1, 2, 3)] for r in (r1, r2))
        assert np.allclose(f2, f1, rtol=1e-8, atol=0)


@needs_mpi
def test_cli_output_refused_on_rank_0_only_is_one_error_exit_2(tmp_path):
    # an output directory that rank 0 cannot create (a file is in the way in its working
    # directory only): rank 0's check is collective, so every rank stops at once with the
    # serial run's exit code 2 and one message, before any work (no abort after a grace)
    (tmp_path / "rank0").mkdir(parents=True)
    (tmp_path / "rank0" / "out").write_text("a file")
    p = _cli_in_rank_dirs(tmp_path, 2, "modal", "--preset", "2-3", "--mesh", "4", "--backend",
                          "petsc", "--vtk", "out/m.vtu", timeout=60)
    assert p.returncode == 2, p.stderr
    assert p.stderr.count("error:") == 1 and "--vtk" in p.stderr and "MPI_ABORT" not in p.stderr
    assert p.stdout == ""


@needs_petsc
def test_distributed_tangent_held_by_a_caller_is_not_overwritten(models):
    # source: the scipy tangent of the same states (a solver holds its iterate's tangent
    # while it evaluates trial points: a refill in place would hand it another state's)
    from tmfem.fem.element import State
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    m = MTCModel(load_preset("2-3"), mesh_n=4, backend="petsc")
    d, ms = m.distributed, models["2-3"]
    x0 = m.initial_positions("design")
    xs = [x0, 1.001 * x0, 1.002 * x0]
    held = [d.residual(State(x=x))[1] for x in xs]          # all three alive at once
    for x, K in zip(xs, held):
        Ks = ms.residual(ms.reduce(x))[1][ms.free][:, ms.free]
        assert np.allclose(K.diagonal(), Ks.diagonal(), rtol=1e-12, atol=0)
    n_before = len(d._K)
    del held
    d.residual(State(x=x0))
    assert len(d._K) == n_before                            # a dropped one is refilled


# ---------------------------------------------------------------- SBC on distributed assembly
@pytest.fixture(scope="module")
def sbc_scipy():
    # 1-4 SBC at 4 x 6 x 6: 937 free dofs, so that scipy's modes come from ARPACK
    # shift-invert (its dense path below 600 dofs has an error ~ eps lambda_max, 1e-7 on the
    # lowest SBC mode with the shells' stiff rotations: docs/guides/backends.md)
    from tmfem.models.sbc.model import SBCModel
    from tmfem.system import load_preset
    m = SBCModel(load_preset("1-4"), mesh_n=6)
    st = m.equilibrium()
    return m, st, m.modes(k=12, at=st)


def _omega2_floor(m, st, md):
    """The round-off floor of each omega_i^2 of the SBC model ``m`` about the equilibrium
    ``st`` (scipy modes ``md``), relative: entries of K known to eps relative move
    omega_i^2 by up to eps |phi_i|^T |K| |phi_i| (first-order perturbation, phi_i
    M-normalised), 7e-8 of omega_1^2 for the 1-4 at mesh 6 (the shells' rotations, 1e14
    against omega_1^2 = 0.67)."""
    K = m.residual(st.state)[1].tocsr()[m.free][:, m.free]
    phi = np.abs(md.shapes[m.free])
    return np.finfo(float).eps * np.einsum("ij,ij->j", phi, abs(K) @ phi) / md.omega2


@needs_petsc
def test_sbc_modes_free_the_mass_they_assemble(sbc_scipy, monkeypatch):
    # petsc4py 3.18 frees a matrix on destroy() only: the mass at the modes' state is that
    # solve's and is destroyed after it; a second solve is the same as the first and as
    # scipy's (source: the scipy model's modes, to 2e-8 or their round-off floor)
    from tmfem.models.sbc.model import SBCModel
    m, st, ref = sbc_scipy
    mp = SBCModel(m.system, mesh_n=6, backend="petsc")
    d = mp.distributed
    made, assemble = [], d.mass
    monkeypatch.setattr(d, "mass", lambda state=None: made.append(assemble(state)) or made[-1])
    omega2 = [mp.modes(k=12, at=st.state).omega2 for _ in range(2)]
    assert len(made) == 2 and all(M.mat.handle == 0 for M in made)
    rtol = np.maximum(2e-8, _omega2_floor(m, st, ref))
    for w in omega2:
        assert np.all(np.abs(w / ref.omega2 - 1) <= rtol)

@needs_petsc
def test_sbc_distributed_tangent_and_its_symmetric_part_are_the_scipy_ones(sbc_scipy):
    # source: the scipy assembly of the same state (T^T K T restricted to the free dofs)
    from tmfem.models.sbc.model import SBCModel
    m, st, _ = sbc_scipy
    mp = SBCModel(m.system, mesh_n=6, backend="petsc")
    d = mp.distributed
    assert d is not None and d._shares[0] is not None          # the shells by elements
    r, K = m.residual(st.state)
    K = K.tocsr()[m.free][:, m.free]
    rd, Kd = d.residual(st.state)
    Kd = d.assembler.scipy(Kd)
    assert np.abs(rd - r[m.free]).max() <= 1e-12 * np.abs(r).max() + 1e-9
    assert abs(Kd - K).max() <= 1e-12 * abs(K).max()
    Ks = d.assembler.scipy(d.residual(st.state, symmetric=True)[1])
    assert abs(Ks - 0.5 * (K + K.T)).max() <= 1e-12 * abs(K).max()
    assert abs(Ks - Ks.T).max() <= 1e-15 * abs(K).max()     # summation order only
    # the mass at the equilibrium's triads from each rank's element masses, and the
    # reference one
    for state in (st.state, None):
        Md = d.assembler.scipy(d.mass(state))
        Ms = m.mass(state).tocsr()[m.free][:, m.free]
        assert abs(Md - Ms).max() <= 1e-14 * abs(Ms).max()
    assert d.energy(st.state) == pytest.approx(m.energy(st.state), rel=1e-12)


@needs_mpi
def test_sbc_one_and_two_ranks_agree_with_scipy(sbc_scipy):
    # source: the scipy SBC model's static solve from the undeformed membrane (MTC
    # predictor, then the SBC trust region) and its 12 modes; the PETSc runs assemble the
    # shells rank by rank (1 rank: in this process)
    from tmfem.models.sbc.model import SBCModel
    m, st, md = sbc_scipy
    u = st.state.x - m.start_state().x
    # frequencies to 1e-8, or to their round-off floor where that is coarser (3.6e-8 in f_1:
    # _omega2_floor); measured spread 1.4-4.4e-9
    rtol = np.maximum(1e-8, _omega2_floor(m, st, md) / 2)
    m1 = SBCModel(m.system, mesh_n=6, backend="petsc")
    s1 = m1.equilibrium()
    runs = {1: {"ranks": 1, "distributed": m1.distributed is not None, "iterations": s1.iterations,
                "predictor_iterations": s1.predictor_iterations, "x": s1.state.x, "R": s1.state.R,
                "omega2": m1.modes(k=12, at=s1.state).omega2}}
    p = _mpirun(2, "1-4", "6", "--model", "sbc")
    assert p.returncode == 0, p.stderr
    lines = p.stdout.strip().splitlines()
    assert len(lines) == 1                             # one document, from rank 0 only
    runs[2] = json.loads(lines[0])
    for n, run in runs.items():
        assert run["ranks"] == n and run["distributed"]
        x = np.array(run["x"])
        assert np.linalg.norm(x - st.state.x) <= 1e-9 * np.linalg.norm(u)
        assert np.abs(np.array(run["R"]) - st.state.R).max() <= 1e-9
        f = np.sqrt(np.array(run["omega2"])) / (2 * np.pi)
        assert np.all(np.abs(f / md.freq_hz - 1) <= rtol)


@needs_mpi
@pytest.mark.slow
def test_sbc_failure_on_one_rank_one_error_nonzero_exit():
    # non-finite shell matrices on rank 1 only: caught collectively, one message from rank 0
    p = _mpirun(2, "1-4", "4", "--model", "sbc", "--nan-rank", "1")
    assert p.returncode != 0
    assert p.stderr.count("error: ") == 1 and "non-finite entries" in p.stderr
    assert p.stdout.strip() == ""
    # the shell kernel of rank 1 raises while rank 0 waits in a collective call: one error,
    # the job aborted (the MTC predictor's MUMPS factors, freed while rank 1 unwinds, are
    # destroyed collectively later, not on the failing rank alone: no hang)
    p = _mpirun(2, "1-4", "4", "--model", "sbc", "--fail-rank", "1", timeout=60)
    assert p.returncode != 0
    assert p.stderr.count("error: rank 1 of 2: FloatingPointError") == 1
    assert p.stdout.strip() == ""


@needs_mpi
@pytest.mark.slow
def test_cli_sbc_modal_under_two_ranks_prints_once_and_agrees(tmp_path):
    # source: the same command on 1 process with scipy (frequencies to their round-off
    # floor); the VTK file written once, by rank 0. The floor: entries
    # of K known to eps relative move f_1 by up to 3.6e-8 here (the first-order estimate of the
    # test above, on the same 1-4 SBC at mesh 6); a CI run measured 1.08e-8 in f_1, above the
    # 1e-8 this test first asked
    argv = ["modal", "--model", "sbc", "--preset", "1-4", "--mesh", "6", "--modes", "6",
            "--json"]
    p = _cli_in_rank_dirs(tmp_path, 2, *argv, "--backend", "petsc", "--vtk", "m.vtu")
    assert p.returncode == 0, p.stderr
    assert _written(tmp_path, 0) == ["m.vtu"] and _written(tmp_path, 1) == []
    d2 = json.loads(p.stdout)                      # exactly one document on stdout
    p1 = subprocess.run([sys.executable, "-m", "tmfem", *argv], capture_output=True, text=True,
                        cwd=tmp_path)
    d1 = json.loads(p1.stdout)
    assert np.allclose(d2["freq_hz"], d1["freq_hz"], rtol=4e-8, atol=0)


@needs_mpi
@pytest.mark.parametrize("ranks", [2, pytest.param(3, marks=pytest.mark.slow)])
def test_slepc_eigen_under_ranks_agrees_with_scipy(models, equilibria, design_run, ranks):
    # source: the scipy model's 12 modes at its own equilibrium from the design (ARPACK on
    # the scipy matrices) and the model's scipy mass for the M-orthonormality; SLEPc's
    # Krylov-Schur on the distributed MUMPS factors of K - sigma M
    ref = models["1-4"].modes(k=12, at=equilibria["1-4"])
    p = design_run(ranks)
    assert p.returncode == 0, p.stderr
    run = json.loads(p.stdout.strip())
    freq = np.sqrt(run["omega2"]) / (2 * np.pi)
    assert np.allclose(freq, ref.freq_hz, rtol=1e-8, atol=0)
    assert run["m_orth"] <= 1e-10


@needs_petsc
def test_eps_and_st_options_are_honoured(capfd):
    # source: SLEPc's own view of its objects (-eps_view): -eps_ncv, -eps_tol and -st_pc_type
    # from options= reach the EPS of the eigen solve and its ST (LU in place of the default
    # Cholesky); the frequencies stay those of the default run to 1e-9
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset
    m = MTCModel(load_preset("1-4"), mesh_n=6, backend=PetscBackend())
    st = m.equilibrium(start="design")
    base = m.modes(k=6, at=st)
    capfd.readouterr()
    m.backend = PetscBackend(options="-eps_ncv 33 -eps_tol 1e-11 -st_pc_type lu -eps_view")
    modes = m.modes(k=6, at=st)
    view = capfd.readouterr().out
    assert "krylovschur" in view.replace("-", "").lower()
    assert "(ncv): 33" in view
    assert "tolerance: 1e-11" in view
    assert "type: sinvert" in view
    st_view = view[view.index("ST Object"):]
    assert "PC Object: (st_)" in st_view and "type: lu" in st_view and "type: cholesky" not in st_view
    assert np.allclose(modes.freq_hz, base.freq_hz, rtol=1e-9, atol=0)


@needs_mpi
@pytest.mark.parametrize("ranks", [1, 2, 3])
def test_block_pair_pattern_is_scipys_pattern_and_matrix(ranks):
    # source: scipy's T^T K T of the same element matrices and entries (its structure from
    # unit values and |T|, so no cancellation); the 4-node group is keyed per block pair
    # (block size 3), the group of permuted local dofs and the entries per entry; an
    # assembly's values array on each rank: the entries of its rows plus those it sends
    # (scipy's pattern of its rows and of its own share), not all distinct keys it touches
    # plus the received and the summed ones; a force vector: each rank's rows of T^T f
    p = _mpirun(ranks, program=[sys.executable, str(ROOT / "tests" / "mpi" / "assembler_pattern.py")])
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["block_sizes"] == [3, 1, 1]
    assert out["pattern_equal"]
    assert out["max_rel"] <= 1e-14
    assert len(out["buffers"]) == ranks
    assert all(size == expected for size, expected in out["buffers"])
    # a summed force vector: each rank its own rows of scipy's T^T f, together all N
    assert sum(size for size, _, _ in out["vector"]) == out["N"]
    assert all(size == expected and err <= 1e-14 for size, expected, err in out["vector"])


@needs_petsc
def test_modes_reuse_the_static_analysis_and_agree_with_scipy(models, equilibria):
    # source: the scipy model's 12 modes at its equilibrium from the design; PETSc's log of
    # MUMPS' symbolic (MatCholFctrSym) and numeric factorisations: K - sigma M has the
    # tangent's pattern (the mass lies within it), so the eigen solve factorises it
    # numerically in the static solve's analysed pattern; an st_ option gives the eigen
    # solve its own KSP, and with it its own analysis
    from petsc4py import PETSc
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset
    PETSc.Log.begin()
    sym, num = PETSc.Log.Event("MatCholFctrSym"), PETSc.Log.Event("MatCholFctrNum")
    ref = models["1-4"].modes(k=12, at=equilibria["1-4"].x)
    for options, analyses in ((None, 0), ("-st_mat_mumps_icntl_14 40", 1)):
        m = MTCModel(load_preset("1-4"), mesh_n=6,
                     backend=PetscBackend(options=options))
        st = m.equilibrium(start="design")
        s0, n0 = sym.getPerfInfo()["count"], num.getPerfInfo()["count"]
        modes = m.modes(k=12, at=st.x)
        assert sym.getPerfInfo()["count"] - s0 == analyses
        assert num.getPerfInfo()["count"] - n0 == 1
        assert np.allclose(modes.omega2, ref.omega2, rtol=2e-8, atol=0)


@needs_petsc
def test_the_modes_of_a_distributed_model_hold_at_most_two_copies_of_the_eigenvectors():
    # source: the sizes of the arrays themselves (k vectors of n float64: 8 n k bytes), and
    # the scipy backend's modes of the same model. SLEPc's vectors stay in PETSc and in the
    # ranks' rows through the Rayleigh-Ritz step (rows_gram), the k wanted are gathered once,
    # lowest_modes keeps one product with them at a time and sets their signs in place: the
    # numpy arrays of the modes phase peak at two full copies and a few vectors (n,), 4.4
    # copies when the converged vectors, the products and |V| were full arrays each
    import tracemalloc
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset
    system = load_preset("1-4")
    m = MTCModel(system, mesh_n=16, backend=PetscBackend())
    st = m.equilibrium(start="design")
    m.modes(k=2, at=st)                  # the mass, assembled once and kept by the model
    k = 12
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        modes = m.modes(k=k, at=st)
        peak = tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()
    copy = 8 * m.distributed.N * k
    assert copy <= peak <= 2.5 * copy, peak / copy
    ref = MTCModel(system, mesh_n=16).modes(k=k, at=st.x)
    assert np.allclose(modes.omega2, ref.omega2, rtol=1e-8, atol=0)


@needs_petsc
def test_pattern_subset_check():
    # source: the patterns themselves (a diagonal lies within a tridiagonal pattern, an
    # entry in the first or the last row outside the band does not), read from the
    # assemblers' patterns or from PETSc's AIJ matrices, whole or a few rows at a time
    from petsc4py import PETSc
    from tmfem.solvers.distributed import DistributedMatrix, Pattern
    from tmfem.solvers.petsc import PetscBackend
    n = 6
    tri = sp.diags([np.ones(n - 1), 2 * np.ones(n), np.ones(n - 1)], [-1, 0, 1], format="csr")

    def corner(i, j):
        return sp.csr_matrix(sp.identity(n) + sp.csr_matrix(([1.0], ([i], [j])), shape=(n, n)))

    def dist(S, carry):
        ip, ix = S.indptr.astype(PETSc.IntType), S.indices.astype(PETSc.IntType)
        mat = PETSc.Mat().createAIJ(size=S.shape, csr=(ip, ix, S.data), comm=PETSc.COMM_SELF)
        return DistributedMatrix(mat, Pattern(ip, ix) if carry else Pattern(), S.shape)
    be = PetscBackend()
    for carry in (True, False):
        for chunk in (1 << 20, 2):
            assert be._subset(dist(sp.identity(n, format="csr"), carry), dist(tri, carry), chunk=chunk)
            assert not be._subset(dist(corner(0, n - 1), carry), dist(tri, carry), chunk=chunk)
            assert not be._subset(dist(corner(n - 1, 0), carry), dist(tri, carry), chunk=chunk)


@needs_petsc
def test_modes_reuse_the_static_distributed_tangent(models, equilibria):
    # source: the scipy model's 12 modes at its equilibrium from the design; the modes of
    # the distributed tangent the static solve assembled last agree with those of one
    # assembled again at the equilibrium, and a scipy tangent is refused for it
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset
    ref = models["1-4"].modes(k=12, at=equilibria["1-4"].x)
    m = MTCModel(load_preset("1-4"), mesh_n=6, backend=PetscBackend())
    st = m.equilibrium(start="design")
    again = m.modes(k=12, at=st.x)
    reused = m.modes(k=12, at=st)
    assert np.allclose(reused.omega2, again.omega2, rtol=1e-10, atol=0)
    assert np.allclose(reused.omega2, ref.omega2, rtol=2e-8, atol=0)
    with pytest.raises(InputError, match=r"expected the tangent of this model's static solve "
                                         r"\(DistributedMatrix"):
        m.modes(k=12, at=replace(st, tangent=equilibria["1-4"].tangent))


def _modal_cli(*argv):
    p = subprocess.run([sys.executable, "-m", "tmfem", "modal", *argv], capture_output=True,
                       text=True, cwd=ROOT)
    return p


@pytest.fixture(scope="module")
def modal_1_4_scipy(once):
    """`tmfem modal --preset 1-4 --mesh 12 --modes 6 --json --backend scipy` (one run, the
    reference of the two PETSc runs below)."""
    argv = ("--preset", "1-4", "--mesh", "12", "--modes", "6", "--json", "--backend", "scipy")
    return once(("modal", *argv), lambda: _modal_cli(*argv))


def test_cli_eig_solver_is_not_an_option():
    # the PETSc backend has one eigen solver (SLEPc): the option is gone, argparse refuses it
    p = _modal_cli("--preset", "2-3", "--mesh", "4", "--modes", "4", "--eig-solver", "slepc")
    assert p.returncode == 2
    assert "unrecognized arguments: --eig-solver" in p.stderr


@needs_petsc
def test_cli_petsc_modes_agree_with_scipy_and_name_the_backend(modal_1_4_scipy):
    # source: the same command with scipy (ARPACK shift-invert on the scipy matrices):
    # frequencies to 1e-8; the JSON and a stderr line name the backend that ran
    argv = ["--preset", "1-4", "--mesh", "12", "--modes", "6", "--json"]
    ref = modal_1_4_scipy
    assert json.loads(ref.stdout)["backend"] == "scipy"
    assert "backend scipy (" in ref.stderr
    p = _modal_cli(*argv, "--backend", "petsc")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["backend"] == "petsc" and "backend petsc (" in p.stderr
    assert np.allclose(d["freq_hz"], json.loads(ref.stdout)["freq_hz"], rtol=1e-8, atol=0)


@needs_mpi
def test_cli_modal_under_two_ranks_takes_petsc_by_default(modal_1_4_scipy):
    # source: the 1-process scipy command (frequencies to 1e-8); under 2 ranks the default
    # backend "auto" takes PETSc (SLEPc on the distributed factors) whatever the size
    argv = ["modal", "--preset", "1-4", "--mesh", "12", "--modes", "6", "--json"]
    ref = json.loads(modal_1_4_scipy.stdout)
    tmfem = [sys.executable, "-m", "tmfem"]
    p = _mpirun(2, *argv, program=tmfem)
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["backend"] == "petsc"
    assert np.allclose(d["freq_hz"], ref["freq_hz"], rtol=1e-8, atol=0)


@needs_petsc
@pytest.mark.parametrize("where", ["factorize", "eigsh"])
def test_a_mumps_failure_other_than_singular_is_named(where):
    # source: MUMPS' own return code (INFOG(1) = -19: the working memory limit ICNTL(23),
    # here 1 MB, is below the need); the tridiagonal matrix is non-singular, so the error
    # must not call it singular (the code a PETSc failed preconditioner hides)
    from tmfem.errors import InputError
    from tmfem.solvers.backends import SingularMatrix
    from tmfem.solvers.petsc import PetscBackend
    n = 3000
    K = sp.diags([-np.ones(n - 1), 2.5 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    prefix = "" if where == "factorize" else "st_"
    be = PetscBackend(options=f"-{prefix}mat_mumps_icntl_23 1")
    with pytest.raises(InputError, match=r"MUMPS INFOG\(1\) = -19.*ICNTL\(23\)") as err:
        if where == "factorize":
            be.factorize(K)
        else:
            be.eigsh(K, sp.identity(n, format="csr"), 3, 0.0)
    assert not isinstance(err.value, SingularMatrix)


@needs_petsc
def test_backend_options_no_solver_read_are_named():
    # source: PETSc's own record of the options its objects read (PetscOptionsUsed): a
    # misspelt option is never read; -ksp_rtol is read by an iterative KSP and ignored by
    # the direct solve (KSP preonly); -eps_ncv is read once an eigen solve has run
    from tmfem.solvers.petsc import PetscBackend
    n = 50
    K = sp.diags([-np.ones(n - 1), 2.5 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    direct = PetscBackend(options="-ksp_tpye cg -ksp_rtol 1e-8 -mat_mumps_icntl_14 30 -eps_ncv 30")
    direct.factorize(K)(np.ones(n))
    assert direct.unused_options() == ["-ksp_tpye", "-ksp_rtol", "-eps_ncv"]
    direct.eigsh(K, sp.identity(n, format="csr"), 3, 0.0)
    assert direct.unused_options() == ["-ksp_tpye", "-ksp_rtol"]
    iterative = PetscBackend(solver="iterative", options="-ksp_rtol 1e-8")
    iterative.factorize(K)(np.ones(n))
    assert iterative.unused_options() == []


@needs_petsc
def test_entries_tied_to_many_unknowns_are_keyed_apart():
    # source: scipy's T^T M T on the unknowns. A mass-like group of 200 000 entries, 50 of
    # them on a dof that T ties to 11 unknowns (an SBC corner): laid out as 11 x 11 pairs
    # each, the group's keys alone would take 200 000 x 121 x 8 bytes = 194 MB; the tied
    # entries apart, the construction and an assembly stay within a few entries' worth
    import tracemalloc
    from tmfem.solvers.distributed import DistributedAssembler
    rng = np.random.default_rng(3)
    n = 20000
    rows, cols, vals = list(range(n)), list(range(n)), [1.0] * n
    rows[0:1], cols[0:1], vals[0:1] = [0] * 11, list(range(100, 111)), list(rng.random(11))
    T = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    keep = np.ones(n, bool)
    keep[5] = False
    ent = rng.integers(1, n, size=(200000, 2))
    ent[:50, 0] = 0
    ev = rng.standard_normal(len(ent))
    tracemalloc.start()
    asm = DistributedAssembler([(ent, "entry")], n, T=T, keep=keep)
    A = asm.scipy(asm.matrix(ev))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    M = sp.csr_matrix((ev, (ent[:, 0], ent[:, 1])), shape=(n, n))
    ref = (T.T @ M @ T).tocsr()[keep][:, keep]
    assert abs(A - ref).max() <= 1e-14 * abs(ref).max()
    assert peak < 60 * 2**20, peak / 2**20
