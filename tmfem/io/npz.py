"""Reading the ``.npz`` archives tmfem writes (controllers, plants): the file's kind is
checked before numpy reads it, so that another file (a system file, a CSV, an ``.npy``)
is named as what it is, not as pickled data."""
from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from tmfem.errors import InputError


def file_kind(path) -> str:
    """What a file holds, from its first bytes: ``an .npz archive``, ``an .npy array``,
    ``a pickle``, ``a TOML file (a system file?)``, ``a text file`` or ``binary data``."""
    with open(path, "rb") as fh:
        head = fh.read(4096)
    if head.startswith(b"PK\x03\x04") or head.startswith(b"PK\x05\x06"):
        return "an .npz archive"
    if head.startswith(b"\x93NUMPY"):
        return "an .npy array"
    if head[:1] == b"\x80":
        return "a pickle"
    if not head:
        return "an empty file"
    try:
        text = head.decode("utf-8")
    except UnicodeDecodeError:
        return "binary data"
    if any(line.strip().startswith(("[", "N =", "name =")) for line in text.splitlines()[:40]):
        return "a TOML file (a system file?)"
    return "a text file"


def read_npz(path, *, expected: str):
    """``np.load`` of the archive ``path`` without pickles; ``expected`` names the writer
    (``an .npz written by `tmfem control hinf --save```) for the message.

    Raises
    ------
    InputError
        the file is missing, not an ``.npz`` archive (its kind, :func:`file_kind`) or broken.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: expected {expected}, found no such file")
    if not path.is_file():
        raise InputError(f"{path}: expected {expected}, found a directory or device, not a file")
    kind = file_kind(path)
    if kind != "an .npz archive":
        raise InputError(f"{path}: expected {expected}, found {kind}")
    try:
        return np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise InputError(f"{path}: expected {expected}, found a broken archive "
                         f"({exc or type(exc).__name__})") from None
