"""Solvers below every model: linear-algebra backends (SciPy; PETSc/SLEPc under MPI), Newton
with line search, load stepping and arc length, the trust-region solver, the shift-invert
eigen solver and Park's time integrator.

The layer imports nothing of tmfem but :mod:`tmfem.errors`. PETSc is loaded only when the
``petsc`` backend is asked for (:mod:`tmfem.solvers.petsc_loader`). Newton's method is
:func:`tmfem.solvers.newton.newton` (a function of the same name as its module is imported
from the module).
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "Backend": "tmfem.solvers.backends",
    "ScipyBackend": "tmfem.solvers.backends",
    "backend_names": "tmfem.solvers.backends",
    "get_backend": "tmfem.solvers.backends",
    "PetscBackend": "tmfem.solvers.petsc",
    "SingularMatrix": "tmfem.solvers.singular",
    "Modes": "tmfem.solvers.eigen",
    "lowest_modes": "tmfem.solvers.eigen",
    "LoadPath": "tmfem.solvers.newton",
    "NewtonResult": "tmfem.solvers.newton",
    "arc_length": "tmfem.solvers.continuation",
    "free_index": "tmfem.solvers.newton",
    "load_stepping": "tmfem.solvers.newton",
    "ParkResult": "tmfem.solvers.park",
    "park_integrate": "tmfem.solvers.park"
})
