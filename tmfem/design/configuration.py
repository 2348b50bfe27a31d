"""The configuration angles theta_i, psi_i of a symmetric M-N, 1-N or 1-N(D) system as design
variables.

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

In a 1-N system eq. 3.33 ties the base radius to the angles, r_1 = l_1 sin(theta_1)
sin(psi_1) / cos(pi / N) (no equilibrium design exists otherwise): an angle of a 1-N system
moves the base A_1j with r_1 (the bases scale with r_1 about the origin), r_1 = r_1,0
r_3.33(theta, psi) / r_3.33(theta_0, psi_0), so that a start given to printed precision (the
1-4 preset's r_1 = 0.6429 m) is the start.

What the MTC and SBC models take from the design: the rest lengths and the pinned bases. The
bars' reference lengths l and the membrane's reference mesh do not change with the angles, and
the design configuration is only the start of the static solve (the SBC model's reference
placement of its beams and shells follows it rigidly, which moves no equilibrium). In the
direct method of :mod:`tmfem.design.sensitivities` an angle is a rest-length direction dr/dp
(the residual's partial derivative is analytic) with the bases' motion dA/dp prescribed on the
pinned degrees of freedom: K_ff du_f = -dR_f/dp - K_fs dA/dp (:func:`design_rates`; the
adapters' ``supports`` of :mod:`tmfem.design.kinematics`).

dr_D/dp is exact: the forward-mode derivative of the design along the angle's direction
(:mod:`tmfem.design.design_derivative`: node coordinates, corner constraints, the linear
membrane solve, the least-squares tendon forces of eq. 3.16 and eqs. 3.8-3.9), with the
configuration's rate from eqs. 3.19-3.20 (:func:`angle_direction`): theta_ij' = 1 (or
psi_ij' = 1) on every bar of the stage and, for a 1-N system, A_1j' = A_1j r_1' / r_1 with
r_1' / r_1 = cot(theta_1) (or cot(psi_1)) from eq. 3.33 (the bases scale with r_1).
"""
from __future__ import annotations

import dataclasses
import re

import numpy as np

from tmfem.design.design_derivative import design_rate
from tmfem.equilibrium.symmetric import r1_1N
from tmfem.errors import InputError
from tmfem.system.coordinates import q_index

#: the angle names; a variable is ``theta_<stage>`` or ``psi_<stage>`` [deg]
ANGLES = ("theta", "psi")

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
    return angle, stage - 1


def angle_value(system, angle: str, stage: int) -> float:
    """The angle [deg] of a stage of a symmetric system."""
    return float(np.degrees(getattr(system.symmetric, angle)[stage]))


def with_angles(system, values: dict):
    """``system`` with the angles ``{(angle, stage): value [deg]}`` changed: its symmetric
    configuration and the fields it fixes (q, base, l); a 1-N system's base radius r_1
    follows eq. 3.33 (a 1-N(D) system's stays: eq. 3.41 bounds it, no equation fixes it)."""
    c = system.symmetric
    arrays = {a: getattr(c, a).copy() for a in ANGLES}
    for (a, i), v in values.items():
        arrays[a][i] = np.radians(v)
    if system.M == 1 and not system.deployable:   # eq. 3.33, relative to the start (printed precision)
        arrays["r"] = c.r * (r1_1N(l1=c.l[0], theta1=arrays["theta"][0], psi1=arrays["psi"][0], N=system.N)
                             / r1_1N(l1=c.l[0], theta1=c.theta[0], psi1=c.psi[0], N=system.N))
    cfg = dataclasses.replace(c, **arrays)
    return system.replace(symmetric=cfg, **cfg.system_arrays(system.N))


def design_of(system, *, mesh_n: int, attachment: str = "point", patch=None, membrane_law: str = "svk"):
    """The ch. 3 design (:func:`tmfem.equilibrium.design.design_equilibrium`) of ``system`` on
    the N x n x n membrane mesh with the given corner attachment and law; raises (SlackTendon,
    SlackMembrane, InfeasibleDesign) where the configuration has no design."""
    from tmfem.equilibrium.design import design_equilibrium
    return design_equilibrium(system, mesh_n=mesh_n, attachment=attachment, patch=patch,
                              membrane_law=membrane_law)


def design_rest_lengths(system, *, mesh_n: int, attachment: str = "point", patch=None,
                        membrane_law: str = "svk") -> np.ndarray:
    """Rest lengths r_D (eqs. 3.8-3.9) of the ch. 3 design of ``system`` (:func:`design_of`)."""
    d = design_of(system, mesh_n=mesh_n, attachment=attachment, patch=patch, membrane_law=membrane_law)
    return np.asarray(d.rest_lengths, dtype=float)


def design_options(model) -> dict:
    """The design's options of an MTC or SBC ``model``: its membrane mesh, attachment and law."""
    topo = model.topology
    return {"mesh_n": topo.mesh.n, "attachment": topo.attachment, "patch": model.patch,
            "membrane_law": model.membrane_law}


def redesign_of(model):
    """``system -> r_D`` on the mesh, attachment and law of an MTC or SBC ``model``."""
    options = design_options(model)

    def redesign(system):
        return design_rest_lengths(system, **options)
    return redesign


def angle_direction(system, angle: str, stage: int) -> tuple:
    """The rates [per deg] of q (n_q,) and of the stage-1 base A_1j (3, N) of ``system`` along
    its angle (angle, stage) (eqs. 3.19-3.20 and, for a 1-N system, eq. 3.33: module
    docstring)."""
    c = system.symmetric
    _, th, ps = q_index(system.M, system.N)
    dq = np.zeros(system.q.size)
    dq[(th if angle == "theta" else ps)[stage]] = np.pi / 180
    dbase = np.zeros_like(system.base)
    if system.M == 1 and not system.deployable:   # r_1 ~ sin(theta_1) sin(psi_1): r_1' / r_1 = cot
        dbase = system.base * (np.pi / 180) / np.tan(getattr(c, angle)[0])
    return dq, dbase


def design_rates(model, angle: str, stage: int, *, design=None) -> tuple:
    """dr/dp [m/deg] (n_tendons,) and dA/dp [m/deg] (3, N) of the bases A_1j of the angle
    variable (angle, stage) of ``model``'s system: the exact rate of the ch. 3 design
    (``design``, default the design of :func:`design_options`) (module docstring)."""
    design = design_of(model.system, **design_options(model)) if design is None else design
    dq, dbase = angle_direction(model.system, angle, stage)
    return design_rate(design, dq=dq, dbase=dbase).rest_lengths, dbase


def warm_start(model, state) -> dict:
    """The keyword of ``model.equilibrium`` that starts it from the equilibrium ``state`` of
    a neighbouring design (MTC: positions (3, n_nodes); SBC: a State) with the pinned bases
    moved to ``model``'s system's A_1j (1-N angles). The SBC model's start is the state of its
    own positions (:meth:`~tmfem.models.sbc.model.SBCModel.state_from_mtc`: directors and bar
    triads turned onto the deformed geometry from its own reference), since the rotations of
    ``state`` are relative to the neighbour's reference."""
    sbc = model.name == "sbc"
    x = np.array(state.x[:, :model.numbering.n_mtc_nodes] if sbc else state, dtype=float)
    x[:, model.topology.fixed_nodes] = model.system.base
    return {"start": model.state_from_mtc(x)} if sbc else {"x0": x}
