"""The rest-length policy of the finite-element models: the rules ``system``, ``design``,
``design@n`` and ``mtc`` (:class:`tmfem.models.fe.tendons.Tendons`), what each means, and the
text a front end states them with (a rule or values per tendon group)."""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError



#: Prefix of the rule ``"design@n"``.
DESIGN_AT = "design@"


def design_mesh_of(rule) -> int | None:
    """n of a rest-length rule ``"design@n"`` (n >= 1), else None."""
    if not (isinstance(rule, str) and rule.startswith(DESIGN_AT)):
        return None
    n = rule[len(DESIGN_AT):]
    if not (n.isdigit() and int(n) >= 1):
        raise InputError(f"rest lengths {rule!r}: expected design@n with an integer n >= 1 "
                         f"(e.g. design@10), found {rule!r}")
    return int(n)


def design_rest_lengths_at(system, n: int) -> np.ndarray:
    """Rest lengths (eqs. 3.8-3.9) of the ch. 3 design of ``system`` on the N x n x n membrane
    mesh with point corners (:func:`tmfem.equilibrium.design.design_equilibrium`; 6.2 uses
    n = 10). Unlike the rule ``"design"``, which designs on the analysis model's own mesh,
    these do not depend on the mesh of the model they are given to: one physical structure
    analysed on several meshes (``tmfem converge``)."""
    from tmfem.equilibrium.design import design_equilibrium
    return np.asarray(design_equilibrium(system, mesh_n=int(n)).rest_lengths, dtype=float)


def describe_rule(rule: str, *, per_mesh_study: bool = False) -> str:
    """One line saying what the rest-length rule ``rule`` (``MTCModel.rest_lengths_source``)
    means, printed beside the results (``per_mesh_study``: in a study over several meshes)."""
    n = design_mesh_of(rule)
    if n is not None:
        return (f"the ch. 3 design (eq. 3.8) on the {n} x {n} mesh per patch with point corners, "
                "the same on every analysis mesh")
    return {"design": "the ch. 3 design (eq. 3.8) on "
                      + ("each analysis mesh, recomputed" if per_mesh_study else
                         "this model's mesh and attachment (use design@10 for the 6.2 design "
                         "on any mesh)"),
            "mtc": "the design made an exact equilibrium of " + ("each mesh" if per_mesh_study
                                                                 else "this model"),
            "system": "the system's rest lengths", "given": "given values",
            }.get(rule, rule)


def apply_rest_lengths(system, text):
    """The system and the ``rest_lengths`` argument of an FE model for a rest-length text:
    ``system``/``design``/``design@n``/``mtc`` or ``GROUP=VALUE[,...]`` (values set on the
    system, which the model then takes as ``"system"``)."""
    if text is None or text in ("system", "design", "mtc") or design_mesh_of(text) is not None:
        return system, text
    values = {}
    for item in text.split(","):
        key, sep, val = item.partition("=")
        try:
            values[key.strip()] = float(val)
        except ValueError:
            sep = ""
        if not sep:
            raise InputError(f"--rest-lengths: expected system, design, design@n, mtc or "
                             f"GROUP=VALUE[,...] "
                             f"(e.g. S1=1.5025), found {text!r}")
    return system.with_rest_lengths(values), "system"
