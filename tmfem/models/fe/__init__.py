"""What the finite-element models (MTC, :mod:`tmfem.models.mtc`; SBC, :mod:`tmfem.models.sbc`)
share: their options (:mod:`~tmfem.models.fe.options`), the equation of motion as a plant
(:mod:`~tmfem.models.fe.plant`), the measured outputs (:mod:`~tmfem.models.fe.outputs`) and the
reduced linearisation (:mod:`~tmfem.models.fe.linearize`)."""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "FEPlant": "tmfem.models.fe.plant",
    "perturbation_names": "tmfem.models.fe.plant",
    "q_from_positions": "tmfem.models.fe.outputs",
    "MeasuredOutputs": "tmfem.models.fe.outputs",
})
