"""What the finite-element models (MTC, :mod:`tmfem.models.mtc`; SBC, :mod:`tmfem.models.sbc`)
share: their options (:mod:`~tmfem.models.fe.options`), the equation of motion as a plant
(:mod:`~tmfem.models.fe.plant`), the measured outputs (:mod:`~tmfem.models.fe.outputs`) and the
reduced linearisation (:mod:`~tmfem.models.fe.linearize`)."""
