"""The control-oriented model in the model registry: its options and how they build it."""
from __future__ import annotations

from tmfem.fem.tension_field import MEMBRANE_LAWS
from tmfem.models.com.model import ControlOrientedModel
from tmfem.models.fe.options import MESH
from tmfem.models.spec import ModelSpec, Option


def build(system, options: dict, backend) -> ControlOrientedModel:
    """The control-oriented model of ``system`` with the registry's option values (its
    solves are small and dense: the backend does not apply); rest lengths the system's when it
    has them, else the design (as the finite-element models)."""
    return ControlOrientedModel(system, membrane_modes=options["membrane_modes"],
                                rest_lengths="design" if system.rest_lengths is None else "system",
                                mesh_n=options["mesh"], damping=options.get("damping", 0.0),
                                prestress_scale=options["prestress_scale"],
                                membrane_law=options["membrane_law"])


SPEC = ModelSpec(
    name="com", help="control-oriented model (ch. 5): rigid bars, linear tendons, membrane modes",
    build=build, uses_backend=False, post="tmfem.post.com",
    options=(
        MESH,
        Option("membrane_modes", int, None, metavar="K", doc=(
            "membrane modes K (default: the system's [models.com], the dissertation's for its "
            "presets: 5 for 1-4, 4 for 2-3; else the smallest K whose 12 lowest frequencies agree "
            "with the FE model's within 5 %, docs/guides/com.md)")),
        Option("prestress_scale", float, 1.0, doc=(
            "factor on the designed membrane prestress (1 = designed; 1.2903 gives the printed "
            "1-4 tendon stress and Table 6.6, docs/validation/errata.md)")),
        Option("membrane_law", str, "svk", choices=MEMBRANE_LAWS, doc=(
            "membrane basis about the linear (svk) or the tension-field prestress "
            "(docs/guides/wrinkling.md)")),
        Option("damping", float, 0.0, stage="dynamics", doc="modal damping c_m [1/s] (eq. 5.13)"),
    ))
