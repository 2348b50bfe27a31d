"""The structure API: shells, beams, bars and membranes on one dof map, with supports that
compose, loads with load factors, path following and results (:mod:`.model`; user guide:
docs/guides/shells.md)."""
from tmfem.fem.structure.model import DOF_NAMES, Structure, StructureState, gmsh_quad_mesh, read_quad_mesh
from tmfem.fem.structure.reactions import Reactions

__all__ = ["DOF_NAMES", "Reactions", "Structure", "StructureState", "gmsh_quad_mesh", "read_quad_mesh"]
