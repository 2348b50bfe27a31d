"""The control-oriented model in the model registry: its options and how they build it."""
from __future__ import annotations

from tmfem.fem.tension_field import MEMBRANE_LAWS
from tmfem.models.base import ModelSpec, Option, register
from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes


def build(system, options: dict, backend) -> ControlOrientedModel:
    """The control-oriented model of ``system`` with the registry's option values (its
    solves are small and dense: the backend does not apply)."""
    K = options["membrane_modes"]
    return ControlOrientedModel(system, membrane_modes=default_membrane_modes(system) if K is None else K,
                                mesh_n=options["mesh"], damping=options.get("damping", 0.0),
                                prestress_scale=options["prestress_scale"],
                                membrane_law=options["membrane_law"])


SPEC = register(ModelSpec(
    name="com", help="control-oriented model (ch. 5): rigid bars, linear tendons, membrane modes",
    commands=("modal", "vibrate"), build=build, shared=("mesh",), uses_backend=False,
    own=(
        Option("--membrane-modes", None, None, dict(type=int, metavar="K", help=(
            "membrane modes K (default: the system's [models.com], the dissertation's for its "
            "presets: 5 for 1-4, 4 for 2-3)"))),
        Option("--prestress-scale", 1.0, None, dict(type=float, help=(
            "factor on the designed membrane prestress (1 = designed; 1.2903 gives the printed "
            "1-4 tendon stress and Table 6.6, docs/validation/errata.md)"))),
        Option("--membrane-law", "svk", None, dict(choices=MEMBRANE_LAWS, help=(
            "membrane basis about the linear (svk) or the tension-field prestress "
            "(docs/guides/wrinkling.md)"))),
        Option("--damping", 0.0, ("vibrate",), dict(type=float, help="modal damping c_m [1/s] (eq. 5.13)")),
    )))
