"""The dissertation's printed numbers and the studies that reproduce them, on top of the library.

Nothing in the library below this package (system, fem, equilibrium, models, solvers,
simulation, control) imports it: printed tables, monitor choices and dissertation-specific
designs live here, the models know none of them. The deployments of 7.4 and 8.4 are set
up by :func:`setup` and :func:`lpv_setup` and run on the plants of :class:`FEPlantOptions`
(:func:`run_on_plant`, :func:`compare_plants`).
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "setup": "tmfem.reference.deployments",
    "lpv_setup": "tmfem.reference.deployments",
    "lpv_bases": "tmfem.reference.deployments",
    "write_outputs": "tmfem.reference.deployments",
    "FEPlantOptions": "tmfem.reference.deployment_plants",
    "compare_plants": "tmfem.reference.deployment_plants",
    "diverged": "tmfem.reference.deployment_plants",
    "run_on_plant": "tmfem.reference.deployment_plants"
})
