"""The error of a linear solve whose matrix cannot be factorised, raised by every backend."""
from __future__ import annotations

from tmfem.errors import ConvergenceError


class SingularMatrix(ConvergenceError):
    """A tangent matrix that cannot be factorised (a mechanism, a slack structure)."""
