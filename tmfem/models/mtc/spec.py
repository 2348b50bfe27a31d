"""The MTC model in the model registry: its options and how they build it."""
from __future__ import annotations

from tmfem.models.fe.options import FE_OPTIONS, SEQUENCE, rayleigh_kwargs, sequence_of
from tmfem.models.fe.rest_lengths import apply_rest_lengths
from tmfem.models.mtc.model import MTCModel
from tmfem.models.spec import ModelSpec, Option


def build(system, options: dict, backend) -> MTCModel:
    """The MTC model of ``system`` with the registry's option values."""
    system, rest = apply_rest_lengths(system, options["rest_lengths"])
    return MTCModel(system, mesh_n=options["mesh"], tendon_elements=options["tendon_elements"],
                    attachment=options["attachment"], patch=options["patch"], rest_lengths=rest,
                    backend=backend, membrane_law=options["membrane_law"])


def equilibrium_kwargs(options: dict) -> dict:
    """Keyword arguments of :meth:`MTCModel.equilibrium` from the option values."""
    return {"start": options["start"],
            "sequence": sequence_of(options["mesh"], options["sequence"])}


SPEC = ModelSpec(
    name="mtc", help="membrane-truss-cable finite-element model (4.4): membrane elements, truss "
                     "bars, tension-only truss tendons",
    build=build, equilibrium_kwargs=equilibrium_kwargs, plant_kwargs=rayleigh_kwargs,
    capabilities=("finite-element",), post="tmfem.post.mtc",
    options=FE_OPTIONS + (
        Option("rest_lengths", str, None, doc=(
            "tendon rest lengths: 'system' (default when the system has them), 'design' (default "
            "otherwise: the ch. 3 design, eq. 3.8, on this model's mesh and attachment, so it "
            "changes with --mesh), 'design@n' (the ch. 3 design on the n x n mesh with point "
            "corners, e.g. design@10 as in 6.2: the same rest lengths on every mesh; the default "
            "of `tmfem converge`), 'mtc' (those that make the design an exact equilibrium of this "
            "model) or values per group/tendon, e.g. 'S1=1.5025'")),
        Option("start", str, "undeformed", choices=("undeformed", "design"), stage="equilibrium",
               doc="start of the static iteration (the undeformed membrane, as in 6.2)"),
        SEQUENCE,
    ))
