"""Membrane-truss-cable (MTC) finite-element model (dissertation 4.4, 6.2-6.4): trusses for
bars and tendons, a plane-stress membrane; statics, modes and dynamics. See docs/guides/mtc.md.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "MTCModel": "tmfem.models.mtc.model"
})
