"""The finite-element models (MTC, SBC) as plants of a deployment controller: state
estimates, tension actuation, the sampled-data loop and the comparison of plants.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "COMStateEstimator": "tmfem.control.fe_plant.state_estimate",
    "FEStatePlant": "tmfem.control.fe_plant.state_estimate",
    "deployment_plant": "tmfem.control.fe_plant.state_estimate",
    "deviation_summary": "tmfem.control.fe_plant.compare",
    "plant_deviation": "tmfem.control.fe_plant.compare",
    "LinearizedFEPlant": "tmfem.control.fe_plant.sampled_loop",
    "linearize_fe_plant": "tmfem.control.fe_plant.sampled_loop"
})
