"""Every script of examples/ runs, in a reduced size where it has one, and prints what it
teaches; the numbers it returns are checked against an independent source.

The serial scripts run in this process (``runpy``, ``__name__ == "__main__"``, their arguments
in ``sys.argv``) in a scratch directory; the PETSc one runs under ``mpiexec -n 2`` and is
skipped, with the reason, where petsc4py, mpi4py or mpiexec is missing.
"""
import importlib.util
import json
import os
import runpy
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def run_example(name, args, monkeypatch, tmp_path):
    """Run examples/<name> as a script; return its ``main``'s namespace (to call it again)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setattr(sys, "argv", [str(EXAMPLES / name), *args])
    return runpy.run_path(str(EXAMPLES / name), run_name="example")


def test_every_example_is_tested():
    tested = {"own_system.py", "control_model.py", "controller_on_fe_plant.py",
              "shell_structure.py", "petsc_mpi.py"}
    assert {p.name for p in EXAMPLES.glob("*.py")} == tested


def test_own_system(monkeypatch, tmp_path, capsys):
    """The pentagon's MTC frequencies: five-fold symmetry gives equal pairs, and the lowest is
    within 3 % of the control-oriented model's 0.1713 Hz (an independent model with rigid bars
    and two membrane modes, docs/tutorial.md; the FE model gives 0.1734 Hz)."""
    ns = run_example("own_system.py", [], monkeypatch, tmp_path)
    f = ns["main"](["--out", "out"])
    assert (tmp_path / "out/modes.vtu").is_file()
    np.testing.assert_allclose(f[1], f[2], rtol=1e-6)
    assert abs(f[0] / 0.1713 - 1) < 0.03
    assert "MTC frequencies" in capsys.readouterr().out


@pytest.mark.slow
def test_control_model(monkeypatch, tmp_path):
    """The ss has one input per tendon and the LQR closed loop is stable (python-control's
    own poles of A - B K)."""
    ns = run_example("control_model.py", [], monkeypatch, tmp_path)
    G, poles = ns["main"]()
    assert G.ninputs == 5 and G.nstates == 24
    assert poles.real.max() < 0


@pytest.mark.slow
def test_controller_on_fe_plant(monkeypatch, tmp_path):
    """The LQR designed on the COM damps the push on both plants: the last second of the run
    is below the open loop's on each plant."""
    ns = run_example("controller_on_fe_plant.py", [], monkeypatch, tmp_path)
    runs = ns["main"](["--mesh", "4", "--t-end", "2"])
    for plant in ("COM", "MTC"):
        closed = np.abs(runs[plant, "LQR"][-100:]).max()
        open_ = np.abs(runs[plant, "open loop"][-100:]).max()
        assert closed < 0.5 * open_, plant


def test_shell_structure(monkeypatch, tmp_path):
    """Plate theory (Navier series): centre deflection and lowest frequency of the simply
    supported plate within 2 % on a 12 x 12 mesh; the following pressure of 100 q deflects it
    less than 100 x the linear solution (membrane stiffening)."""
    ns = run_example("shell_structure.py", [], monkeypatch, tmp_path)
    w_ratio, f_ratio, nonlinear = ns["main"](["--n", "12", "--out", "out"])
    assert abs(w_ratio - 1) < 0.02 and abs(f_ratio - 1) < 0.02
    assert 20 < nonlinear < 100
    assert (tmp_path / "out/plate_pressure.vtu").is_file()


def _mpi_reason():
    for module in ("petsc4py", "slepc4py", "mpi4py"):
        if importlib.util.find_spec(module) is None:
            return f"{module} is not installed (make install builds it)"
    if shutil.which("mpiexec") is None:
        return "mpiexec is not on the PATH"
    return None


@pytest.mark.skipif(_mpi_reason() is not None, reason=str(_mpi_reason()))
def test_petsc_mpi_agrees_with_scipy(tmp_path):
    """Two ranks with PETSc give the scipy backend's 12 frequencies (an independent solver
    stack: SuperLU and ARPACK in this process) to 1e-8."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1",
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    cmd = ["mpiexec", "--oversubscribe", "-n", "2", sys.executable,
           str(EXAMPLES / "petsc_mpi.py"), "--mesh", "6", "--json"]
    run = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    out = json.loads(run.stdout)
    assert out["ranks"] == 2
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    m = MTCModel(load_preset("1-4"), mesh_n=6)
    ref = m.modes(k=12, at=m.equilibrium()).freq_hz
    np.testing.assert_allclose(out["freq_hz"], ref, rtol=1e-8)
