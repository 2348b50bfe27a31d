"""Linear control at a deployed configuration (dissertation 7.3, eqs. 5.62-5.67, 5.71):
the generalized plant of Fig. 7.1, PBH tests, H-infinity synthesis (LMI, Riccati, central
controller), the end-to-end design and its closed-loop plots.

The synthesis functions of the same name as their modules (``hinf_lmi``, ``hinf_riccati``,
``hinf_central``, ``pbh``) are imported from their modules.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "GeneralizedPlant": "tmfem.control.linear.hinf_lmi",
    "HinfDesign": "tmfem.control.linear.hinf_lmi",
    "hinf_gamma": "tmfem.control.linear.hinf_lmi",
    "hinf_state_feedback": "tmfem.control.linear.hinf_lmi",
    "closed_loop": "tmfem.control.linear.hinf_lmi",
    "DeployedPlant": "tmfem.control.linear.generalized_plant",
    "deployed_plant": "tmfem.control.linear.generalized_plant",
    "DeployedDesign": "tmfem.control.linear.deployed_design",
    "deployed_hinf": "tmfem.control.linear.deployed_design",
    "PBHResult": "tmfem.control.linear.pbh"
})
