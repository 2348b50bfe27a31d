"""Linear control at a deployed configuration (dissertation 7.3, eqs. 5.62-5.67, 5.71):
generalised plants, PBH tests, H-infinity synthesis (LMI, Riccati, central controller),
the end-to-end design and its closed-loop plots."""

from tmfem.control.linear.hinfsyn import HinfResult, hinfsyn, hinfsyn_state
from tmfem.control.linear.partitioned_plant import GeneralizedPlant

__all__ = ["GeneralizedPlant", "HinfResult", "hinfsyn", "hinfsyn_state"]
