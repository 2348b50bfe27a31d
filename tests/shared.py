"""Results shared by the processes of one test run (the pytest-xdist workers): computed by the
first process that needs them, under a lock, in the base temp directory the workers share, and
read by the others."""
from __future__ import annotations

import contextlib
import fcntl
import hashlib
import os
import pickle
from pathlib import Path


def shared_dir(tmp_path_factory) -> Path:
    """A directory of this run that every xdist worker sees (the parent of the workers' base
    temp directories; a run without xdist has its own base temp directory)."""
    base = tmp_path_factory.getbasetemp()
    d = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "shared"
    d.mkdir(exist_ok=True)
    return d


@contextlib.contextmanager
def locked(path: Path):
    """Hold an exclusive lock on the file ``path`` (created if missing) within the block."""
    with open(path, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)            # released when the file is closed
        yield


class Once:
    """``once(key, compute)``: the value of ``compute()`` for ``key`` (a repr-able, e.g. a
    tuple of the command's arguments), computed once per test run: the first process that asks
    computes and pickles it, the others (and later calls) read it."""

    def __init__(self, directory: Path):
        self.directory, self._memo = directory, {}

    def __call__(self, key, compute):
        if key not in self._memo:
            name = hashlib.sha256(repr(key).encode()).hexdigest()[:24]
            f = self.directory / f"{name}.pickle"
            with locked(self.directory / f"{name}.lock"):
                if f.exists():
                    value = pickle.loads(f.read_bytes())
                else:
                    value = compute()
                    f.write_bytes(pickle.dumps(value))
            self._memo[key] = value
        return self._memo[key]
