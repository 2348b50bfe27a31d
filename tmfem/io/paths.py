"""Output paths checked before any work: a known suffix, a writable parent directory."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from tmfem.errors import InputError

SUFFIXES = (".vtu", ".xdmf", ".vtk")


def check_path(path, *, suffixes=SUFFIXES) -> Path:
    """Validate an output path: a known suffix, not a directory; create missing parents."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise InputError(f"output file {str(path)!r}: expected a suffix in {list(suffixes)}, "
                         f"found {path.suffix or 'none'!r}")
    if path.is_dir():
        raise InputError(f"output file {str(path)!r} is a directory")
    parent = path.parent
    if parent.exists() and not parent.is_dir():
        raise InputError(f"output file {str(path)!r}: parent {str(parent)!r} is not a directory")
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"output file {str(path)!r}: cannot create directory "
                         f"{str(parent)!r} ({exc.strerror})") from None
    _probe(parent, f"output file {str(path)!r}: directory {str(parent)!r}")
    return path


def _probe(directory: Path, what: str) -> None:
    """Create and remove a file in ``directory``: the permission bits do not tell (root
    passes them; a read-only mount or a pseudo-filesystem such as /proc refuses the write)."""
    if not os.access(directory, os.W_OK):
        raise InputError(f"{what} is not writable")
    try:
        with tempfile.NamedTemporaryFile(dir=directory, prefix=".tmfem-probe-"):
            pass
    except OSError as exc:
        raise InputError(f"{what} is not writable ({exc.strerror})") from None


def check_dir(path) -> Path:
    """Validate an output directory before any work: not a file, creatable, writable."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"output directory {str(path)!r} is a file")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"output directory {str(path)!r}: cannot create it "
                         f"({exc.strerror})") from None
    _probe(path, f"output directory {str(path)!r}")
    return path
