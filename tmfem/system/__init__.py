"""System description (dissertation ch. 2): topology, geometry, materials, files, presets."""
from tmfem.system.geometry import SymmetricConfig, bar_direction, beta, membrane_corners_regular
from tmfem.system.materials import BarSection, MembraneMaterial, TendonSection
from tmfem.system.presets import list_presets, load_preset
from tmfem.system.spec import dump_system, load_system, system_from_dict, system_to_dict
from tmfem.system.system import System
from tmfem.system.topology import Tendon, tendon_topology

__all__ = ["System", "SymmetricConfig", "Tendon", "MembraneMaterial", "BarSection", "TendonSection",
           "bar_direction", "beta", "membrane_corners_regular", "tendon_topology", "load_system",
           "dump_system", "system_from_dict", "system_to_dict", "load_preset", "list_presets"]
