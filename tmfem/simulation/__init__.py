"""Time simulation of any model's plant with open-loop inputs or a controller (Park's method).

* :mod:`tmfem.simulation.controllers`: the controller hook u = k(t, y, x_c) with controller
  states, open-loop schedules, linear (python-control) controllers, state feedback;
* :mod:`tmfem.simulation.driver`: :func:`simulate`, Park's method or the trapezoidal rule
  (eqs. 5.34-5.35) on a :class:`tmfem.models.base.Plant` with the controller in the loop.
"""
from tmfem.simulation.controllers import Controller, LinearController, OpenLoop
from tmfem.simulation.driver import Simulation, simulate

__all__ = ["Controller", "LinearController", "OpenLoop", "Simulation", "simulate"]
