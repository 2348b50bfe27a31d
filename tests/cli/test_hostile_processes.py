"""Concurrent and interrupted runs, with real processes: a second run into an output
directory in use fails at once naming the first (the lock of tmfem.io.lock); SIGINT and
SIGTERM end a real run with one line and exit 130 / 143, leaving its time series marked
partial (NAME.csv.partial, the .pvd's incomplete comment) and no lock or temporary file."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tmfem.io.lock import LOCK_NAME
from tmfem.io.series import INCOMPLETE

ROOT = Path(__file__).resolve().parents[2]


def tmfem(*argv, **kw):
    env = dict(os.environ, PYTHONUNBUFFERED="1", OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT))
    return subprocess.Popen([sys.executable, "-m", "tmfem", *map(str, argv)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, env=env, text=True, **kw)


def wait_for(cond, timeout=90.0):
    t0 = time.monotonic()
    while not cond():
        if time.monotonic() - t0 > timeout:
            raise AssertionError("timed out")
        time.sleep(0.2)


def rows(path):
    return path.read_text().count("\n") if path.exists() else 0


@pytest.mark.parametrize("sig, code, word", [pytest.param(signal.SIGTERM, 143, "terminated", marks=pytest.mark.slow),
                                             (signal.SIGINT, 130, "interrupted")])
def test_second_run_refused_and_signal_leaves_partial_files(tmp_path, sig, code, word):
    out = tmp_path / "out"
    csv = out / "h.csv"
    partial = out / "h.csv.partial"
    first = tmfem("vibrate", "--preset", "1-4", "--t-end", "1000", "--csv", csv,
                  "--vtk", out / "series", "--vtk-every", "50")
    try:
        wait_for(lambda: rows(partial) > 20)              # running: a header and rows
        assert not csv.exists()
        holder = (out / LOCK_NAME).read_text()
        assert f"pid {first.pid} (tmfem vibrate" in holder
        # a second run into the same directory: refused at once, naming the first
        t0 = time.monotonic()
        second = tmfem("vibrate", "--preset", "1-4", "--t-end", "0.1", "--csv", out / "g.csv")
        _, err = second.communicate(timeout=60)
        assert second.returncode == 2, err
        line = err.strip().splitlines()[-1]
        assert line.startswith("tmfem vibrate: error: output directory") and "is in use by" in line
        assert f"pid {first.pid} (tmfem vibrate" in line
        assert time.monotonic() - t0 < 60 and not (out / "g.csv").exists()
        # the signal: one line, the code, files marked partial
        first.send_signal(sig)
        _, err = first.communicate(timeout=60)
    finally:
        if first.poll() is None:
            first.kill()
    assert first.returncode == code, err
    assert "Traceback" not in err and err.strip().splitlines()[-1] == f"tmfem vibrate: {word}"
    assert partial.exists() and not csv.exists()
    assert rows(partial) > 20
    pvd = next((out / "series").glob("*.pvd"))
    assert INCOMPLETE in pvd.read_text()
    assert not (out / LOCK_NAME).exists()
    assert not [p for p in out.rglob(".*tmp-*")]
    # the directory is free again; a run that ends renames its series to the final names
    done = tmfem("vibrate", "--preset", "1-4", "--t-end", "0.1", "--csv", csv,
                 "--vtk", out / "series", "--vtk-every", "5")
    _, err = done.communicate(timeout=120)
    assert done.returncode == 0, err
    assert csv.exists() and not partial.exists()
    assert INCOMPLETE not in pvd.read_text()
    assert csv.read_text().count("\n") == 12         # header, t = 0 and 10 steps of 0.01 s


@pytest.mark.slow
def test_two_study_runs_into_one_directory(tmp_path):
    out = tmp_path / "study"
    first = tmfem("study", "--preset", "2-3", "--out", out, "--map-grid", "60")
    try:
        wait_for(lambda: (out / LOCK_NAME).exists())
        second = tmfem("study", "--preset", "1-4", "--out", out, "--map-grid", "0")
        _, err = second.communicate(timeout=60)
        assert second.returncode == 2 and f"pid {first.pid} (tmfem study" in err, err
    finally:
        first.send_signal(signal.SIGTERM)
        first.communicate(timeout=60)
    assert first.returncode in (0, 143)
    # a directory whose run did not end says so (its files may mix two runs)
    assert (out / "INCOMPLETE").exists() == (first.returncode == 143)
    done = tmfem("study", "--preset", "1-4", "--out", out, "--mesh", "4", "--map-grid", "0")
    _, err = done.communicate(timeout=300)
    assert done.returncode == 0, err
    assert not (out / "INCOMPLETE").exists() and not (out / LOCK_NAME).exists()
