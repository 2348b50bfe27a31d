"""Quadrilateral meshes of the membrane polygon (gmsh) for the finite-element models.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "MembraneMesh": "tmfem.mesh.polygon",
    "polygon_quad_mesh": "tmfem.mesh.polygon"
})
