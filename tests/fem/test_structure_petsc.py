"""A general shell structure (:class:`tmfem.fem.structure.Structure`, not a tensegrity) solved
with the PETSc backend: every solve (linear, load-control Newton, arc length, modes) agrees
with the scipy backend's. Source: the same model solved with scipy (an independent backend:
SuperLU/ARPACK against MUMPS/SLEPc)."""
from __future__ import annotations

import numpy as np
from skfem import MeshQuad

from tests.solvers.test_petsc_backend import needs_petsc
from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure


def _hemisphere(backend, n=6, force=50.0):
    """The pinched hemisphere with an 18 deg hole of docs/guides/shells.md, quarter model,
    with mass and a load that makes it nonlinear."""
    R = 10.0
    m = MeshQuad.init_tensor(np.linspace(0, np.pi / 2, n + 1), np.linspace(np.deg2rad(18), np.pi / 2, n + 1))
    theta, psi = m.p
    p = R * np.vstack([np.sin(psi) * np.cos(theta), np.sin(psi) * np.sin(theta), np.cos(psi)])
    s = Structure.shell((p, m.t), section=ShellSection(E=6.825e7, nu=0.3, thickness=0.04, rho=1000.0),
                        normals=p / R, backend=backend)
    s.symmetry(s.nodes_where(lambda x, y, z: np.isclose(y, 0)), normal="y")
    s.symmetry(s.nodes_where(lambda x, y, z: np.isclose(x, 0, atol=1e-9)), normal="x")
    s.node_set("A", s.nodes_where(lambda x, y, z: np.isclose(x, R) & np.isclose(y, 0)))
    s.node_set("B", s.nodes_where(lambda x, y, z: np.isclose(y, R) & np.isclose(x, 0, atol=1e-9)))
    s.fix("A", "uz")
    s.point_load("A", force=(force, 0, 0))
    s.point_load("B", force=(0, -force, 0))
    return s


def _solves(backend):
    s = _hemisphere(backend)
    lin = s.displacements(s.solve_linear())
    path = s.solve(steps=3)
    arc = s.solve_arc_length(dl=0.5, max_steps=3)
    modes = s.modes(k=4, at=path[-1])
    return lin, path, arc, modes


@needs_petsc
def test_shell_structure_on_petsc_agrees_with_scipy():
    ref, got = _solves("scipy"), _solves("petsc")
    lin_s, path_s, arc_s, modes_s = ref
    lin_p, path_p, arc_p, modes_p = got
    # the load path is not linear: at the full load the displacement differs from the
    # linear one by more than 1 %
    u = path_s[-1].state.x - path_s[0].state.x
    assert np.abs(u - lin_s).max() > 1e-2 * np.abs(lin_s).max()
    assert np.abs(lin_p - lin_s).max() <= 1e-9 * np.abs(lin_s).max()
    for a, b in ((path_s, path_p), (arc_s, arc_p)):
        assert a.reason == b.reason and len(a) == len(b)
        assert np.allclose(b.lam, a.lam, rtol=1e-8, atol=1e-12)
        ua, ub = a[-1].state.x - a[0].state.x, b[-1].state.x - b[0].state.x
        assert np.abs(ub - ua).max() <= 1e-8 * np.abs(ua).max()
    assert np.allclose(modes_p.omega2, modes_s.omega2, rtol=1e-8, atol=0)
    assert modes_s.omega2[0] > 0
