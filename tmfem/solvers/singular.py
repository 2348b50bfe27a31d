"""The error of a linear solve whose matrix cannot be factorised, raised by every backend."""
from __future__ import annotations

from tmfem.errors import ConvergenceError


class SingularMatrix(ConvergenceError):
    """A tangent matrix that cannot be factorised (a mechanism, a slack structure)."""


#: Smallest ratio of the smallest to the largest LU pivot of a non-singular matrix (at the
#: scale of the matrix, or of its Jacobi equilibration): below it the matrix is singular to
#: working precision (a pivot at the round-off of the largest one).
SINGULAR_PIVOT_RATIO = 1e-14
