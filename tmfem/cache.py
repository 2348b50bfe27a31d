"""tmfem's on-disk cache: small results that take long to compute and depend only on their
inputs, kept as one JSON file per key so that the next process reads them instead.

Directory (the XDG base-directory convention): ``$TMFEM_CACHE_DIR`` when set, else
``$XDG_CACHE_HOME/tmfem`` (an absolute ``XDG_CACHE_HOME`` only, as the specification says),
else ``~/.cache/tmfem``. Each kind of result has a subdirectory (:class:`JsonCache`
``namespace``); an entry's file name is the SHA-256 of its key -- everything the result depends
on, tmfem's version included -- and the file repeats the key, which a read checks.

The cache never decides a result: a missing, unreadable, corrupt or mismatched entry is
logged and ignored (the caller recomputes), and a directory that cannot be written is
named in one warning per process, after which the results are just not stored. Entries are
written to a temporary name in the same directory and renamed (``os.replace``, atomic on
POSIX): a reader never sees half an entry. (:mod:`tmfem.io.atomic` does the same for the
commands' outputs; it lives in a layer above the models, which use this cache.) Deleting the
directory is always safe.

Within one process, :class:`MemoryMemo` keeps the last few values of a computation by the
:func:`content_digest` of its inputs (values that are not JSON, such as casadi Functions).
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
from collections import OrderedDict
from dataclasses import fields, is_dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from tmfem import __version__

log = logging.getLogger(__name__)

#: environment variable that overrides the cache directory
ENV_VAR = "TMFEM_CACHE_DIR"

#: directories whose write failed (warned about once per process)
_UNWRITABLE: set[Path] = set()


def cache_dir() -> Path:
    """The cache directory (module docstring); not created here."""
    d = os.environ.get(ENV_VAR)
    if d:
        return Path(d).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    base = Path(xdg) if os.path.isabs(xdg) else Path.home() / ".cache"
    return base / "tmfem"


class JsonCache:
    """Entries of one kind of result under ``cache_dir() / namespace``.

    Parameters
    ----------
    namespace : str
        The subdirectory (one per kind of result).
    """

    def __init__(self, namespace: str):
        self.namespace = namespace

    @property
    def directory(self) -> Path:
        """``cache_dir() / namespace``, evaluated at each use (the environment may change)."""
        return cache_dir() / self.namespace

    @staticmethod
    def full_key(key: dict) -> dict:
        """``key`` with tmfem's version added (a new version recomputes)."""
        return {**key, "tmfem": __version__}

    def path(self, key: dict) -> Path:
        """The entry's file: the SHA-256 of the key's canonical JSON."""
        text = json.dumps(self.full_key(key), sort_keys=True, allow_nan=False)
        return self.directory / f"{hashlib.sha256(text.encode()).hexdigest()}.json"

    def get(self, key: dict) -> dict | None:
        """The value stored under ``key``, or None (no entry; an unreadable, corrupt or
        mismatched one is logged and ignored)."""
        path = self.path(key)
        try:
            text = path.read_text()
        except FileNotFoundError:
            return None
        except OSError as e:
            log.info("cache entry %s is unreadable (%s): recomputing", path, e.strerror or e)
            return None
        try:
            entry = json.loads(text)
        except ValueError as e:
            log.info("cache entry %s is not valid JSON (%s): recomputing", path, e)
            return None
        if not isinstance(entry, dict) or entry.get("key") != self.full_key(key) \
                or not isinstance(entry.get("value"), dict):
            log.info("cache entry %s does not hold this key or this tmfem version (%s): recomputing",
                     path, __version__)
            return None
        log.debug("cache entry %s read", path)
        return entry["value"]

    def put(self, key: dict, value: dict) -> Path | None:
        """Store ``value`` (JSON-able) under ``key``; returns the file, or None when the
        directory cannot be written (one warning per directory and process)."""
        path = self.path(key)
        text = json.dumps({"key": self.full_key(key), "value": value}, sort_keys=True, allow_nan=False)
        tmp = None
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp")
            with os.fdopen(fd, "w") as fh:
                fh.write(text)
            os.replace(tmp, path)
            tmp = None
        except OSError as e:
            if path.parent not in _UNWRITABLE:
                _UNWRITABLE.add(path.parent)
                log.warning("cache directory %s is not writable (%s): results are not kept between runs "
                            "(set %s to a writable directory)", path.parent, e.strerror or e, ENV_VAR)
            return None
        finally:
            if tmp is not None and os.path.exists(tmp):
                os.unlink(tmp)
        log.debug("cache entry %s written", path)
        return path


def _feed(h, value) -> None:
    """Add ``value`` to the hash ``h``, tagged by its type (:func:`content_digest`)."""
    if value is None or isinstance(value, (bool, int, float, complex, str, bytes, np.generic)):
        h.update(f"{type(value).__name__}:{value!r};".encode())
    elif isinstance(value, np.ndarray):
        a = np.ascontiguousarray(value)
        h.update(f"ndarray:{a.dtype.str}:{a.shape};".encode())
        h.update(a.tobytes())
    elif is_dataclass(value) and not isinstance(value, type):
        h.update(f"{type(value).__qualname__}(".encode())
        for f in fields(value):
            h.update(f"{f.name}=".encode())
            _feed(h, getattr(value, f.name))
        h.update(b")")
    elif isinstance(value, dict):
        h.update(f"dict{len(value)}{{".encode())
        for k in sorted(value, key=repr):
            _feed(h, k)
            _feed(h, value[k])
        h.update(b"}")
    elif isinstance(value, (list, tuple)):
        h.update(f"{type(value).__name__}{len(value)}[".encode())
        for v in value:
            _feed(h, v)
        h.update(b"]")
    else:
        raise TypeError(f"content_digest: expected numbers, strings, arrays, dataclasses, dicts, "
                        f"lists or tuples of them, found {type(value).__name__}")


def content_digest(*values) -> str:
    """SHA-256 (hex) of the content of ``values``: numbers and strings by type and repr,
    arrays by dtype, shape and bytes, dataclasses field by field, dicts (by sorted key),
    lists and tuples element by element, recursively. Equal content gives equal digests
    whatever the objects; TypeError for any other type (its content is unknown)."""
    h = hashlib.sha256()
    for v in values:
        _feed(h, v)
    return h.hexdigest()


class MemoryMemo:
    """The values of the last ``size`` distinct inputs of one computation in this process, by
    their :func:`content_digest`, the least recently used dropped first.

    Parameters
    ----------
    size : int
        How many values are kept.
    """

    def __init__(self, size: int):
        self.size = size
        self._values: OrderedDict = OrderedDict()

    def get(self, inputs, compute: Callable):
        """The value kept for ``inputs`` (anything :func:`content_digest` takes), else
        ``compute()`` kept and returned; inputs it cannot digest are computed every time."""
        try:
            key = content_digest(inputs)
        except TypeError:
            return compute()
        if key in self._values:
            self._values.move_to_end(key)
            return self._values[key]
        value = self._values[key] = compute()
        while len(self._values) > self.size:
            self._values.popitem(last=False)
        return value
