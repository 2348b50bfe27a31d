"""SNES statics of the PETSc backend (tmfem.solvers.petsc_snes) and the automatic backend choice.

Sources: the scipy backend's trust-region statics of the same model (an independent nonlinear
solver on the same residual), PETSc's own output (-snes_monitor, -snes_view) and converged
reasons, the crossover constant of tmfem.solvers.backends.
"""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tmfem.errors import ConvergenceError, InputError
from tests.solvers.test_petsc_backend import _mpirun, needs_mpi, needs_petsc

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def scipy_2_3():
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    m = MTCModel(load_preset("2-3"), mesh_n=4)
    return m, m.equilibrium()


def _petsc_model(options=None):
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset
    return MTCModel(load_preset("2-3"), mesh_n=4, backend=PetscBackend(options=options))


@needs_petsc
def test_snes_options_are_honoured_and_reach_the_same_equilibrium(scipy_2_3, capfd):
    # source: the scipy trust region's equilibrium (displacements to 1e-9); PETSc's monitor
    # and view show that the static solve is a SNES solve with the options given
    m, st = scipy_2_3
    capfd.readouterr()
    res = _petsc_model("-snes_monitor -snes_view -ksp_type preonly").equilibrium()
    out = capfd.readouterr().out
    assert "SNES Function norm" in out and "type: newtonls" in out
    x0 = m.initial_positions("undeformed")
    assert np.linalg.norm(res.x - st.x) <= 1e-9 * np.linalg.norm(st.x - x0)


@needs_petsc
def test_one_tangent_of_the_model_serves_the_static_solve(scipy_2_3):
    # source: the scipy trust region's equilibrium; the SNES evaluations let go of each
    # tangent before the next (tmfem.solvers.petsc_snes, "Memory"), so the model assembled
    # one tangent matrix, refilled it at every evaluation, and returns it at the equilibrium
    m, st = scipy_2_3
    pm = _petsc_model()
    res = pm.equilibrium()
    x0 = m.initial_positions("undeformed")
    assert np.linalg.norm(res.x - st.x) <= 1e-9 * np.linalg.norm(st.x - x0)
    dist = pm.distributed
    assert len(dist._K) == 1 and res.tangent is dist._K[0] and res.tangent.version > 5
    from tmfem.fem.element import State
    _, K = dist.residual(State(x=res.x))
    assert K is not res.tangent      # the caller holds it: the model assembles another
    d = K.mat.copy()
    d.axpy(-1.0, res.tangent.mat)
    assert d.norm() <= 1e-12 * K.mat.norm()


@needs_petsc
def test_snes_with_a_loose_tolerance_stops_where_it_is_met(scipy_2_3):
    # source: the test |r| <= tol x force scale itself, and the scipy trust region's
    # equilibrium, which the tight solve from the loose state (the coarse levels of a mesh
    # sequencing) reaches; a state that meets the loose tolerance during the continuation
    # ends it instead of regularising a step that cannot move
    m, st = scipy_2_3
    pm = _petsc_model()
    loose = pm.equilibrium(tol=1e-4)
    assert np.linalg.norm(pm.residual(pm.reduce(loose.x))[0][pm.free]) <= 1e-4 * pm._force_scale(loose.x)
    tight = pm.equilibrium(x0=loose.x, tol=1e-9)
    assert np.linalg.norm(pm.residual(pm.reduce(tight.x))[0][pm.free]) <= 1e-9 * pm._force_scale(tight.x)
    # both solvers stop as soon as |r| <= tol x force scale; on this soft structure that
    # residual fixes the displacement to ~3e-6 only (the reference, solved from the undeformed
    # membrane, ended on a Newton step that went far below the tolerance)
    x0 = m.initial_positions("undeformed")
    assert np.linalg.norm(tight.x - st.x) <= 1e-5 * np.linalg.norm(st.x - x0)


@needs_petsc
def test_snes_from_an_interpolated_state_meets_a_loose_tolerance():
    # source: the test |r| <= tol x force scale itself. A Newton step from the state
    # interpolated off a coarser mesh (a level of the mesh sequencing) need not halve |r|;
    # with tol = 1e-4 that happens well inside 1e3 tol x force scale, which is not the
    # round-off floor (the step's predicted energy change is not round-off): the solve goes
    # on to the tolerance instead of stopping there
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset
    # the 1-4 as printed, with the S-tendon rest length that Tables 6.3/6.6 imply
    system = load_preset("1-4", as_printed=True).with_rest_lengths({"S1": 1.5025})
    coarse = MTCModel(system, mesh_n=10, backend=PetscBackend()).equilibrium(tol=1e-4)
    fine = MTCModel(system, mesh_n=20, backend=PetscBackend())
    x0 = fine.interpolate_from(MTCModel(system, mesh_n=10), coarse.x)
    res = fine.equilibrium(x0=x0, tol=1e-4)
    assert res.residual_history[0] > 1e-4 * fine._force_scale(x0)
    assert res.residual_history[-1] <= 1e-4 * fine._force_scale(res.x)


@needs_petsc
def test_snes_converged_reason_names_the_convergence_error():
    # every SNES solve stops after one function evaluation (-snes_max_funcs 1): the
    # continuation runs out and the error names PETSc's reason and the option it owes to
    with pytest.raises(ConvergenceError, match="SNES DIVERGED_FUNCTION_COUNT .* with the PETSc "
                                               "options -snes_max_funcs 1$"):
        _petsc_model("-snes_max_funcs 1").equilibrium()


@needs_petsc
@pytest.mark.parametrize("options, reason", [
    ("-snes_type foo", "86: Unable to find requested SNES type foo"),
    ("-snes_linesearch_type foo", "86: Unable to find requested Line Search type foo"),
])
def test_snes_options_that_petsc_refuses_are_input_errors(options, reason):
    # source: PETSc's refusal of an unknown SNES or line-search type when the SNES reads
    # the database: bad input named with PETSc's reason, before any iteration
    with pytest.raises(InputError, match=f"^MTC static solve \\(SNES\\): expected a type this "
                                         f"PETSc knows in the PETSc options, found PETSc error "
                                         f"{reason}$"):
        _petsc_model(options).equilibrium()


def _cli_static(petsc_options: str):
    """``tmfem static`` of the 2-3 at mesh 4 on the PETSc backend with PETSC_OPTIONS; the
    finished process (exit 0 asserted)."""
    env = dict(os.environ, PETSC_OPTIONS=petsc_options)
    p = subprocess.run([sys.executable, "-m", "tmfem", "static", "--preset", "2-3", "--mesh", "4",
                        "--backend", "petsc"], capture_output=True, text=True, cwd=ROOT, env=env)
    assert p.returncode == 0, p.stderr
    return p


@needs_petsc
def test_cli_snes_monitor_is_visible():
    # PETSC_OPTIONS reaches the SNES of the CLI's static solve; its monitor prints on stdout
    p = _cli_static("-snes_monitor")
    assert "SNES Function norm" in p.stdout
    assert "backend petsc (" in p.stderr
    assert "PETSc options" not in p.stderr          # the option was read: no warning


@needs_petsc
def test_cli_refuses_a_petsc_option_petsc_refuses_in_one_line():
    # an unknown KSP type in PETSC_OPTIONS: exit 2 (bad input) with PETSc's reason on one
    # line, no traceback
    env = dict(os.environ, PETSC_OPTIONS="-ksp_type foo")
    p = subprocess.run([sys.executable, "-m", "tmfem", "static", "--preset", "2-3", "--mesh", "4",
                        "--backend", "petsc"], capture_output=True, text=True, cwd=ROOT, env=env)
    errors = [line for line in p.stderr.splitlines() if "error" in line]
    assert p.returncode == 2 and "Traceback" not in p.stderr, p.stderr
    assert errors == ["tmfem static: error: linear solver (petsc): expected a type this PETSc "
                      "knows in the PETSc options, found PETSc error 86: Unable to find requested "
                      "KSP type foo"], p.stderr


@needs_petsc
def test_cli_warns_of_petsc_options_no_solver_read():
    # source: PETSc's own record of the options its objects read (PetscOptionsUsed): a
    # misspelt SNES option and an eigen option in a static run (no eigen solve) change
    # nothing, and the command says so once on stderr; the results are unchanged (exit 0)
    p = _cli_static("-snes_monitr -eps_ncv 30 -snes_converged_reason")
    warned = [line for line in p.stderr.splitlines() if "PETSc options that no solver" in line]
    assert len(warned) == 1 and "-eps_ncv -snes_monitr (" in warned[0], p.stderr
    assert "snes_converged_reason" not in warned[0]


def test_auto_backend_chooses_by_the_crossover(monkeypatch):
    # source: AUTO_CROSSOVER_DOFS (6500, the measured crossover of the module's constant)
    from tmfem.solvers import backends as b
    assert b.AUTO_CROSSOVER_DOFS == 6500
    assert b.choose_backend(n_dofs=6499, ranks=1) == "scipy"
    assert b.choose_backend(n_dofs=100, ranks=2) == "petsc"          # under mpiexec
    monkeypatch.setattr(b, "petsc_available", lambda: True)
    assert b.choose_backend(n_dofs=6500, ranks=1) == "petsc"
    monkeypatch.setattr(b, "petsc_available", lambda: False)
    assert b.choose_backend(n_dofs=10**6, ranks=1) == "scipy"       # PETSc not installed
    assert b.get_backend("auto", n_dofs=10**6).name == "scipy"
    with pytest.raises(InputError, match="expected the model's number of free dofs"):
        b.get_backend("auto")
    with pytest.raises(InputError, match="backend 'auto': option does not apply: solver"):
        b.get_backend("auto", n_dofs=10, solver="iterative")
    assert "auto" in b.backend_names()


def test_petsc_available_is_false_without_petsc4py(monkeypatch):
    monkeypatch.setitem(sys.modules, "petsc4py", None)
    from tmfem.solvers.backends import petsc_available
    assert petsc_available() is False


def test_auto_model_below_the_crossover_is_scipy():
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    m = MTCModel(load_preset("2-3"), mesh_n=4, backend="auto")
    assert m.ndof < 6500 and m.backend.name == "scipy"


@needs_mpi
@pytest.mark.parametrize("ranks", [2, pytest.param(3, marks=pytest.mark.slow)])
def test_snes_under_ranks_honours_options_and_reports_its_reason_once(scipy_2_3, ranks):
    # source: the scipy trust region's equilibrium (displacements to 1e-9); under mpiexec the
    # SNES monitor prints from rank 0 and a SNES failure on every rank is one error
    m, st = scipy_2_3
    p = _mpirun(ranks, "2-3", "4", "--options=-snes_monitor")
    assert p.returncode == 0, p.stderr
    lines = p.stdout.strip().splitlines()
    assert "SNES Function norm" in p.stdout
    run = json.loads(lines[-1])
    assert run["ranks"] == ranks
    x0 = m.reduce(m.initial_positions("undeformed"))
    xs = m.reduce(st.x)
    assert np.linalg.norm(np.array(run["x"]) - xs) <= 1e-9 * np.linalg.norm(xs - x0)
    p = _mpirun(ranks, "2-3", "4", "--options=-snes_max_funcs 1")
    assert p.returncode != 0
    assert p.stderr.count("SNES DIVERGED_FUNCTION_COUNT") == 1


@needs_mpi
@pytest.mark.slow
def test_sbc_snes_under_three_ranks_agrees_with_scipy():
    # source: the scipy SBC model's static solve from the undeformed membrane (MTC predictor,
    # then the SBC trust region); the SNES continuation on 3 ranks, the shells assembled rank
    # by rank: positions and rotations to 1e-9
    from tmfem.models.sbc.model import SBCModel
    from tmfem.system import load_preset
    m = SBCModel(load_preset("1-4"), mesh_n=4)
    st = m.equilibrium()
    p = _mpirun(3, "1-4", "4", "--model", "sbc")
    assert p.returncode == 0, p.stderr
    run = json.loads(p.stdout.strip().splitlines()[-1])
    assert run["ranks"] == 3
    u = st.state.x - m.start_state().x
    assert np.linalg.norm(np.array(run["x"]) - st.state.x) <= 1e-9 * np.linalg.norm(u)
    assert np.abs(np.array(run["R"]) - st.state.R).max() <= 1e-9


@needs_petsc
def test_snes_stops_at_once_on_a_mumps_failure_a_shift_cannot_cure():
    # source: MUMPS' return code INFOG(1) = -19 (a 1 MB working memory limit): the
    # continuation's larger shifts cannot cure it, so the static solve names it after its
    # first linear solve instead of raising the shift to 1e12 of its scale
    from tmfem.models.mtc.model import MTCModel
    from tmfem.solvers.petsc import PetscBackend
    from tmfem.system import load_preset
    m = MTCModel(load_preset("1-4"), mesh_n=10, backend=PetscBackend(options="-mat_mumps_icntl_23 1"))
    with pytest.raises(InputError, match=r"SNES\): expected the MUMPS factorisation to succeed, "
                                         r"found MUMPS INFOG\(1\) = -19"):
        m.equilibrium()


@needs_mpi
@pytest.mark.slow
def test_sbc_on_more_ranks_than_shells_agrees_with_scipy():
    # source: the scipy SBC model of a system of our own (a one-stage triangle) whose
    # membrane has 3 shells: on 4 ranks the last has none, and the static solve and the
    # modes still agree with scipy's
    from tmfem.models.sbc.model import SBCModel
    from tmfem.system import load_system
    system = ROOT / "tests" / "data" / "systems" / "triangle-1-3.toml"
    m = SBCModel(load_system(system), mesh_n=1)
    st = m.equilibrium()
    w2 = m.modes(k=12, at=st).omega2
    p = _mpirun(4, str(system), "1", "--model", "sbc")
    assert p.returncode == 0, p.stderr
    run = json.loads(p.stdout.strip().splitlines()[-1])
    assert run["ranks"] == 4
    u = st.state.x - m.start_state().x
    assert np.linalg.norm(np.array(run["x"]) - st.state.x) <= 1e-9 * np.linalg.norm(u)
    assert np.allclose(run["omega2"], w2, rtol=1e-8, atol=0)
