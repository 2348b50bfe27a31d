"""Total-Lagrangian finite elements (dissertation ch. 4): the truss (eqs. 4.1-4.4), the
membrane (plane stress, SVK and tension-field laws, eq. 4.9), the MITC4 shell and the
geometrically exact beam of the SBC model, their assembly, and the :class:`Structure` API
that builds a structure of one's own from these elements.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "Structure": "tmfem.fem.structure",
    "gmsh_quad_mesh": "tmfem.fem.structure",
    "read_quad_mesh": "tmfem.fem.structure",
    "TrussElement": "tmfem.fem.truss",
    "TrussSet": "tmfem.fem.truss",
    "MembraneElement": "tmfem.fem.membrane",
    "PlaneStressMembrane": "tmfem.fem.plane_stress",
    "SVKLaw": "tmfem.fem.tension_field",
    "TensionFieldLaw": "tmfem.fem.tension_field",
    "membrane_law": "tmfem.fem.tension_field",
    "MITC4Shell": "tmfem.fem.mitc4",
    "ShellPressure": "tmfem.fem.mitc4",
    "ShellSection": "tmfem.fem.shell_section",
    "BeamElement": "tmfem.fem.beam",
    "BeamSection": "tmfem.fem.beam",
    "BeamSet": "tmfem.fem.beam",
    "Assembler": "tmfem.fem.assembly",
    "DofMap": "tmfem.fem.dofmap"
})
