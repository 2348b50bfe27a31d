"""Models of a tensegrity-membrane system, all built from one :class:`~tmfem.system.System`.

* :mod:`tmfem.models.mtc`: membrane-truss-cable finite-element model (4.4, 6.2-6.4);
* :mod:`tmfem.models.com`: control-oriented model (ch. 5).
"""
