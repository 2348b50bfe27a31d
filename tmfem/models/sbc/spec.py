"""The SBC model in the model registry: its command-line options and how they build it."""
from __future__ import annotations

from tmfem.models.base import ModelSpec, Option, register
from tmfem.models.mtc.spec import apply_rest_lengths
from tmfem.models.sbc.model import SBCModel


def build(system, options: dict, backend) -> SBCModel:
    """The SBC model of ``system`` with the registry's option values."""
    system, rest = apply_rest_lengths(system, options["rest_lengths"])
    return SBCModel(system, mesh_n=options["mesh"], tendon_elements=options["tendon_elements"],
                    bar_elements=options["bar_elements"], attachment=options["attachment"],
                    patch=options["patch"], rest_lengths=rest, backend=backend,
                    membrane_law=options["membrane_law"])


SPEC = register(ModelSpec(
    name="sbc", help="shell-beam-cable finite-element model (4.3): MITC4 shell membrane, 4-node "
                     "beam bars, tension-only truss tendons",
    commands=("static", "modal", "vibrate"), build=build,
    shared=("mesh", "tendon_elements", "attachment", "patch", "membrane_law", "rayleigh"),
    own=(
        Option("--bar-elements", 1, None, dict(type=int, help="4-node beam elements per bar (6.2: 1); per bar segment A-H, H-B of a 1-N(D) system")),
        Option("--rest-lengths", None, None, dict(help=(
            "tendon rest lengths: 'system', 'design' (eq. 3.8 on this model's mesh), 'design@n' "
            "(eq. 3.8 on the n x n mesh, e.g. design@10), 'mtc' (the MTC model's consistent ones) "
            "or values per group/tendon, e.g. 'S1=1.5025'"))),
    )))
