"""Design variables of a tensegrity-membrane system and how a design vector changes it.

Names (:func:`parse_variables`):

* a tendon group (``"S1"``, ``"V2"``): the rest lengths of every tendon of the group; its value
  is their mean [m] and a change moves all of them by the same amount (r = r_0 + G p);
* a tendon name (``"S_11"``): that tendon's rest length [m];
* ``"h_membrane"``: the membrane thickness h [m];
* ``"d_bar"``: the diameter of the (solid circular) bars [m];
* ``"d_<family>"`` (``"d_S"``, ``"d_V"``): the diameter of every tendon of that family [m];
* ``"r_mb"``: the circumradius of a regular membrane [m] (its corners and reference mesh
  scale; the bars and the rest lengths stay);
* ``"theta_<i>"``, ``"psi_<i>"``: the declination and azimuth of stage i of a symmetric M-N,
  1-N or 1-N(D) system [deg]; the rest lengths follow the ch. 3 design, a 1-N system's base
  radius eq. 3.33 (:mod:`tmfem.design.configuration`).

The other coordinates of the design configuration (sigma, z, r, l) are refused (:data:`GEOMETRY`).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from tmfem.design.configuration import angle_value, parse_angle, with_angles
from tmfem.errors import InfeasibleDesign, InputError
from tmfem.system.geometry import membrane_corners_regular

#: kinds of variable
KINDS = ("rest_length", "thickness", "bar_diameter", "tendon_diameter", "membrane_radius", "angle")
#: names of variables that change the design configuration (refused)
GEOMETRY = ("theta", "psi", "sigma", "z", "r", "l")


@dataclass(frozen=True)
class Variable:
    """One design variable.

    name : str
    kind : one of :data:`KINDS`
    tendons : tuple of int
        The tendons it acts on (rest lengths and tendon diameters; empty otherwise).
    family : str
        The tendon family of a tendon diameter ("" otherwise).
    angle, stage : str, int
        An angle variable's angle ("theta" or "psi") and stage index (0-based).
    """

    name: str
    kind: str
    tendons: tuple = ()
    family: str = ""
    angle: str = ""
    stage: int = 0


def group_names(system) -> list:
    """Tendon groups of ``system`` in the order of its tendons."""
    return list(dict.fromkeys(t.group for t in system.tendons))


def parse_variables(system, variables) -> list:
    """The :class:`Variable` list of ``variables``: ``"groups"`` (one per tendon group),
    ``"tendons"`` (one per tendon) or a sequence of names (module docstring)."""
    tendons = system.tendons
    if isinstance(variables, str):
        if variables == "groups":
            variables = group_names(system)
        elif variables == "tendons":
            variables = [t.name for t in tendons]
        else:
            raise InputError(f"variables: expected 'groups', 'tendons' or a list of names, "
                             f"found {variables!r}")
    names = list(variables)
    if not names:
        raise InputError("variables: expected at least one design variable, found none")
    if len(set(names)) != len(names):
        raise InputError(f"variables: expected distinct names, found {names}")
    families = list(dict.fromkeys(t.family for t in tendons))
    groups = group_names(system)
    out = []
    for n in names:
        if not isinstance(n, str):
            raise InputError(f"variables: expected names, found {n!r}")
        if n in groups:
            out.append(Variable(n, "rest_length", tuple(i for i, t in enumerate(tendons) if t.group == n)))
        elif n in system.tendon_names():
            out.append(Variable(n, "rest_length", (system.tendon_names().index(n),)))
        elif n == "h_membrane":
            out.append(Variable(n, "thickness"))
        elif n == "d_bar":
            out.append(Variable(n, "bar_diameter"))
        elif n == "r_mb":
            if system.r_mb is None or not np.allclose(system.membrane_corners,
                                                      membrane_corners_regular(system.N, system.r_mb)):
                raise InputError("design variable 'r_mb': expected a regular membrane (r_mb in the "
                                 "system file), found one given by its corners")
            out.append(Variable(n, "membrane_radius"))
        elif n.startswith("d_") and n[2:] in families:
            fam = n[2:]
            out.append(Variable(n, "tendon_diameter", tuple(i for i, t in enumerate(tendons)
                                                            if t.family == fam), fam))
        elif parse_angle(system, n) is not None:
            angle, stage = parse_angle(system, n)
            out.append(Variable(n, "angle", angle=angle, stage=stage))
        elif n.split("_")[0] in GEOMETRY:
            raise InputError(f"design variable {n!r}: of the configuration only the angles "
                             f"theta_<stage> and psi_<stage> are variables; expected rest lengths, "
                             f"'h_membrane', 'd_bar', 'd_<family>', 'r_mb', 'theta_<i>' or 'psi_<i>'")
        else:
            raise InputError(f"design variable {n!r}: expected a tendon group {groups}, a tendon "
                             f"name, 'h_membrane', 'd_bar', 'r_mb' or one of "
                             f"{['d_' + f for f in families]}")
    other = [v.name for v in out if v.kind not in ("rest_length", "angle")]
    if other and any(v.kind == "angle" for v in out):
        raise InputError(f"variables: angle variables combine with rest lengths only (the design "
                         f"they re-make depends on the sections and the membrane), found {other}")
    rest = [i for v in out if v.kind == "rest_length" for i in v.tendons]
    if len(set(rest)) != len(rest):
        raise InputError(f"variables: a tendon's rest length appears in two variables of {names}")
    return out


def variable_values(system, rest_lengths: np.ndarray, variables: list) -> np.ndarray:
    """Current values of the ``variables`` of ``system`` at ``rest_lengths`` (n_tendons,)."""
    vals = []
    for v in variables:
        if v.kind == "rest_length":
            vals.append(float(np.mean(rest_lengths[list(v.tendons)])))
        elif v.kind == "thickness":
            vals.append(system.membrane.h)
        elif v.kind == "bar_diameter":
            vals.append(system.bar.d)
        elif v.kind == "membrane_radius":
            vals.append(system.r_mb)
        elif v.kind == "angle":
            vals.append(angle_value(system, v.angle, v.stage))
        else:
            vals.append(system.tendon_section(system.tendons[v.tendons[0]]).d)
    return np.array(vals)


def _family_section(system, family: str, d: float) -> dict:
    """``system.tendon_sections`` with every tendon of ``family`` given diameter d."""
    secs = {system.tendon_section(t) for t in system.tendons if t.family == family}
    if len(secs) != 1:
        raise InputError(f"design variable 'd_{family}': expected one cross section for the "
                         f"family {family}, found {len(secs)} different ones (per group)")
    sec = dataclasses.replace(secs.pop(), d=float(d))
    keep = {k: s for k, s in system.tendon_sections.items()
            if not any(t.family == family and k == t.group for t in system.tendons)}
    return {**keep, family: sec}


def apply_design(system, rest_lengths: np.ndarray, variables: list, p, *, redesign=None) -> tuple:
    """The system and rest lengths of the design ``p`` (one value per variable): rest-length
    variables move their tendons by p - (current value); the others replace the membrane
    thickness, the bar diameter or a tendon family's diameter; angle variables replace the
    configuration and move the rest lengths by the change of the design ``redesign(system)``
    (:func:`tmfem.design.configuration.redesign_of`; required with angle variables)."""
    p = np.asarray(p, dtype=float)
    if p.shape != (len(variables),) or not np.all(np.isfinite(p)):
        raise InputError(f"design: expected {len(variables)} finite values, found {p}")
    r = np.array(rest_lengths, dtype=float)
    now = variable_values(system, r, variables)
    changes = {}
    secs = dict(system.tendon_sections)
    angles = {(v.angle, v.stage): x for v, x in zip(variables, p) if v.kind == "angle"}
    for v, x, x0 in zip(variables, p, now):
        if v.kind == "rest_length":
            r[list(v.tendons)] += x - x0
        elif v.kind == "thickness":
            changes["membrane"] = dataclasses.replace(system.membrane, h=float(x))
        elif v.kind == "bar_diameter":
            changes["bar"] = dataclasses.replace(system.bar, d=float(x))
        elif v.kind == "membrane_radius":
            changes.update(with_membrane_radius(system, float(x)))
        elif v.kind == "angle":
            continue
        else:
            secs = _family_section(system.replace(tendon_sections=secs), v.family, x)
    if any(v.kind == "tendon_diameter" for v in variables):
        changes["tendon_sections"] = secs
    if angles:
        if redesign is None:
            raise InputError("design: angle variables need the design rule of the model (redesign)")
        moved = with_angles(system, angles)
        try:
            r += redesign(moved) - redesign(system)
        except InfeasibleDesign as e:
            at = ", ".join(f"{v.name} = {x:.6g} deg" for v, x in zip(variables, p) if v.kind == "angle")
            raise type(e)(f"design: no ch. 3 equilibrium design at {at} ({e}); expected angle bounds "
                          f"within which the design exists") from e
        changes.update(symmetric=moved.symmetric, q=moved.q, base=moved.base, l=moved.l)
    if np.any(r <= 0):
        raise InputError(f"design: expected positive rest lengths, found {r}")
    return system.replace(**changes, rest_lengths=r), r


def with_membrane_radius(system, r_mb: float) -> dict:
    """The fields ``r_mb`` and ``membrane_corners`` of ``system`` with the regular membrane's
    circumradius r_mb: the corners of :func:`tmfem.system.geometry.membrane_corners_regular`,
    as a system file with this r_mb reads (linear in r_mb: the reference mesh scales)."""
    if not r_mb > 0:
        raise InputError(f"design: expected r_mb > 0, found {r_mb!r}")
    return {"r_mb": r_mb, "membrane_corners": membrane_corners_regular(system.N, r_mb)}


def area_derivative(d: float) -> float:
    """dA/dd = pi d / 2 of a solid circular section A = pi d^2 / 4."""
    return math.pi * d / 2.0
