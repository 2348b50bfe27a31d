"""PBH margins at repeated eigenvalues against the Hautus rank test.

Reference: (A, B) is controllable at lambda iff rank [A - lambda I, B] = n (Hautus); the
margin of :func:`tmfem.control.linear.pbh.pbh` must be positive exactly then. A defective
eigenvalue (a Jordan block) has fewer eigenvectors than its multiplicity: its computed
eigenvectors are nearly parallel and must not be taken as a basis of a larger eigenspace.
"""
import numpy as np
import pytest

from tests.data.compleib import compleib
from tmfem.control.linear.pbh import pbh, require_stabilizable_detectable


def _hautus_rank(A, B, lam):
    return np.linalg.matrix_rank(np.hstack([A - lam * np.eye(len(A)), B]), tol=1e-9)


@pytest.mark.parametrize("A, B, controllable", [
    (np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]), True),     # double integrator
    (np.zeros((2, 2)), np.array([[0.0], [1.0]]), False),                     # two integrators, one input
    (np.eye(2), np.eye(2), True),                                            # semisimple, two inputs
    (np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, -1.0]]), np.array([[0.0], [0.0], [1.0]]), True),
    (np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, -1.0]]), np.array([[1.0], [0.0], [0.0]]), False),
])
def test_repeated_eigenvalue_margins_agree_with_the_hautus_rank(A, B, controllable):
    lam = np.linalg.eigvals(A)[0].real
    assert bool(_hautus_rank(A, B, lam) == len(A)) is controllable
    r = pbh(A, B, np.eye(len(A)))
    assert bool(r.controllability_margin.min() > r.tol) is controllable
    # the dual test on (A^T, B^T) as observability
    assert bool(pbh(A.T, np.eye(len(A)), B.T).observability_margin.min() > r.tol) is controllable


def test_compleib_rea3_jordan_block_at_zero_is_stabilizable():
    # COMPleib REA3: two eigenvalues at 0 (an integrator and a zero-sum kinetics block), one
    # eigenvector; rank [A, B] = 12, so the plant is stabilisable and must not be refused
    A, B1, B2, C1, C2, D11, D12, D21 = compleib("REA3")
    assert _hautus_rank(A, B2, 0.0) == 12 and np.linalg.matrix_rank(np.vstack([A, C2]), tol=1e-9) == 12
    require_stabilizable_detectable(A, B2, C2)
