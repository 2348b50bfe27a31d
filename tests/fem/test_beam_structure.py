"""The beam through the general structure API (tmfem.fem.structure.Structure).

Sources: the elastica (benchmarks.json elastica_end_moment_closed_form) and the invariance of
natural frequencies under a rigid rotation of the whole structure (the mass of a rotated
beam turns its rotary inertia with the directors).
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tmfem.fem.beam import BeamElement, BeamSection, BeamSet, line_mesh
from tmfem.fem.element import State
from tmfem.fem.structure import Structure, StructureState
from tmfem.reference.benchmarks.shell_cantilever_moment import elastica


def _cantilever(rho=0.0):
    X, conn = line_mesh([0, 0, 0], [12.0, 0, 0], n_elements=5)
    s = Structure(points=X, dofs=6)
    s.add(BeamElement(BeamSet(conn=conn, section=BeamSection.rectangle(a=1.0, b=0.1), E=1.2e6,
                              nu=0.0, rho=rho, v1=[0, 1, 0]), s.dofmap, X=X))
    s.fix([0], "all")
    return s, X


def test_roll_up_through_the_structure_api():
    s, X = _cantilever()
    s.point_load([X.shape[1] - 1], moment=(0.0, -2 * np.pi * 100.0 / 12.0, 0.0))
    path = s.solve(steps=20)
    lam = np.array([p.lam for p in path])
    u, w = elastica(lam, 12.0)
    tip = np.array([p.x[:, -1] for p in path])
    err = np.hypot(tip[:, 0] - 12.0 - u, tip[:, 2] - w)
    assert lam[-1] == pytest.approx(1.0) and np.max(err[1:] / np.hypot(u, w)[1:]) < 0.01


def test_modes_of_a_rigidly_rotated_beam_equal_the_reference_modes():
    s, X = _cantilever(rho=500.0)
    m0 = s.modes(k=8)
    Q = Rotation.from_rotvec([0.4, -1.1, 0.7]).as_matrix()
    n = X.shape[1]
    rotated = StructureState(state=State(x=Q @ X, R=np.broadcast_to(Q, (n, 3, 3)).copy()), lam=0.0)
    # the clamp fixes increments, so the rotated state is an equally clamped cantilever
    m1 = s.modes(k=8, at=rotated)
    np.testing.assert_allclose(m1.omega, m0.omega, rtol=1e-8)
