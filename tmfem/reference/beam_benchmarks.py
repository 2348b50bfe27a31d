"""Beam benchmarks: the cantilever rolled up by an end moment (dissertation 4.5.2).

:func:`cantilever_end_moment` builds the problem of 4.5.2 from the four-node beam element
(:mod:`tmfem.fem.beam`) and the solver layer's load stepping; the elastica is
its closed form (benchmarks.json ``elastica_end_moment_closed_form``; the function
``elastica`` of the shell benchmark of the same problem).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError
from tmfem.fem.beam import BeamElement, BeamSection, BeamSet, line_mesh
from tmfem.fem.constraints import ConstraintMap
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import State
from tmfem.reference.benchmarks.shell_cantilever_moment import elastica
from tmfem.solvers import load_stepping


@dataclass
class CantileverRollUp:
    """Load path of :func:`cantilever_end_moment`: load factors lam (M = 2 pi lam EI / L),
    tip displacements u_tip, w_tip [m], Newton iterations per step, the elastica at the same
    lam, the axis shapes (3, n) at every converged step, and the problem data."""

    lam: np.ndarray
    u_tip: np.ndarray
    w_tip: np.ndarray
    u_elastica: np.ndarray
    w_elastica: np.ndarray
    iterations: list
    rejected: int
    shapes: list
    L: float
    EI: float
    n_elements: int


def cantilever_end_moment(*, n_elements: int = 5, n_steps: int = 20, E: float = 1.2e6,
                          nu: float = 0.0, L: float = 12.0, b: float = 1.0, h: float = 0.1,
                          integration: str = "reduced", tol: float = 1e-8) -> CantileverRollUp:
    """The cantilever of 4.5.2 (E = 1.2e6 Pa, nu = 0, L = 12 m, width b = 1 m, thickness
    h = 0.1 m, EI = 100 N m^2) clamped at x = 0 and loaded at x = L by the end moment
    M = 2 pi lam EI / L about -y (turning the tip towards +z), lam = 0 .. 1 in ``n_steps``
    equal load steps (Newton with the finite-rotation update at each).

    The beam axis is along x, V1 = e_y (width b), V2 = e_z (thickness h); a moment is a
    rotational load: its work-conjugate is the spatial rotation increment, so the constant
    spatial vector -M e_y is the end moment (a planar problem: it stays conservative).
    """
    if not (isinstance(n_steps, (int, np.integer)) and n_steps >= 1):
        raise InputError(f"cantilever: expected n_steps >= 1, found {n_steps!r}")
    X, conn = line_mesh([0.0, 0.0, 0.0], [L, 0.0, 0.0], n_elements=n_elements)
    nn = X.shape[1]
    dm = DofMap(np.full(nn, 6))
    section = BeamSection.rectangle(a=b, b=h)
    beam = BeamElement(BeamSet(conn=conn, section=section, E=E, nu=nu, rho=0.0, v1=[0.0, 1.0, 0.0]),
                       dm, X=X, integration=integration)
    EI = E * section.I_s
    cm = ConstraintMap.build(dm, fixed_dofs=dm.node_dofs([0]).ravel())
    tip = dm.node_dofs([nn - 1])[0]
    fext = np.zeros(dm.ndof)
    fext[tip[4]] = -2.0 * np.pi * EI / L

    def residual(state, lam):
        f, K = beam.internal(state)
        return cm.residual(f - lam * fext), cm.tangent(K)

    path = load_stepping(residual, State.reference(X, dm), free=cm.free, dlam0=1.0 / n_steps,
                         target_iter=0, tol=tol, line_search=False, scale=float(np.linalg.norm(fext)) / n_steps,
                         update=lambda s, du: s.advanced(cm.full(du), dm))
    u_tip = np.array([s.x[0, -1] - L for s in path.u])
    w_tip = np.array([s.x[2, -1] for s in path.u])
    ue, we = elastica(path.lam, L)
    return CantileverRollUp(lam=path.lam, u_tip=u_tip, w_tip=w_tip, u_elastica=ue, w_elastica=we,
                            iterations=list(path.iterations), rejected=path.rejected,
                            shapes=[beam.centerline(s) for s in path.u], L=L, EI=EI,
                            n_elements=n_elements)
