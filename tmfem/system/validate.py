"""Checks of a system file beyond its types: size, name, tendon list, list lengths and the
physical plausibility of every value (docs/guides/equilibrium.md, "Limits of the values").

Each check names the table and the field it refuses, says what was expected and what was
found; the types themselves are checked where the values are read (:mod:`tmfem.system.spec`).
A value of the wrong type is left to that reader, so the two never disagree.
"""
from __future__ import annotations

import math
import os
import re
import select
import stat
import time
from pathlib import Path

from tmfem.errors import InputError, shorten
from tmfem.system.topology import FAMILIES_D, FAMILIES_MN

#: Largest system file read [bytes]; the presets are below 8 kB, a 2000-stage file ~150 kB.
MAX_FILE_BYTES = 1 << 20
#: Longest wait for a pipe or FIFO given as the system file to deliver its data [s].
READ_TIMEOUT_S = 10.0

#: Plausibility bounds (SI units) of the numbers of a system file: (table, key) ->
#: (lower, upper, unit, what). Angles are bounded in magnitude. The table of
#: docs/guides/equilibrium.md lists the same numbers (tests/system/test_validate.py compares them).
BOUNDS = {
    ("membrane", "h"): (1e-7, 0.1, "m", "membrane thickness"),
    ("membrane", "E"): (1e5, 1e13, "Pa", "Young's modulus"),
    ("membrane", "rho"): (1.0, 1e5, "kg/m^3", "density"),
    ("membrane", "yield_stress"): (1e3, 1e11, "Pa", "yield stress"),
    ("membrane", "r_mb"): (1e-3, 1e3, "m", "membrane circumradius"),
    ("membrane", "corners"): (-1e3, 1e3, "m", "corner coordinate"),
    ("bar", "E"): (1e5, 1e13, "Pa", "Young's modulus"),
    ("bar", "rho"): (1.0, 1e5, "kg/m^3", "density"),
    ("bar", "d"): (1e-6, 10.0, "m", "bar diameter"),
    ("tendons.*", "E"): (1e5, 1e13, "Pa", "Young's modulus"),
    ("tendons.*", "rho"): (1.0, 1e5, "kg/m^3", "density"),
    ("tendons.*", "d"): (1e-6, 10.0, "m", "tendon diameter"),
    ("tendons.*", "yield_stress"): (1e3, 1e11, "Pa", "yield stress"),
    ("symmetric", "l"): (1e-3, 1e3, "m", "bar length"),
    ("symmetric", "r"): (1e-3, 1e3, "m", "stage base radius"),
    ("symmetric", "z"): (-1e3, 1e3, "m", "stage base height"),
    ("symmetric", "theta_deg"): (-360.0, 360.0, "deg", "declination"),
    ("symmetric", "psi_deg"): (-360.0, 360.0, "deg", "azimuth"),
    ("symmetric", "sigma_deg"): (-360.0, 360.0, "deg", "stage rotation"),
    ("general", "l"): (1e-3, 1e3, "m", "bar length"),
    ("general", "base"): (-1e3, 1e3, "m", "base node coordinate"),
    ("rest_lengths", "*"): (1e-3, 1e3, "m", "rest length"),
}

#: Characters of a system name: it becomes part of output file names (ParaView series,
#: report files), so letters, digits and ``_ . ( ) -``, at most 64, starting with a letter
#: or digit.
NAME_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.()-]{0,63}")

#: Tendon families of ``[[tendon]]`` entries (section 2.2).
FAMILIES = FAMILIES_MN + FAMILIES_D


def read_bounded(path, *, limit: int = MAX_FILE_BYTES, timeout: float = READ_TIMEOUT_S) -> bytes:
    """The bytes of the file at ``path``, at most ``limit``: a larger file, or an endless
    stream (``/dev/zero``, a pipe that does not stop), is refused after reading ``limit + 1``
    bytes; a pipe or FIFO that delivers nothing for ``timeout`` s is refused too.

    Raises
    ------
    InputError
        naming the file, the limit and what was found.
    """
    path = Path(path)
    try:
        st = os.stat(path)
        regular = stat.S_ISREG(st.st_mode)
        if regular and st.st_size > limit:
            raise InputError(f"system file {path}: expected at most {limit:,} bytes, found "
                             f"{st.st_size:,}")
        if stat.S_ISDIR(st.st_mode):
            raise InputError(f"system file {path}: expected a file, found a directory")
        fd = os.open(path, os.O_RDONLY | (0 if regular else os.O_NONBLOCK))
    except OSError as exc:
        raise InputError(f"cannot read system file {path}: {exc.strerror}") from None
    chunks, size, deadline = [], 0, time.monotonic() + timeout
    try:
        while size <= limit:
            if not regular:
                wait = deadline - time.monotonic()
                if wait <= 0 or not select.select([fd], [], [], wait)[0]:
                    raise InputError(f"system file {path}: expected its data within "
                                     f"{timeout:g} s, found {size:,} bytes and no end")
            try:
                chunk = os.read(fd, min(1 << 16, limit + 1 - size))
            except BlockingIOError:
                continue
            except OSError as exc:
                raise InputError(f"cannot read system file {path}: {exc.strerror}") from None
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    finally:
        os.close(fd)
    if size > limit:
        raise InputError(f"system file {path}: expected at most {limit:,} bytes, found more "
                         "(an endless stream or a file that is not a system file)")
    return b"".join(chunks)


def system_name(d: dict, where: str) -> str:
    """The system's ``name`` (refused unless it matches :data:`NAME_PATTERN`); a file without
    one is named after its stem, with other characters replaced by ``_``."""
    if "name" not in d:
        stem = re.sub(r"[^A-Za-z0-9_.()-]", "_", Path(where).stem).lstrip("_.()-")
        return stem[:64] or "system"
    name = d["name"]
    if not isinstance(name, str):
        raise InputError(f"{where}: expected 'name' to be a string, found {name!r}")
    if not NAME_PATTERN.fullmatch(name):
        raise InputError(f"{where}: expected 'name' of 1-64 letters, digits, '_', '.', '(', ')' "
                         f"or '-' starting with a letter or digit (it names output files), "
                         f"found {name!r}")
    return name


def _numbers(v):
    """The numbers of a value (a number, a list, a list of rows); other types give none."""
    if isinstance(v, bool):
        return []
    if isinstance(v, (int, float)):
        return [v] if math.isfinite(v) else []
    if isinstance(v, list):
        return [x for item in v for x in _numbers(item)]
    return []


def check_bounds(d: dict, where: str) -> None:
    """Every number of :data:`BOUNDS` within its bounds."""
    for (table, key), (lo, hi, unit, what) in BOUNDS.items():
        if table == "tendons.*":
            t = d.get("tendons")
            tables = ({f"tendons.{k}": v for k, v in t.items() if isinstance(v, dict)}
                      if isinstance(t, dict) else {})
        else:
            tables = {table: d.get(table)} if isinstance(d.get(table), dict) else {}
        for name, t in tables.items():
            keys = list(t) if key == "*" else [key] if key in t else []
            for k in keys:
                bad = [x for x in _numbers(t[k]) if not lo <= x <= hi]
                if bad:
                    raise InputError(f"{where} [{name}]: expected '{k}' ({what}) within "
                                     f"{lo:g}..{hi:g} {unit} (docs/guides/equilibrium.md, limits), "
                                     f"found {bad[0]!r}")


def check_tendon_list(entries, where: str, *, symmetric: bool) -> None:
    """``[[tendon]]`` entries: known families and names used once; not with ``[symmetric]``
    (whose topology is the standard one of section 2.2)."""
    if not isinstance(entries, list) or not entries:
        return
    if symmetric:
        raise InputError(f"{where}: [[tendon]] does not apply with [symmetric] (the standard "
                         "topology of section 2.2); expected it with [general] only")
    seen = {}
    for k, t in enumerate(entries):
        if not isinstance(t, dict):
            continue
        w = f"{where} [[tendon]] entry {k + 1}"
        fam, name = t.get("family"), t.get("name")
        if isinstance(fam, str) and fam not in FAMILIES:
            raise InputError(f"{w}: expected 'family' to be one of {list(FAMILIES)}, found {fam!r}")
        if isinstance(name, str):
            if name in seen:
                raise InputError(f"{w}: expected unique tendon names, found {name!r} again "
                                 f"(entry {seen[name] + 1})")
            seen[name] = k


def check_stage_lists(d: dict, N, where: str) -> None:
    """Lengths that fix the number of stages: ``[symmetric] theta_deg`` (one entry per
    stage, at least one) and ``[general] q`` (2 N + 5 N (M - 1) entries, eqs. 3.1-3.2)."""
    s = d.get("symmetric")
    if isinstance(s, dict) and isinstance(s.get("theta_deg"), list) and not s["theta_deg"]:
        raise InputError(f"{where} [symmetric]: expected 'theta_deg' to have one entry per "
                         "stage (at least 1), found []")
    g = d.get("general")
    if isinstance(g, dict) and isinstance(N, int) and N >= 3:
        n = len(_numbers(g.get("q")))
        if n and (n < 2 * N or (n - 2 * N) % (5 * N)):
            sizes = ", ".join(f"{2 * N + 5 * N * (M - 1)} for M = {M}" for M in (1, 2, 3))
            raise InputError(f"{where} [general]: expected 'q' to have 2 N + 5 N (M - 1) entries "
                             f"(N = {N}: {sizes}, ...), found {n}")
        M = 1 + (n - 2 * N) // (5 * N)
        nl = len(_numbers(g.get("l")))
        if n and nl not in (0, 1, M * N):
            raise InputError(f"{where} [general]: expected 'l' to have 1 or M N = {M * N} entries "
                             f"(M = {M} stages from 'q'), found {nl}")


def check_keys_used(system, d: dict, where: str) -> None:
    """Keys of ``[tendons.KEY]`` and ``[rest_lengths]`` that no tendon of the built
    ``system`` takes (a misspelt group would be ignored silently): refused, with the keys
    the system has. ``"*"`` (every tendon) is always taken."""
    groups = sorted({t.group for t in system.tendons})
    families = sorted({t.family for t in system.tendons})
    sections = d.get("tendons") if isinstance(d.get("tendons"), dict) else {}
    for key in sections:
        if key != "*" and key not in groups and key not in families:
            raise InputError(f"{where} [tendons.{key}]: expected a tendon group {groups}, a "
                             f"family {families} or \"*\", found {key!r}, which no tendon of "
                             "this system has")
    rest = d.get("rest_lengths") if isinstance(d.get("rest_lengths"), dict) else {}
    names = {t.name for t in system.tendons}
    for key in rest:
        if key not in names and key not in groups:
            raise InputError(f"{where} [rest_lengths]: expected tendon names or groups "
                             f"({shorten(groups)}), found {key!r}, which no tendon of this "
                             "system has")
