"""petsc4py and slepc4py, imported and initialised on first use.

The PETSc backend's modules (:mod:`tmfem.solvers.petsc`, :mod:`tmfem.solvers.distributed`)
import this module at module level and call
:func:`petsc_modules` where they need PETSc, so that importing them costs nothing on a
machine without PETSc and ``import tmfem`` never loads it (docs/architecture.md,
"Imports").
"""
from __future__ import annotations

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
    return PETSc, SLEPc


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
