"""PETSc's options database as tmfem reads it: options given as a string or a dict, and
which of them a solver has read.

A PETSc option changes a solver only if the solver reads it; a misspelt one, or one of a
solver the run does not create, changes nothing. PETSc records which options its objects
read (``PetscOptionsUsed``); :func:`unused_options` lists the solver options nobody read, so
that the CLI can say so instead of ignoring them.
"""
from __future__ import annotations

import ctypes
import functools
import shlex
import sys

from tmfem.errors import InputError


def parse_options(options) -> dict:
    """PETSc options as ``{name: value}`` (names without the leading '-') from a dict, a
    string ``"-ksp_type cg -ksp_rtol 1e-9 -ksp_view"`` or None."""
    if options is None:
        return {}
    if isinstance(options, dict):
        return {str(k).lstrip("-"): ("" if v is None else str(v)) for k, v in options.items()}
    if not isinstance(options, str):
        raise InputError(f"petsc options: expected a dict or a string such as '-ksp_type cg', "
                         f"found {type(options).__name__}")
    out, key = {}, None
    for tok in shlex.split(options):
        if tok.startswith("-") and not _is_number(tok):
            key = tok.lstrip("-")
            out[key] = ""
        elif key is None:
            raise InputError(f"petsc options: expected '-name value' pairs, found {tok!r} first")
        else:
            out[key] = tok
            key = None
    return out


#: prefixes of the options of the PETSc and SLEPc objects tmfem creates (SNES, KSP, PC, Mat
#: and its MUMPS factorisation, EPS, ST): those :func:`unused_options` reports
SOLVER_PREFIXES = ("snes_", "ksp_", "pc_", "mat_", "eps_", "st_")


@functools.cache
def _library(path: str):
    """ctypes handle of a loaded shared library (its dependencies' symbols resolve through it)."""
    return ctypes.CDLL(path)


def option_used(PETSc, name: str) -> bool:
    """Whether a PETSc object has read the option ``name`` (without '-') of the options
    database: PETSc's ``PetscOptionsUsed``, which petsc4py does not wrap (the library
    handle of petsc4py's extension module resolves libpetsc's symbols)."""
    used = ctypes.c_int(0)
    _library(PETSc.__file__).PetscOptionsUsed(None, name.encode(), ctypes.byref(used))
    return bool(used.value)


def unused_options() -> list[str]:
    """The solver options (:data:`SOLVER_PREFIXES`) of PETSc's options database
    (``PETSC_OPTIONS``, the command line) that no PETSc or SLEPc object has read so far, as
    ``-name``: a misspelt option, or one of a solver the run did not create. Empty when
    PETSc is not loaded. (The ``options=`` of a :class:`PetscBackend` live in the database
    only while its solvers run: :meth:`tmfem.solvers.petsc.PetscBackend.unused_options`.)"""
    if "petsc4py.PETSc" not in sys.modules:
        return []
    PETSc = sys.modules["petsc4py.PETSc"]
    return [f"-{name}" for name in sorted(PETSc.Options().getAll())
            if name.startswith(SOLVER_PREFIXES) and not option_used(PETSc, name)]


def _is_number(tok: str) -> bool:
    try:
        float(tok)
        return True
    except ValueError:
        return False
