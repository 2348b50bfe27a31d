"""tmfem: modeling, analysis and deployment control of tensegrity-membrane systems.

The package follows the dissertation "Modeling and Control of Tensegrity-Membrane
Systems" (chapters 2-8). Every model is built from one :class:`tmfem.system.System`.
"""
from tmfem.system import System, SymmetricConfig, load_system, load_preset, list_presets

__all__ = ["System", "SymmetricConfig", "load_system", "load_preset", "list_presets"]
__version__ = "0.1.0"
