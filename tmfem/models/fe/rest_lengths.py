"""The rest-length policy of the finite-element models as a front end states it: a rule name
(``system``, ``design``, ``design@n``, ``mtc``; :meth:`tmfem.models.mtc.model.MTCModel.set_rest_lengths`)
or values per tendon group."""
from __future__ import annotations

from tmfem.errors import InputError
from tmfem.models.mtc.design import design_mesh_of


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
