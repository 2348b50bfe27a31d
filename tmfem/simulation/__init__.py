"""Time simulation of any model's plant with open-loop inputs or a controller (Park's method).

* :mod:`tmfem.simulation.controllers`: the controller hook u = k(t, y, x_c) with controller
  states, open-loop schedules, linear (python-control) controllers, state feedback;
* :mod:`tmfem.simulation.driver`: :func:`simulate`, Park's method or the trapezoidal rule
  (eqs. 5.34-5.35) on a :class:`tmfem.models.base.Plant` with the controller in the loop.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "Controller": "tmfem.simulation.controllers",
    "LinearController": "tmfem.simulation.controllers",
    "OpenLoop": "tmfem.simulation.controllers",
    "MeasurementNoise": "tmfem.simulation.controllers",
    "Simulation": "tmfem.simulation.driver",
    "simulate": "tmfem.simulation.driver"
})
