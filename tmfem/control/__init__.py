"""Control of tensegrity-membrane systems (dissertation ch. 5.5-5.6, 7 and 8).

Subpackages, one concept each:

* :mod:`tmfem.control.linear`: linear plants at a deployed configuration and the generalized
  plant of Fig. 7.1, PBH tests (eq. 5.71), H-infinity synthesis by LMIs and by Riccati
  equations with alpha-stability (eqs. 5.63-5.67), the central controller, the end-to-end
  design and its closed-loop plots;
* :mod:`tmfem.control.deployment`: deployment by reference trajectories (eq. 5.68), partial
  feedback linearisation (eqs. 5.39-5.41), RBF adaptation (eqs. 5.44, 5.51-5.58), rest-length
  limits, the switch to a linear controller (eq. 5.70), closed-loop runs and stress recovery;
* :mod:`tmfem.control.lpv`: gridded LPV synthesis, verification, output feedback and
  deployment (ch. 8), with the design workflow as library functions;
* :mod:`tmfem.control.fe_plant`: the finite-element models as plants of a deployment
  controller (state estimates, tension actuation, sampled loops, plant comparison).

May import system, models, simulation, solvers, errors; imported only by cli and reference.
See docs/guides/control.md.
"""
from tmfem._lazy import lazy_exports

# the python-control-style synthesis entry points, one attribute away
__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "GeneralizedPlant": "tmfem.control.linear.partitioned_plant",
    "HinfResult": "tmfem.control.linear.hinf_synthesis",
    "hinfsyn": "tmfem.control.linear.hinf_synthesis",
    "hinfsyn_state": "tmfem.control.linear.hinf_synthesis",
}, subpackages=("deployment", "fe_plant", "linear", "lpv"))
