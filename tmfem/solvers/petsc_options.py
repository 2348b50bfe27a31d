"""PETSc's options database as tmfem reads it: options given as a string or a dict, which
of them a solver has read, and which values PETSc refused.

A PETSc option changes a solver only if the solver reads it; a misspelt one, or one of a
solver the run does not create, changes nothing. PETSc records which options its objects
read (``PetscOptionsUsed``); :func:`unused_options` lists the solver options nobody read, so
that the CLI can say so instead of ignoring them. A value that PETSc refuses (an unknown
type, a value out of range) raises a PETSc error where it is read; :func:`option_error`
turns it into an :class:`~tmfem.errors.InputError` with PETSc's reason.
"""
from __future__ import annotations

import ctypes
import functools
import re
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


#: PETSc error codes that a value of the options database causes wherever it is read: an
#: unknown type (``-ksp_type foo``: PETSC_ERR_UNKNOWN_TYPE) and a factorisation package PETSc
#: does not have for the matrix (``-pc_factor_mat_solver_type foo``: PETSC_ERR_MISSING_FACTOR)
OPTION_ERRORS = {86: "a type this PETSc knows", 92: "a factorisation package this PETSc has "
                 "for the matrix (-pc_factor_mat_solver_type)"}


def petsc_reason(exc) -> str:
    """PETSc's own reason for the error ``exc`` (a ``petsc4py.PETSc.Error``): the last line
    of its traceback without the rank prefix, such as ``Unable to find requested KSP type
    foo``; ``error code N`` when it has no traceback."""
    lines = [line.split("] ", 1)[-1] for line in str(exc).splitlines() if line.strip()]
    return lines[-1] if lines else f"error code {getattr(exc, 'ierr', '?')}"


def option_error(exc, what: str) -> InputError | None:
    """The :class:`~tmfem.errors.InputError` of a PETSc error that a value of the options
    database caused, else None: a code of :data:`OPTION_ERRORS`, or any error raised where
    an object reads the database (a ``...SetFromOptions...()`` in PETSc's traceback: a value
    out of range, such as ``-eps_nev -2``, or MUMPS' ``-mat_mumps_icntl_7 99``, which MUMPS
    reads at its factorisation)."""
    code = getattr(exc, "ierr", None)
    if code not in OPTION_ERRORS and not re.search(r"SetFromOptions\w*\(\)", str(exc)):
        return None
    expected = OPTION_ERRORS.get(code, "option values this PETSc accepts")
    return InputError(f"{what}: expected {expected} in the PETSc options, found PETSc error "
                      f"{code}: {petsc_reason(exc)}")


def set_from_options(obj, what: str) -> None:
    """``obj.setFromOptions()`` (a SNES, KSP or EPS): the options database read into a
    solver; an option that PETSc refuses (an unknown type or value) is an
    :class:`~tmfem.errors.InputError` with PETSc's reason (:func:`option_error`), not a
    PETSc traceback."""
    try:
        obj.setFromOptions()
    except RuntimeError as exc:          # petsc4py.PETSc.Error
        err = option_error(exc, what)
        if err is None:
            raise
        raise err from None
