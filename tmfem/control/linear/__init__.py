"""Linear control at a deployed configuration (dissertation 7.3, eqs. 5.62-5.67, 5.71):
the generalized plant of Fig. 7.1, PBH tests, H-infinity synthesis (LMI, Riccati, central
controller), the end-to-end design and its closed-loop plots.

The python-control-style entry points are :func:`hinfsyn` and :func:`hinfsyn_state` (the
verified route of :mod:`tmfem.control.linear.hinf_synthesis`). The synthesis functions of the
same name as their modules (``hinf_lmi``, ``hinf_central``, ``hinf_slicot``, ``pbh``) are
imported from their modules.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "GeneralizedPlant": "tmfem.control.linear.partitioned_plant",
    "HinfResult": "tmfem.control.linear.hinf_synthesis",
    "hinfsyn": "tmfem.control.linear.hinf_synthesis",
    "hinfsyn_state": "tmfem.control.linear.hinf_synthesis",
    "HinfDesign": "tmfem.control.linear.verification",
    "closed_loop": "tmfem.control.linear.verification",
    "hinf_gamma": "tmfem.control.linear.hinf_lmi",
    "hinf_state_feedback": "tmfem.control.linear.hinf_lmi",
    "DeployedPlant": "tmfem.control.linear.generalized_plant",
    "deployed_plant": "tmfem.control.linear.generalized_plant",
    "DeployedDesign": "tmfem.control.linear.deployed_design",
    "deployed_hinf": "tmfem.control.linear.deployed_design",
    "PBHResult": "tmfem.control.linear.pbh"
})
