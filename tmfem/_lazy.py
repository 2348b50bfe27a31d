"""Lazy re-exports of a package's public names (PEP 562 module ``__getattr__``).

Every package ``__init__`` of tmfem declares its public names as data, ``{name: module}``,
and gets its ``__getattr__``, ``__dir__`` and ``__all__`` from :func:`lazy_exports`: a name is
imported from its module on first access and then cached in the package. So
``import tmfem`` stays light (no SciPy, CasADi, cvxpy, pyvista or PETSc), ``tmfem.System`` and
``from tmfem.control.lpv import synthesize_state_feedback`` still work, and the import graph
has no edges from a package to its modules (no cycles through ``__init__`` files).

Heavy third-party libraries (petsc4py and slepc4py through
:func:`tmfem.solvers.petsc_loader.petsc_modules`, cvxpy, python-control, pyvista,
matplotlib, gmsh, scikit-fem, meshio, mpi4py) are imported inside the function that needs
them; tmfem's own modules import each other at module level (docs/architecture.md,
"Imports").
"""
from __future__ import annotations

import importlib
import sys


def lazy_exports(package: str, exports: dict[str, str], *, subpackages=()):
    """``(__getattr__, __dir__, __all__)`` of the package ``package`` whose public names are
    ``exports`` ``{name: module}`` and its ``subpackages`` (names of its subpackages, so that
    ``tmfem.control.lpv`` works after ``import tmfem``).

    A name must not also be the name of a submodule of ``package``: importing the submodule
    would set the package attribute to the module (Python's import system), so the function
    ``linearize`` is exported by ``tmfem`` and ``tmfem.models``, not by
    ``tmfem.models.com``, which has a module of that name.

    Examples
    --------
    In ``tmfem/solvers/__init__.py``::

        __getattr__, __dir__, __all__ = lazy_exports(__name__, {
            "get_backend": "tmfem.solvers.backends", "newton": "tmfem.solvers.newton"})
    """
    def __getattr__(name: str):
        if name in subpackages:
            value = importlib.import_module(f"{package}.{name}")
        elif name in exports:
            value = getattr(importlib.import_module(exports[name]), name)
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        setattr(sys.modules[package], name, value)
        return value

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | set(exports) | set(subpackages))

    return __getattr__, __dir__, sorted(exports)
