"""One run per output directory: a lock file ``.tmfem.lock`` held (``flock``) for the whole
run in every directory a command writes to. A second run that would write into a directory
in use fails at once and names the first (its process id, command line and start time);
the lock goes with the process, also when it is killed, so a stale file never blocks.
"""
from __future__ import annotations

import fcntl
import os
import shlex
import sys
import time
from pathlib import Path

from tmfem.errors import OutputBusy

LOCK_NAME = ".tmfem.lock"


class OutputLock:
    """Locks on output directories, taken by :meth:`acquire` and given back by
    :meth:`release` (the lock files are removed)."""

    def __init__(self):
        self._held: list[tuple[Path, int]] = []

    def acquire(self, directory, *, label: str = "") -> None:
        """Lock ``directory`` (created when missing; a directory that cannot be created is
        left to the output checks, which report it).

        Raises
        ------
        OutputBusy
            naming the directory and the run that holds it.
        """
        directory = Path(directory)
        if any(d == directory.resolve() for d, _ in self._held):
            return
        try:
            directory.mkdir(parents=True, exist_ok=True)
        except OSError:
            return
        path = directory / LOCK_NAME
        while True:
            try:
                fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError:
                return                                # not writable: the output checks say so
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.pread(fd, 4096, 0).decode(errors="replace").strip() or "another run"
                os.close(fd)
                raise OutputBusy(f"output directory {str(directory)!r} is in use by {holder}; "
                                 "expected one run per output directory (wait for it to end or "
                                 "choose another directory)") from None
            # the holder may have removed the file between our open and flock: retry then
            try:
                same = os.fstat(fd).st_ino == os.stat(path).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        stamp = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
        text = f"pid {os.getpid()} ({label or shlex.join(sys.argv)}, started {stamp})\n"
        os.ftruncate(fd, 0)
        os.pwrite(fd, text.encode(), 0)
        self._held.append((directory.resolve(), fd))

    def release(self) -> None:
        """Remove the lock files and give the locks back (idempotent)."""
        while self._held:
            directory, fd = self._held.pop()
            try:
                os.unlink(directory / LOCK_NAME)      # still locked: nobody holds it meanwhile
            except OSError:
                pass
            os.close(fd)
