"""Linear control of tensegrity-membrane systems (dissertation 7.3-7.4, eqs. 5.62-5.71).

* :mod:`tmfem.control.plant`: linear plant at a deployed configuration in (q, v)
  coordinates (eqs. 5.17-5.18, 5.62) and the generalised plant of Fig. 7.1;
* :mod:`tmfem.control.pbh`: PBH eigenvector tests with margins (eq. 5.71);
* :mod:`tmfem.control.hinf`: H-infinity output feedback by eliminated LMIs with
  alpha-stability, controller recovery (eqs. 5.63-5.67), state feedback;
* :mod:`tmfem.control.design`: the end-to-end design, saving and re-checking;
* :mod:`tmfem.control.analysis`: closed-loop plots.

May import system, models, solvers, errors; imported only by cli, reference, simulation.
See docs/control.md.
"""
