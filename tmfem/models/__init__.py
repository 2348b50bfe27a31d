"""Models of a tensegrity-membrane system, all built from one :class:`~tmfem.system.System` and
all implementing the interface of :mod:`tmfem.models.base` (equilibrium, modes, plant,
linearisation):

* :mod:`tmfem.models.mtc`: membrane-truss-cable finite-element model (4.4, 6.2-6.4);
* :mod:`tmfem.models.sbc`: shell-beam-cable finite-element model (4.3, 6.2-6.4);
* :mod:`tmfem.models.com`: control-oriented model (ch. 5);
* :mod:`tmfem.models.fe`: what the two finite-element models share;
* :mod:`tmfem.models.registry`: the registered models and their options;
* :mod:`tmfem.models.compare`: every model of one system side by side.
"""
