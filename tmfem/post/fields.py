"""Membrane fields for output: the designed membrane placed on the bar tops.

:func:`membrane_design_field` solves the linear plane-stress problem of the membrane
(:class:`tmfem.fem.plane_stress.PlaneStressMembrane`, eq. 5.8) for the corner displacements
that a configuration q imposes (corners B_Mj expressed in the floating frame O_f of 3.2)
and returns the deformed mesh with its displacement and stresses (principal, von Mises
of eqs. 5.29-5.30) as a :class:`tmfem.io.MembraneField` ready for the VTK writer and the
renderer.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError
from tmfem.fem.plane_stress import PlaneStressMembrane, radial_directions
from tmfem.io.fields import DISPLACEMENT_FIELD, MembraneField


def corner_radial_displacements(system, q=None) -> np.ndarray:
    """Outward radial displacement (N,) of each membrane corner relative to the centroid.

    The in-plane corner displacements (:meth:`tmfem.system.System.corner_displacements`,
    eq. 3.4) with the rigid translation
    that keeps the centroid fixed removed, projected on the direction from the centroid to
    the undeformed corner. For a symmetric system every entry equals Delta of eq. 3.22;
    a membrane is stretched only if all are positive (eq. 3.36).
    """

    delta = system.corner_displacements(q)[0][:2]
    d = delta - delta.mean(axis=1, keepdims=True)
    return np.sum(d * radial_directions(system.membrane_corners), axis=0)


def membrane_design_field(system, *, q=None, n: int = 10, attachment: str = "point",
                          patch: float | None = None) -> MembraneField:
    """The membrane of configuration q: linear plane-stress state for its corner positions.

    Parameters
    ----------
    system : System
    q : ndarray, optional
        Configuration; default ``system.q``.
    n : int
        Elements per side of each of the N quadrilateral patches (6.2 uses 10).
    attachment, patch
        Corner attachment of the plane-stress membrane (``"point"`` or ``"distributed"``,
        default patch 10 % of r_mb; see :class:`tmfem.fem.plane_stress.PlaneStressMembrane`).

    Returns
    -------
    MembraneField with point data ``displacement_Of`` (floating frame O_f, the name used by
    every output: :data:`tmfem.io.fields.DISPLACEMENT_FIELD`) and cell data
    ``von_mises`` and ``sigma_p1`` (element maxima over the quadrature points, as the maxima
    of Tables 6.3 / 6.5 are taken), ``sigma_p2`` (element minimum), ``von_mises_mean``,
    ``membrane_state`` (0 taut, 1 wrinkled, 2 slack) and ``wrinkle_direction`` (inertial
    frame) of the membrane law's criterion (docs/guides/wrinkling.md).
    """

    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise InputError(f"membrane mesh: expected n >= 1, found {n!r}")
    model = PlaneStressMembrane(corners=system.membrane_corners, material=system.membrane, n=n,
                                attachment=attachment, patch=patch)
    return placed_membrane_field(system, model, model.solve(system.corner_displacements(q)[0][:2]),
                                 q=q)


def placed_membrane_field(system, model, sol, *, q=None) -> MembraneField:
    """A solved plane-stress membrane placed on the bar tops of configuration q.

    Parameters
    ----------
    system : System
    model : PlaneStressMembrane
        The membrane model (its mesh is the one placed).
    sol : PlaneStressSolution
        Its solution for the corner displacements of q (eq. 5.8), e.g. the ``membrane`` of
        an :class:`tmfem.equilibrium.design.EquilibriumDesign` at the same q.
    q : ndarray, optional
        Configuration; default ``system.q``.

    Returns
    -------
    MembraneField as :func:`membrane_design_field`.
    """
    _, o, R = system.corner_displacements(q)
    mesh = model.mesh
    x = o[:, None] + R[:, :2] @ (mesh.p + sol.u)
    u_f = np.vstack([sol.u, np.zeros(sol.u.shape[1])])      # in-plane: w = 0 in O_f
    vm = sol.von_mises()
    pr = sol.principal()
    dofs = np.zeros(model.basis.N)
    dofs[model.basis.nodal_dofs] = sol.u
    wr = model.wrinkling(dofs)
    return MembraneField(mesh=mesh, x=x, point_data={DISPLACEMENT_FIELD: u_f},
                         cell_data={"von_mises": vm.max(axis=1), "sigma_p1": pr[0].max(axis=1),
                                    "sigma_p2": pr[1].min(axis=1),
                                    "von_mises_mean": vm.mean(axis=1),
                                    "membrane_state": wr["state"].astype(np.int32),
                                    "wrinkle_direction": R @ wr["direction"]})
