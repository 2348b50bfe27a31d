"""Output locks and signals under ``mpiexec -n 2 ... --backend petsc``, with real processes:
rank 0 takes the output directory's lock, a second run into it is refused on every rank at
once with one message (exit 2, no hang); SIGTERM or SIGINT to mpiexec or to one rank ends
every rank with one ``tmfem`` line and the signal's exit code (143 / 130), leaving the time
series marked partial and no lock file. Each rank runs tmfem as a child of
tests/mpi/rank_exit.py, which records the rank's own exit code (mpiexec reports its own
status when it is signalled). Skipped where petsc4py or mpiexec is missing."""
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.cli.test_hostile_processes import rows, wait_for
from tmfem.io.lock import LOCK_NAME
from tmfem.solvers.petsc_loader import petsc_available

ROOT = Path(__file__).resolve().parents[2]
MPIEXEC = shutil.which("mpiexec")

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not (MPIEXEC and petsc_available()),
                                 reason="petsc4py or mpiexec missing (install: make install)")]

RUN = ["vibrate", "--preset", "1-4", "--model", "mtc", "--mesh", "4", "--backend", "petsc"]


def mpiexec(directory, *argv, wrapper=True):
    """``mpiexec -n 2`` of tmfem ARGV (through tests/mpi/rank_exit.py, which writes
    DIRECTORY/rank<r>.exit), started in the background."""
    # a pytest process that initialised MPI has Open MPI's variables in its environment: a
    # child mpiexec that sees them thinks it is nested
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "ORTE_")) or "ALLOW_RUN_AS_ROOT" in k}
    env.update(PYTHONUNBUFFERED="1", OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT))
    program = ([str(ROOT / "tests" / "mpi" / "rank_exit.py"), str(directory)] if wrapper
               else ["-m", "tmfem"])
    cmd = [MPIEXEC, "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable,
           *program, *map(str, argv)]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env)


def rank_pid(directory, rank):
    """Process id of the tmfem process of ``rank`` writing into ``directory``."""
    for env in Path("/proc").glob("[0-9]*/environ"):
        try:
            cmd = (env.parent / "cmdline").read_bytes()
            variables = env.read_bytes().split(b"\0")
        except OSError:
            continue
        if (b"-m\0tmfem" in cmd and str(directory).encode() in cmd
                and f"OMPI_COMM_WORLD_RANK={rank}".encode() in variables):
            return int(env.parent.name)
    raise AssertionError(f"no rank {rank} found")


def tmfem_lines(err):
    return [line for line in err.splitlines() if line.startswith("tmfem ")]


def start_long_run(out):
    first = mpiexec(out, *RUN, "--t-end", "1000", "--csv", out / "h.csv")
    wait_for(lambda: rows(out / "h.csv.partial") > 20, timeout=180)
    return first


@pytest.mark.parametrize("sig, code, word, target", [
    (signal.SIGTERM, 143, "terminated", "mpiexec"),
    (signal.SIGTERM, 143, "terminated", 1),
    (signal.SIGINT, 130, "interrupted", 0),
])
def test_signal_ends_every_rank_once(tmp_path, sig, code, word, target):
    out = tmp_path / "out"
    first = start_long_run(out)
    try:
        assert "(tmfem vibrate" in (out / LOCK_NAME).read_text()
        if target == "mpiexec":
            first.send_signal(sig)
        else:
            os.kill(rank_pid(out, target), sig)
        _, err = first.communicate(timeout=60)
    finally:
        if first.poll() is None:
            first.kill()
    # rank 0 ends with the signal's code and the job says it once; mpiexec passes its own
    # SIGINT to the ranks as SIGTERM (Open MPI) and exits with its own status then
    assert (out / "rank0.exit").read_text().strip() == str(code), err
    assert tmfem_lines(err)[-1] == f"tmfem vibrate: {word}", err
    assert [line for line in tmfem_lines(err) if "terminated" in line or "interrupted" in line
            ] == [f"tmfem vibrate: {word}"], err
    assert "Traceback" not in err
    if target != "mpiexec":
        assert first.returncode == code, err
    # the series is marked partial, the lock and temporary files are gone
    assert (out / "h.csv.partial").exists() and not (out / "h.csv").exists()
    assert not (out / LOCK_NAME).exists()
    assert not list(out.rglob(".*tmp-*"))


def test_second_run_refused_on_every_rank(tmp_path):
    out = tmp_path / "out"
    first = start_long_run(out)
    try:
        holder = (out / LOCK_NAME).read_text()
        # a second job into the same directory: refused on both ranks before any work
        t0 = time.monotonic()
        second = mpiexec(out, *RUN, "--t-end", "0.1", "--csv", out / "g.csv", wrapper=False)
        _, err = second.communicate(timeout=120)
        assert second.returncode == 2, err
        errors = [line for line in tmfem_lines(err) if "error:" in line]
        assert len(errors) == 1 and "is in use by" in errors[0], err
        assert holder.split(" (")[0] in errors[0]                   # names the first (its pid)
        assert "MPI_ABORT" not in err and time.monotonic() - t0 < 120
        assert not (out / "g.csv").exists() and not (out / "g.csv.partial").exists()
        # a serial run is refused as well
        serial = subprocess.run([sys.executable, "-m", "tmfem", *RUN[:-2], "--t-end", "0.1",
                                 "--csv", out / "g.csv"], capture_output=True, text=True,
                                env=dict(os.environ, PYTHONPATH=str(ROOT)), timeout=120)
        assert serial.returncode == 2 and "is in use by" in serial.stderr
    finally:
        first.send_signal(signal.SIGTERM)
        first.communicate(timeout=60)
    assert not (out / LOCK_NAME).exists()
