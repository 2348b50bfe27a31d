"""Equilibrium of tensegrity-membrane systems (dissertation ch. 3).

* :mod:`tmfem.equilibrium.symmetric`: closed forms for 1-N and 1-N(D) systems (3.3.3-3.3.4).
* :mod:`tmfem.equilibrium.general`: A(q) of eq. 3.16 from virtual work with the corner
  constraints of eq. 3.5, its symmetric reduction (3.3.2) and the positive null-vector search.
"""
from tmfem.equilibrium.design import EquilibriumDesign, design_equilibrium, forces_from_rest_lengths
from tmfem.equilibrium.general import equilibrium_matrix, positive_null_vector, symmetric_matrix
from tmfem.equilibrium.symmetric_map import equilibrium_map

__all__ = ["EquilibriumDesign", "design_equilibrium", "forces_from_rest_lengths",
           "equilibrium_matrix", "positive_null_vector", "symmetric_matrix", "equilibrium_map"]
