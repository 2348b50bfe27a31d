"""Equilibrium of tensegrity-membrane systems (dissertation ch. 3).

* :mod:`tmfem.equilibrium.symmetric`: closed forms for 1-N and 1-N(D) systems (3.3.3-3.3.4);
* :mod:`tmfem.equilibrium.general`: A(q) of eq. 3.16 from virtual work with the corner
  constraints of eq. 3.5, its symmetric reduction (3.3.2) and the positive null-vector search;
* :mod:`tmfem.equilibrium.design`: the rest lengths of a designed equilibrium;
* :mod:`tmfem.equilibrium.symmetric_map`: the equilibria over the symmetric parameters (eq. 5.97).
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "EquilibriumDesign": "tmfem.equilibrium.design",
    "design_equilibrium": "tmfem.equilibrium.design",
    "forces_from_rest_lengths": "tmfem.equilibrium.design",
    "equilibrium_matrix": "tmfem.equilibrium.general",
    "positive_null_vector": "tmfem.equilibrium.general",
    "symmetric_matrix": "tmfem.equilibrium.general",
    "equilibrium_map": "tmfem.equilibrium.symmetric_map"
})
