"""Meshes of the membrane polygon (gmsh) for the finite-element models."""
from tmfem.mesh.polygon import MembraneMesh, polygon_quad_mesh

__all__ = ["MembraneMesh", "polygon_quad_mesh"]
