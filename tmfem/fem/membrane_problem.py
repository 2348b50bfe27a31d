"""A stand-alone membrane boundary-value problem on any quadrilateral mesh.

The total-Lagrangian membrane of :mod:`tmfem.fem.membrane` with a membrane law
(:mod:`tmfem.fem.tension_field`) under prescribed displacements and nodal loads: the
equilibrium f_int(x) = lam f_ext on the free dofs with the prescribed displacements scaled by
the same load factor lam, reached by adaptive load stepping (:func:`tmfem.solvers.newton.load_stepping`,
Newton at each step, eqs. 4.5-4.6). It is the public entry point for membrane benchmarks
(docs/guides/wrinkling.md): a strip in simple shear and a twisted annulus are in the test suite.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError
from tmfem.fem.membrane import MembraneTL
from tmfem.mesh.polygon import MembraneMesh
from tmfem.solvers.newton import load_stepping
from tmfem.system.materials import MembraneMaterial


def quad_mesh(p, t) -> MembraneMesh:
    """A :class:`MembraneMesh` from node coordinates p (2, nn) [m] and counter-clockwise
    quadrilateral connectivity t (4, ne) (e.g. ``skfem.MeshQuad``'s ``p``, ``t``; a
    ``meshio`` quad mesh transposed), with no polygon corners."""
    p = np.asarray(p, dtype=float)
    t = np.asarray(t, dtype=np.int64)
    if p.ndim != 2 or p.shape[0] != 2 or t.ndim != 2 or t.shape[0] != 4:
        raise InputError(f"quad mesh: expected p (2, nn) and t (4, ne), found {p.shape} and {t.shape}")
    if t.size and (t.min() < 0 or t.max() >= p.shape[1]):
        raise InputError(f"quad mesh: expected node indices in [0, {p.shape[1]}), found "
                         f"[{t.min()}, {t.max()}]")
    return MembraneMesh(p=p, t=t, corners=np.zeros(0, dtype=np.int64), n=0)


@dataclass
class MembraneSolution:
    """Equilibrium of :func:`solve_membrane`.

    Attributes
    ----------
    membrane : MembraneTL
    x : ndarray (3, nn)
        Current positions [m].
    u : ndarray (3, nn)
        Displacements x - X [m].
    reactions : ndarray (3, nn)
        f_int - f_ext at the prescribed dofs: the force the supports exert on the membrane
        (the membrane pulls on them with the opposite), zero at the free dofs [N].
    steps : int
        Load steps taken.
    """

    membrane: MembraneTL
    x: np.ndarray
    u: np.ndarray
    reactions: np.ndarray
    steps: int

    def wrinkling(self) -> dict:
        """Element states and tension directions (:meth:`MembraneTL.wrinkling`)."""
        return self.membrane.wrinkling(self.x)


def solve_membrane(*, mesh, material: MembraneMaterial, law="svk", fixed=None, displacement=None,
                   loads=None, x0=None, tol: float = 1e-9, dlam0: float = 1.0,
                   max_iter: int = 25) -> MembraneSolution:
    """Static equilibrium of a membrane on a quadrilateral mesh (eqs. 4.4-4.6).

    Parameters
    ----------
    mesh : MembraneMesh or skfem.MeshQuad
        Flat reference mesh in the (x, y) plane.
    material : MembraneMaterial
    law : {"svk", "tension-field"} or MembraneLaw
    fixed : bool array (3, nn)
        Prescribed dofs (component i of node k); required (the membrane alone has rigid
        motions).
    displacement : array (3, nn), optional
        Prescribed displacements [m] (read at the ``fixed`` dofs; default 0).
    loads : array (3, nn), optional
        Nodal forces [N] on the free dofs (default 0).
    x0 : array (3, nn), optional
        Start positions at the free dofs (default: the reference positions).
    tol, dlam0, max_iter
        Newton tolerance (relative to the first load increment's residual), first load
        increment and Newton iterations per step of :func:`load_stepping`.

    Returns
    -------
    MembraneSolution
    """
    if not isinstance(mesh, MembraneMesh):
        if not (hasattr(mesh, "p") and hasattr(mesh, "t")):
            raise InputError(f"solve_membrane: expected a MembraneMesh or skfem.MeshQuad, found "
                             f"{type(mesh).__name__}")
        mesh = quad_mesh(mesh.p, mesh.t)
    mem = MembraneTL(mesh=mesh, material=material, law=law)
    nn = mem.nn
    shape = (3, nn)

    def arr(a, name, dtype=float):
        if a is None:
            return np.zeros(shape, dtype=dtype)
        a = np.asarray(a, dtype=dtype)
        if a.shape != shape or (dtype is float and not np.all(np.isfinite(a))):
            raise InputError(f"solve_membrane: expected {name} of shape {shape} with finite "
                             f"entries, found shape {a.shape}")
        return a

    if fixed is None:
        raise InputError("solve_membrane: expected fixed (3, nn) prescribed dofs, found none "
                         "(a free membrane has rigid-body motions)")
    fixed = arr(fixed, "fixed", bool)
    disp = arr(displacement, "displacement")
    f_ext = arr(loads, "loads")
    if np.any(f_ext[fixed] != 0.0):
        raise InputError("solve_membrane: expected loads only on free dofs, found "
                         f"{int(np.count_nonzero(f_ext[fixed]))} loads on prescribed dofs")
    X = mem.X
    start = X.copy() if x0 is None else arr(x0, "x0").copy()
    start[fixed] = X[fixed]
    dofs_fixed = fixed.T.ravel()
    free = ~dofs_fixed
    u_pres = disp.T.ravel()
    fe = f_ext.T.ravel()
    X_flat = X.T.ravel()
    s0 = start.T.ravel()

    def residual(w, lam):
        w = w.copy()
        w[dofs_fixed] = X_flat[dofs_fixed] + lam * u_pres[dofs_fixed]
        f, K = mem.internal(w.reshape(nn, 3).T)
        return f - lam * fe, K

    # load stepping keeps the fixed entries of its iterate: residual() imposes X + lam u_p
    path = load_stepping(residual, s0, free=free, dlam0=dlam0, tol=tol, max_iter=max_iter,
                         store=False)
    w = np.asarray(path.u[-1], dtype=float).copy()
    w[dofs_fixed] = X_flat[dofs_fixed] + u_pres[dofs_fixed]
    x = w.reshape(nn, 3).T
    f, _ = mem.internal(x, tangent=False)
    reac = np.where(dofs_fixed, f - fe, 0.0).reshape(nn, 3).T
    return MembraneSolution(membrane=mem, x=x, u=x - X, reactions=reac, steps=len(path.lam) - 1)

