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
import os

from tmfem.errors import BackendUnavailable

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


@functools.cache
def _restore_malloc() -> None:
    """Give freed memory back to the system again after PETSc has loaded (once).

    A library PETSc links (SuperLU_DIST's CombBLAS, in Debian's build) sets glibc's
    ``M_MMAP_MAX`` to 0 and ``M_TRIM_THRESHOLD`` to -1 when it loads: every allocation then
    comes from the heap and the heap never shrinks, so each transient array (a pattern
    set-up's keys, an assembly's element matrices) stays resident to the end of the run.
    This puts back what glibc's own adaptive thresholds settle at for arrays of this size
    (blocks from 32 MB up mapped on their own and unmapped when freed, the heap top trimmed
    beyond 64 MB free): smaller blocks are reused from the heap without new page faults (with
    glibc's initial 128 kB threshold every transient array is mapped afresh, ~15 % more CPU
    time at 78k dofs)."""
    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError):       # not glibc
        return
    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD, M_MMAP_MAX = -1, -3, -4
    mallopt(M_MMAP_MAX, 65536)
    mallopt(M_MMAP_THRESHOLD, 32 << 20)
    mallopt(M_TRIM_THRESHOLD, 64 << 20)


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
