"""Solvers below every model: linear-algebra backends (SciPy; PETSc/SLEPc under MPI), Newton
with line search, load stepping and arc length, the trust-region solver, the shift-invert
eigen solver and Park's time integrator.

The layer imports nothing of tmfem but :mod:`tmfem.errors`. PETSc is loaded only when the
``petsc`` backend is asked for (:mod:`tmfem.solvers.petsc_loader`). Newton's method is
:func:`tmfem.solvers.newton.newton` (a function of the same name as its module is imported
from the module).
"""
# the solver layer imports nothing of tmfem but tmfem.errors, so its names are imported here
# directly (its modules need NumPy and SciPy only; PETSc stays behind petsc_loader)
from tmfem.solvers.backends import Backend, ScipyBackend, backend_names, get_backend
from tmfem.solvers.continuation import arc_length
from tmfem.solvers.eigen import Modes, lowest_modes
from tmfem.solvers.newton import LoadPath, NewtonResult, free_index, load_stepping
from tmfem.solvers.park import ParkResult, park_integrate
from tmfem.solvers.petsc import PetscBackend
from tmfem.solvers.singular import SingularMatrix

__all__ = ["Backend", "ScipyBackend", "backend_names", "get_backend", "PetscBackend", "SingularMatrix",
           "Modes", "lowest_modes", "LoadPath", "NewtonResult", "arc_length", "free_index",
           "load_stepping", "ParkResult", "park_integrate"]
