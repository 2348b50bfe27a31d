"""Atomic writes, the output-directory lock and the partial marks of a time series
(tmfem.io.atomic, tmfem.io.lock, tmfem.io.run, tmfem.io.series)."""
import numpy as np
import pytest

from tmfem.errors import OutputBusy
from tmfem.io.atomic import atomic_open, atomic_path, remove_pending
from tmfem.io.lock import LOCK_NAME, OutputLock
from tmfem.io.run import RunOutputs, partial_name
from tmfem.io.series import INCOMPLETE


def test_atomic_write_replaces_only_when_complete(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("old\n")
    with pytest.raises(RuntimeError):
        with atomic_open(p) as fh:
            fh.write("half")
            raise RuntimeError("stopped")
    assert p.read_text() == "old\n" and [q.name for q in tmp_path.iterdir()] == ["a.csv"]
    with atomic_open(p) as fh:
        fh.write("new\n")
        assert p.read_text() == "old\n"                   # the reader sees the old file
    assert p.read_text() == "new\n"


def test_pending_temporary_files_are_removed(tmp_path):
    ctx = atomic_path(tmp_path / "m.vtu")
    tmp = ctx.__enter__()
    tmp.write_text("partial")
    assert tmp.suffix == ".vtu" and tmp.parent == tmp_path and tmp.name.startswith(".m.tmp-")
    remove_pending()                                      # what the signal handlers do
    assert not tmp.exists()


def test_second_lock_names_the_first(tmp_path):
    first, second = OutputLock(), OutputLock()
    first.acquire(tmp_path / "out", label="tmfem vibrate")
    with pytest.raises(OutputBusy, match=r"'.*out' is in use by pid \d+ \(tmfem vibrate, started"):
        second.acquire(tmp_path / "out", label="tmfem study")
    first.release()
    assert not (tmp_path / "out" / LOCK_NAME).exists()
    second.acquire(tmp_path / "out", label="tmfem study")
    assert "tmfem study" in (tmp_path / "out" / LOCK_NAME).read_text()
    second.release()


def test_stale_lock_file_does_not_block(tmp_path):
    (tmp_path / LOCK_NAME).write_text("pid 1 (tmfem vibrate, started long ago)\n")
    lock = OutputLock()
    lock.acquire(tmp_path)                                # nobody holds the flock
    lock.release()


def run_outputs(tmp_path, **kw):
    return RunOutputs(csv_path=tmp_path / "h.csv", columns=["t", "theta_11"],
                      vtk_dir=tmp_path / "s", vtk_every=1, name="run", **kw)


def frame(out, t):
    out.series.append(t, np.zeros((3, 3)), [("triangle", np.array([[0], [1], [2]]))])


@pytest.mark.parametrize("complete", [True, False])
def test_time_series_marked_until_complete(tmp_path, complete):
    (tmp_path / "h.csv").write_text("t [s]\nearlier run\n")
    out = run_outputs(tmp_path)
    assert not (tmp_path / "h.csv").exists()              # never beside this run's rows
    out.row(0.0, np.array([0.1]))
    frame(out, 0.0)
    pvd = out.series.pvd
    assert INCOMPLETE in pvd.read_text()
    out.close(complete=complete)
    assert (tmp_path / "h.csv").exists() == complete
    assert partial_name(tmp_path / "h.csv").exists() != complete
    assert (INCOMPLETE in pvd.read_text()) != complete
    text = (tmp_path / ("h.csv" if complete else "h.csv.partial")).read_text()
    assert text == "t [s],theta_11 [rad]\n0,0.1\n"


def test_write_series_ends_complete(tmp_path):
    from tmfem.io.series import write_series
    pvd = write_series(tmp_path, [(0.0, np.zeros((3, 3)), [("triangle", np.array([[0], [1], [2]]))])])
    assert INCOMPLETE not in pvd.read_text()


def test_nonfinite_row_is_refused(tmp_path):
    from tmfem.errors import ConvergenceError
    out = run_outputs(tmp_path)
    out.row(0.0, np.array([0.1]))
    with pytest.raises(ConvergenceError, match=r"t = 0.01 s: non-finite values of theta_11"):
        out.row(0.01, np.array([np.nan]))
    out.close(complete=False)
    assert partial_name(tmp_path / "h.csv").read_text().count("\n") == 2     # header, t = 0
