"""Design of tensegrity-membrane systems: exact sensitivities of static and modal responses
with respect to design variables (:mod:`tmfem.design.sensitivities`)."""
from tmfem.design.sensitivities import Sensitivities, design_sensitivities

__all__ = ["Sensitivities", "design_sensitivities"]
