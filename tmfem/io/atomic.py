"""Output files written atomically: the data goes to a temporary name in the same directory,
which is renamed onto the final name when it is complete (``os.replace``, atomic on POSIX).
A reader -- or a second run -- never sees half a file; a run that stops leaves the previous
file or none, and its temporary files are removed (also by the CLI's signal handlers,
:func:`remove_pending`).
"""
from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path

#: Temporary files being written by this process (removed by :func:`remove_pending`).
_PENDING: set[Path] = set()


def temporary_name(path) -> Path:
    """A hidden name in ``path``'s directory that keeps its suffix (writers such as meshio
    choose the format by the suffix): ``dir/.name.tmp-PID.suffix``."""
    path = Path(path)
    return path.with_name(f".{path.stem}.tmp-{os.getpid()}{path.suffix}")


@contextmanager
def atomic_path(path):
    """Yield a temporary path to write ``path`` through; on success it is renamed onto
    ``path``, on an error it is removed and the error propagates."""
    path = Path(path)
    tmp = temporary_name(path)
    _PENDING.add(tmp)
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        _PENDING.discard(tmp)
        if tmp.exists():
            tmp.unlink()


@contextmanager
def atomic_open(path, mode: str = "w", **kwargs):
    """``open`` for writing ``path`` atomically (:func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, mode, **kwargs) as fh:
        yield fh


def write_text(path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; returns ``path``."""
    with atomic_open(path, "w") as fh:
        fh.write(text)
    return Path(path)


def remove_pending() -> None:
    """Remove the temporary files of writes still under way (before the process ends on a
    signal)."""
    for tmp in list(_PENDING):
        try:
            tmp.unlink()
        except OSError:
            pass
    _PENDING.clear()
