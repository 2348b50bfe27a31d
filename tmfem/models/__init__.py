"""Models of a tensegrity-membrane system, all built from one :class:`~tmfem.system.System` and
all implementing the interface of :mod:`tmfem.models.base` (equilibrium, modes, plant,
linearisation):

* :mod:`tmfem.models.mtc`: the membrane-truss-cable finite-element model (4.4, 6.2-6.4),
  :class:`MTCModel`;
* :mod:`tmfem.models.sbc`: the shell-beam-cable finite-element model (4.3, 6.2-6.4),
  :class:`SBCModel`;
* :mod:`tmfem.models.com`: the control-oriented model (ch. 5), :class:`ControlOrientedModel`,
  and its linearisation :func:`linearize` (a python-control ``ss`` with named signals).
* :mod:`tmfem.models.fe`: what the two finite-element models share;
* :mod:`tmfem.models.registry`: the registered models and their options.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "MTCModel": "tmfem.models.mtc.model",
    "SBCModel": "tmfem.models.sbc.model",
    "ControlOrientedModel": "tmfem.models.com.model",
    "Linearization": "tmfem.models.com.linearize",
    "linearize": "tmfem.models.com.linearize"
}, subpackages=("com", "mtc", "sbc"))
