"""Linear control of tensegrity-membrane systems (dissertation 7.3-7.4, eqs. 5.62-5.71).

* :mod:`tmfem.control.plant`: linear plant at a deployed configuration in (q, v)
  coordinates (eqs. 5.17-5.18, 5.62) and the generalised plant of Fig. 7.1;
* :mod:`tmfem.control.pbh`: PBH eigenvector tests with margins (eq. 5.71);
* :mod:`tmfem.control.hinf`: H-infinity output feedback by eliminated LMIs with
  alpha-stability, controller recovery (eqs. 5.63-5.67), state feedback;
* :mod:`tmfem.control.hinf_central`: the central (minimum-entropy) controller at
  (1 + tol) gamma_opt, one well-defined member of a degenerate optimum's family;
* :mod:`tmfem.control.design`: the end-to-end design, saving and re-checking;
* :mod:`tmfem.control.analysis`: closed-loop plots;
* deployment (7.2, 7.4, 7.6; docs/deployment.md): :mod:`tmfem.control.reference_trajectory`
  (eq. 5.68), :mod:`tmfem.control.pfl` (eqs. 5.39-5.41), :mod:`tmfem.control.rbf`
  (eqs. 5.44, 5.51-5.52), :mod:`tmfem.control.adaptive` (eq. 5.58), :mod:`tmfem.control.switching`
  (eq. 5.70), :mod:`tmfem.control.deploy` (closed-loop runs; uses tmfem.simulation).

May import system, models, solvers, errors; imported only by cli, reference, simulation.
See docs/control.md.
"""
