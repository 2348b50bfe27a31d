"""System description (dissertation ch. 2): topology, geometry, materials, files and presets.
Every model is built from one :class:`System` (:func:`load_system` reads a TOML file,
:func:`load_preset` a packaged system of the dissertation).
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "SymmetricConfig": "tmfem.system.geometry",
    "bar_direction": "tmfem.system.geometry",
    "beta": "tmfem.system.geometry",
    "membrane_corners_regular": "tmfem.system.geometry",
    "BarSection": "tmfem.system.materials",
    "MembraneMaterial": "tmfem.system.materials",
    "TendonSection": "tmfem.system.materials",
    "list_presets": "tmfem.system.presets",
    "load_preset": "tmfem.system.presets",
    "dump_system": "tmfem.system.spec",
    "load_system": "tmfem.system.spec",
    "system_from_dict": "tmfem.system.spec",
    "system_to_dict": "tmfem.system.spec",
    "System": "tmfem.system.system",
    "Tendon": "tmfem.system.topology",
    "tendon_topology": "tmfem.system.topology"
})
