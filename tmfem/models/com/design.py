"""The control-oriented model's design equilibrium: a stretched membrane and the tendon
forces and rest lengths that make the design configuration an equilibrium (eqs. 3.8-3.9,
3.16, 3.21-3.22, 3.36)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InfeasibleDesign, SlackMembrane, SlackTendon
from tmfem.fem.truss import linear_rest_length


@dataclass
class StaticDesign:
    """Equilibrium of the COM at the design configuration (eq. 3.16 with the COM's energies)."""

    tendon_forces: np.ndarray
    rest_lengths: np.ndarray
    residual: float


def check_membrane_stretched(system, layout, zeta0) -> None:
    """Refuse a design that does not pull every membrane corner outward (eqs. 3.21, 3.36):
    the radial corner displacement relative to the membrane centroid, rigid translation
    removed (corner N is the origin of O_f), must be > 0; else :class:`SlackMembrane`."""
    d = layout.delta_array(zeta0)[:2]
    c = system.membrane_corners
    e = c - c.mean(axis=1, keepdims=True)
    e = e / np.linalg.norm(e, axis=0)
    radial = np.sum((d - d.mean(axis=1, keepdims=True)) * e, axis=0)
    if np.any(radial <= 0):
        raise SlackMembrane(f"system {system.name!r}: expected every membrane corner "
                            "displaced outward at the design (Delta > 0, eqs. 3.21-3.22, 3.36), "
                            f"found radial corner displacements {np.round(radial, 6).tolist()} m")


def design_rest_lengths(system, static, q0, zeta0) -> StaticDesign:
    """Tendon forces making the design q0 an equilibrium of the COM, then rest lengths.

    Static equilibrium of the q equations (eq. 3.16 with the COM's membrane energy):
    sum_t T_t d|d_t|/dq + dU_m/dq = 0, solved for the tendon forces T by least squares (the
    minimum-norm solution; when it is not positive and the system has a self-stress, as with
    more tendons than independent equations, the solution closest to the tendon forces of the
    ch. 3 design, :func:`tmfem.equilibrium.design.design_equilibrium`); rest lengths
    r = EA |d| / (EA + T) (eqs. 3.8-3.9). A small residual (rounded design values,
    e.g. r_1 = 0.4286 m of Table 6.2) is accepted up to 1e-3 relative; the model's
    ``equilibrium`` then finds the exact equilibrium nearby.

    Parameters
    ----------
    system : System
    static : casadi.Function
        (q, zeta) -> (d|d|/dq, dU_m/dq, |d|) of :func:`tmfem.models.com.graphs.static_graph`.
    q0, zeta0 : ndarray
        The design configuration and its dependent coordinates.
    """
    JL, gm, L = (np.asarray(a) for a in static(q0, zeta0))
    L = L.ravel()
    gm = gm.ravel()
    T, _, rank, _ = np.linalg.lstsq(JL.T, -gm, rcond=None)
    if np.any(T <= 0) and rank < JL.shape[0]:
        # more tendons than independent equations (a self-stress, e.g. M >= 3): of the forces
        # that balance the COM's membrane, the ones closest to the ch. 3 design's
        from tmfem.equilibrium.design import design_equilibrium
        T_3 = np.asarray(design_equilibrium(system, q=q0, strict=False).tendon_forces, dtype=float)
        T = T_3 + np.linalg.lstsq(JL.T, -gm - JL.T @ T_3, rcond=None)[0]
    res = np.linalg.norm(JL.T @ T + gm) / max(np.linalg.norm(gm), 1e-300)
    if res > 1e-3:
        raise InfeasibleDesign(f"system {system.name!r}: the design q is not an equilibrium "
                               "of any tendon forces (eq. 3.16): relative residual "
                               f"{res:.3e}, expected <= 1e-3")
    if np.any(T <= 0):
        bad = [f"{t.name}={f:.4g} N" for t, f in zip(system.tendons, T) if f <= 0]
        raise SlackTendon(f"system {system.name!r}: design tendon forces must be > 0 "
                          f"(eq. 3.16), found {', '.join(bad)}")
    r = linear_rest_length(L, T, system.tendon_EA)
    return StaticDesign(tendon_forces=T, rest_lengths=r, residual=float(res))
