"""The configuration angles theta_i, psi_i of a symmetric M-N system as design variables.

A change of the declination theta_i or the azimuth psi_i of stage i (eqs. 3.19-3.20) moves
the bars and changes the ch. 3 equilibrium design: the node coordinates, the corner
displacements and forces of the membrane, the tendon forces that balance them (the null
vector of A(q), eq. 3.16) and the rest lengths r = EA |d| / (T + EA) (eqs. 3.8-3.9). The
finite-element model takes from the design its rest lengths; an angle variable moves them by
the change of the design,

    r(theta, psi) = r_0 + r_D(theta, psi) - r_D(theta_0, psi_0),

(r_0 the model's rest lengths, r_D the design on the model's membrane mesh, corner attachment
and membrane law: the rule ``"design"``), so that a system whose rest lengths are its design
stays designed, and offsets of rest-length variables are kept.

Why the rest lengths are all the MTC model takes: its residual depends on the design only
through them. The bars' reference lengths l, the membrane's reference mesh and the pinned
bases A_1j (r_1, sigma_1, z_1) do not change with the angles; the design configuration is
only the start of the static solve. The derivative of the FE responses is then that of a
rest-length variable along dr/dp (:func:`rest_length_rates`), with the exact direct method
of :mod:`tmfem.design.sensitivities`.

dr_D/dp is the fourth-order central difference (8 (r(h) - r(-h)) - (r(2h) - r(-2h))) / 12h
of the re-designed rest lengths (no FE solve: one linear plane-stress solve per design),
step h = 0.001 deg: truncation O(h^4) below 1e-12 relative, rounding of the design (its
equilibrium residual about 1e-15) / h about 1e-10. Not analytic.

1-N systems are refused: eq. 3.33 ties r_1 to (l_1, theta_1, psi_1), so an angle alone has
no equilibrium design, and the base (or the bars) would have to move with it.
"""
from __future__ import annotations

import dataclasses
import re

import numpy as np

from tmfem.errors import InputError

#: the angle names; a variable is ``theta_<stage>`` or ``psi_<stage>`` [deg]
ANGLES = ("theta", "psi")
#: step of the design's central difference [deg]
STEP_DEG = 1e-3

_NAME = re.compile(r"^(theta|psi)_(\d+)$")


def parse_angle(system, name: str):
    """(angle, stage index) of an angle variable ``name`` (``"theta_2"``: ("theta", 1)), or
    None when ``name`` is not of that form; InputError when the system cannot take it."""
    m = _NAME.match(name)
    if m is None:
        return None
    angle, stage = m.group(1), int(m.group(2))
    if system.symmetric is None:
        raise InputError(f"design variable {name!r}: expected a symmetric system ([symmetric] "
                         f"theta_deg, psi_deg), found one given by its coordinates")
    if not 1 <= stage <= system.M:
        raise InputError(f"design variable {name!r}: expected {angle}_<stage> of a stage 1..{system.M} "
                         f"(one angle per stage), found stage {stage}")
    if system.deployable or system.M == 1:
        raise InputError(f"design variable {name!r}: expected an M-N system with M >= 2; in a 1-N"
                         f"{'(D)' if system.deployable else ''} system eq. 3.33 ties r_1 to l_1, "
                         f"theta_1 and psi_1, so the angle alone has no equilibrium design")
    return angle, stage - 1


def angle_value(system, angle: str, stage: int) -> float:
    """The angle [deg] of a stage of a symmetric system."""
    return float(np.degrees(getattr(system.symmetric, angle)[stage]))


def with_angles(system, values: dict):
    """``system`` with the angles ``{(angle, stage): value [deg]}`` changed: its symmetric
    configuration and the fields it fixes (q, base, l)."""
    c = system.symmetric
    arrays = {a: getattr(c, a).copy() for a in ANGLES}
    for (a, i), v in values.items():
        arrays[a][i] = np.radians(v)
    cfg = dataclasses.replace(c, **arrays)
    return system.replace(symmetric=cfg, **cfg.system_arrays(system.N))


def design_rest_lengths(system, *, mesh_n: int, attachment: str = "point", patch=None,
                        membrane_law: str = "svk") -> np.ndarray:
    """Rest lengths r_D (eqs. 3.8-3.9) of the ch. 3 design of ``system`` on the N x n x n
    membrane mesh with the given corner attachment and law; raises (SlackTendon,
    SlackMembrane, InfeasibleDesign) where the configuration has no design."""
    from tmfem.equilibrium.design import design_equilibrium
    d = design_equilibrium(system, mesh_n=mesh_n, attachment=attachment, patch=patch,
                           membrane_law=membrane_law)
    return np.asarray(d.rest_lengths, dtype=float)


def redesign_of(model):
    """``system -> r_D`` on the mesh, attachment and law of an MTC ``model``."""
    topo = model.topology

    def redesign(system):
        return design_rest_lengths(system, mesh_n=topo.mesh.n, attachment=topo.attachment,
                                   patch=model.patch, membrane_law=model.membrane_law)
    return redesign


def rest_length_rates(model, angle: str, stage: int) -> np.ndarray:
    """dr/dp [m/deg] (n_tendons,) of the angle variable (angle, stage) of ``model``'s system
    (module docstring: the design's fourth-order central difference)."""
    redesign = redesign_of(model)
    p0 = angle_value(model.system, angle, stage)
    r = {k: redesign(with_angles(model.system, {(angle, stage): p0 + k * STEP_DEG}))
         for k in (2, 1, -1, -2)}
    return (8 * (r[1] - r[-1]) - (r[2] - r[-2])) / (12 * STEP_DEG)
