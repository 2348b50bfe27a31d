"""The CLI's message channel: warnings once, one line, without source paths; progress bars
only on a terminal (never in a redirected log, never with --quiet or TQDM_DISABLE)."""
import fcntl
import os
import pty
import struct
import subprocess
import sys
import termios
import warnings
from pathlib import Path

import numpy as np
import pytest

from tests.cli.test_cli_misuse import run
from tmfem.cli import presets

ROOT = Path(__file__).resolve().parents[2]


def test_warnings_once_without_source_path(monkeypatch, capsys):
    def noisy(args):
        for _ in range(3):
            warnings.warn("No artists with labels found", UserWarning)
            np.sqrt(np.array([-1.0]))                      # numpy's RuntimeWarning
        return {"presets": []}
    monkeypatch.setattr(presets, "run", noisy)
    with warnings.catch_warnings():
        warnings.simplefilter("always")                    # every call reaches the CLI
        rc, _, err = run(["presets"], capsys)
    assert rc == 0
    lines = err.strip().splitlines()
    assert lines == ["tmfem: WARNING: No artists with labels found (UserWarning)",
                     "tmfem: WARNING: invalid value encountered in sqrt (RuntimeWarning)"], err
    assert ".py" not in err


def vibrate(stderr, *, quiet=False, **env):
    """``tmfem vibrate`` of 300 steps, its stderr to ``stderr``."""
    full = {k: v for k, v in os.environ.items() if k not in ("TQDM_DISABLE", "NO_COLOR")}
    full.update(PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1", **env)
    argv = ["vibrate", "--preset", "1-4", "--t-end", "3"] + (["--quiet"] if quiet else [])
    return subprocess.run([sys.executable, "-m", "tmfem", *argv], stdout=subprocess.DEVNULL,
                          stderr=stderr, env=full, timeout=120)


def on_terminal(**env):
    """stderr of a run whose stderr is a terminal (a pseudo-terminal of 24 x 100)."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    try:
        r = vibrate(slave, **env)
        os.close(slave)
        chunks = []
        while True:
            try:
                data = os.read(master, 65536)
            except OSError:
                break
            if not data:
                break
            chunks.append(data)
    finally:
        os.close(master)
    assert r.returncode == 0
    return b"".join(chunks).decode(errors="replace")


@pytest.mark.slow
def test_progress_bar_on_a_terminal_only(tmp_path):
    assert "/300" in on_terminal()
    log = tmp_path / "log.txt"
    with open(log, "w") as fh:
        assert vibrate(fh).returncode == 0
    text = log.read_text()
    assert "\r" not in text and "/300" not in text and "vibrate 1-4:" not in text


@pytest.mark.parametrize("env", [{"TQDM_DISABLE": "1"}, {"quiet": True}])
def test_no_progress_bar_when_disabled(env):
    text = on_terminal(**env)
    assert "/300" not in text and "\r" not in text.replace("\r\n", "\n")


def test_no_color_draws_plain_ascii():
    text = on_terminal(NO_COLOR="1")
    assert "/300" in text and not any(ord(c) > 127 for c in text)


def test_edge_membrane_points_snapped_silently(capsys):
    # eq. 5.73's point (2, 1) lies on the edge of the 1-4(D) membrane (side 1.9997 m): moved
    # inside by the documented rule, without a message on every run
    rc, out, err = run(["control", "pbh", "--preset", "1-4D"], capsys)
    assert rc == 0 and "controllable True" in out
    assert "outside the mesh" not in err
