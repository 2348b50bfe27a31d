"""petsc4py and slepc4py, imported and initialised on first use.

The PETSc backend's modules (:mod:`tmfem.solvers.petsc`, :mod:`tmfem.solvers.distributed`)
import this module at module level and call
:func:`petsc_modules` where they need PETSc, so that importing them costs nothing on a
machine without PETSc and ``import tmfem`` never loads it (docs/architecture.md,
"Imports").
"""
from __future__ import annotations

import ctypes
import functools
import logging
import os

from tmfem.errors import BackendUnavailable

log = logging.getLogger(__name__)

PETSC_INSTALL = "make install  (runs scripts/install_petsc.sh; see docs/guides/backends.md)"


def petsc_modules():
    """``(PETSc, SLEPc)`` imported (and initialised) lazily; :class:`BackendUnavailable`
    naming the install command when petsc4py/slepc4py are missing or do not load."""
    try:
        import petsc4py
        import slepc4py
        petsc4py.init()
        slepc4py.init()
        from petsc4py import PETSc
        from slepc4py import SLEPc
    except ImportError as exc:
        raise BackendUnavailable(f"backend 'petsc': expected petsc4py and slepc4py importable, found "
                                 f"{exc}; install with: {PETSC_INSTALL}") from None
    _restore_malloc()
    return PETSc, SLEPc


#: glibc's malloc parameters that :func:`_restore_malloc` sets: (``mallopt`` number,
#: ``GLIBC_TUNABLES`` name, tmfem's value)
MALLOC_PARAMETERS = ((-4, "glibc.malloc.mmap_max", 65536),             # M_MMAP_MAX
                     (-3, "glibc.malloc.mmap_threshold", 32 << 20),    # M_MMAP_THRESHOLD
                     (-1, "glibc.malloc.trim_threshold", 64 << 20))    # M_TRIM_THRESHOLD

#: the largest value ``mallopt`` takes (a C int)
MALLOPT_MAX = 2**31 - 1


def malloc_parameters(tunables: str) -> list[tuple[int, str, int]]:
    """``(mallopt number, name, value)`` of :data:`MALLOC_PARAMETERS`: the value a
    ``GLIBC_TUNABLES`` string ``name=value:name=value`` gives (an integer, decimal or 0x
    hexadecimal, as glibc reads it), else tmfem's. A value that is not an integer from 0 to
    2**31 - 1 (``mallopt`` takes a C int) is left out and named in a warning."""
    given = dict(item.partition("=")[::2] for item in tunables.split(":") if "=" in item)
    chosen = []
    for number, name, default in MALLOC_PARAMETERS:
        value = default
        if name in given:
            try:
                value = int(given[name], 0)
                if not 0 <= value <= MALLOPT_MAX:
                    raise ValueError
            except ValueError:
                log.warning("GLIBC_TUNABLES: %s=%s is not an integer from 0 to %d; using %d",
                            name, given[name], MALLOPT_MAX, default)
                value = default
        chosen.append((number, name, value))
    return chosen


@functools.cache
def _restore_malloc() -> None:
    """Give freed memory back to the system again after PETSc has loaded (once).

    A library PETSc links (SuperLU_DIST's CombBLAS, in Debian's build) sets glibc's
    ``M_MMAP_MAX`` to 0 and ``M_TRIM_THRESHOLD`` to -1 when it loads, over glibc's defaults
    and over the user's ``GLIBC_TUNABLES``: every allocation then comes from the heap and
    the heap never shrinks, so each transient array (a pattern set-up's keys, an assembly's
    element matrices) stays resident to the end of the run. This puts back the values of
    ``GLIBC_TUNABLES`` (:func:`malloc_parameters`), else what glibc's own adaptive
    thresholds settle at for arrays of this size (blocks from 32 MB up mapped on their own
    and unmapped when freed, the heap top trimmed beyond 64 MB free): smaller blocks are
    reused from the heap without new page faults (with glibc's initial 128 kB threshold
    every transient array is mapped afresh, ~15 % more CPU time at 78k dofs)."""
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):       # not glibc
        return
    for number, _, value in malloc_parameters(os.environ.get("GLIBC_TUNABLES", "")):
        mallopt(number, value)


def petsc_available() -> bool:
    """Whether petsc4py and slepc4py load (:func:`petsc_modules`)."""
    try:
        petsc_modules()
    except BackendUnavailable:
        return False
    return True


def launched_ranks() -> int:
    """Number of MPI ranks of this process's job as the launcher announces it (Open MPI's or
    MPICH's environment), 1 outside ``mpiexec``; does not initialise MPI."""
    return int(os.environ.get("OMPI_COMM_WORLD_SIZE") or os.environ.get("PMI_SIZE") or 1)


def launched_local_ranks() -> int:
    """Number of this job's ranks on this machine as the launcher announces it (Open MPI's
    ``OMPI_COMM_WORLD_LOCAL_SIZE``, MPICH's ``MPI_LOCALNRANKS``), else
    :func:`launched_ranks`; does not initialise MPI."""
    return int(os.environ.get("OMPI_COMM_WORLD_LOCAL_SIZE") or os.environ.get("MPI_LOCALNRANKS")
               or launched_ranks())
