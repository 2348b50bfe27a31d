"""Deployment control (dissertation 7.2, 7.4, 7.6): reference trajectories (eq. 5.68),
partial feedback linearisation (eqs. 5.39-5.41), RBF adaptation (eqs. 5.44, 5.51-5.58),
rest-length limits, the switch to a linear controller (eq. 5.70), closed-loop runs and the
stress recovery of a run.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "DeploymentReference": "tmfem.control.deployment.reference_trajectory",
    "AdaptivePFL": "tmfem.control.deployment.adaptive",
    "Gains": "tmfem.control.deployment.adaptive",
    "RestLengthLimits": "tmfem.control.deployment.limits",
    "SwitchingController": "tmfem.control.deployment.switching",
    "StressRecovery": "tmfem.control.deployment.recovery",
    "DeploymentResult": "tmfem.control.deployment.run",
    "DeploymentSetup": "tmfem.control.deployment.run",
    "build_deployment": "tmfem.control.deployment.run",
    "run_deployment": "tmfem.control.deployment.run"
})
