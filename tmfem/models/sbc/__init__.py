"""Shell-beam-cable (SBC) finite-element model (dissertation 4.3, 6.2-6.4): beams for bars,
cables for tendons, MITC4 shells for the membrane; statics, modes and dynamics.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "SBCModel": "tmfem.models.sbc.model"
})
