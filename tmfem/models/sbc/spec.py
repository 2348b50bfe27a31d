"""The SBC model in the model registry: its options and how they build it."""
from __future__ import annotations

from tmfem.models.fe.options import FE_OPTIONS, rayleigh_kwargs
from tmfem.models.fe.rest_lengths import apply_rest_lengths
from tmfem.models.sbc.model import SBCModel
from tmfem.models.spec import ModelSpec, Option


def build(system, options: dict, backend) -> SBCModel:
    """The SBC model of ``system`` with the registry's option values."""
    system, rest = apply_rest_lengths(system, options["rest_lengths"])
    return SBCModel(system, mesh_n=options["mesh"], tendon_elements=options["tendon_elements"],
                    bar_elements=options["bar_elements"], attachment=options["attachment"],
                    patch=options["patch"], rest_lengths=rest, backend=backend,
                    membrane_law=options["membrane_law"])


SPEC = ModelSpec(
    name="sbc", help="shell-beam-cable finite-element model (4.3): MITC4 shell membrane, 4-node "
                     "beam bars, tension-only truss tendons",
    build=build, plant_kwargs=rayleigh_kwargs, capabilities=("finite-element",), dofs_per_node=6,
    post="tmfem.post.sbc",
    options=FE_OPTIONS + (
        Option("bar_elements", int, 1, doc="4-node beam elements per bar (6.2: 1); per bar "
                                           "segment A-H, H-B of a 1-N(D) system"),
        Option("rest_lengths", str, None, doc=(
            "tendon rest lengths: 'system', 'design' (eq. 3.8 on this model's mesh), 'design@n' "
            "(eq. 3.8 on the n x n mesh, e.g. design@10), 'mtc' (the MTC model's consistent ones) "
            "or values per group/tendon, e.g. 'S1=1.5025'")),
    ))
