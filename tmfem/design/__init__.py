"""Design of tensegrity-membrane systems: exact sensitivities of static and modal responses
with respect to design variables (:mod:`tmfem.design.sensitivities`) and optimal designs
(:mod:`tmfem.design.optimizer`)."""
from tmfem.design.optimizer import OptimizationResult, optimize
from tmfem.design.sensitivities import RESPONSES, Sensitivities, design_sensitivities

__all__ = ["OptimizationResult", "RESPONSES", "Sensitivities", "design_sensitivities", "optimize"]
