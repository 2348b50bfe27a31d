"""Solvers: Newton (line search), load stepping, arc length, eigen (shift-invert), backends.

Park's time integrator lives in :mod:`tmfem.solvers.park`.
"""
from tmfem.solvers.backends import Backend, ScipyBackend, get_backend
from tmfem.solvers.eigen import Modes, lowest_modes
from tmfem.solvers.newton import LoadPath, NewtonResult, arc_length, free_index, load_stepping, newton

__all__ = ["Backend", "ScipyBackend", "get_backend", "Modes", "lowest_modes", "LoadPath",
           "NewtonResult", "arc_length", "free_index", "load_stepping", "newton"]
