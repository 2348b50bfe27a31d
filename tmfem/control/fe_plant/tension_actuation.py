"""Tension-controlled tendon actuators of a finite-element plant (docs/guides/fe-plant.md).

The dissertation's actuators set rest lengths (eq. 5.19). A deployable tendon reeled by a
winch can instead be servoed on a load cell: the winch holds the tension it is asked for. The
deployment controllers stay those designed on the control-oriented model (COM) and still
command rest lengths u_c; the actuator turns them into the tension the COM would have at
the *measured* configuration and the plant realises that tension:

* demand (the COM's tendon law, eq. 3.8 with the fixed rates of eq. 5.19, k = EA / u_0 of the
  final rest lengths u_0, at the measured bar coordinates q):

      T_d = max(0, k (|d(q)| - u_c)),

  clipped at zero (a tendon cannot push; with the rest-length limits u_c <= |d(q)| it is
  non-negative anyway);
* realisation (the FE tendon's own law at its measured state): the rest length r whose FE
  tendon force -- the mean of its k elements' forces, each the St.Venant-Kirchhoff truss of
  eqs. 4.9, 4.23 (:func:`tmfem.fem.truss.truss_internal`), tension-only --

      N_e = EA_e (lambda_e^2 - 1) lambda_e / 2,   lambda_e = k l_e / r   (l_e: element length),
      EA_e = EA (cable: EA fixed, k = EA / r, eq. 3.9),   EA_e = EA r / r_0 (fixed rate, MTC option),

  is T_d, solved per tendon by Newton's method (the mean force is decreasing and convex in r,
  so the iteration converges monotonically from its second iterate) and capped at the FE
  tendon length L = sum l_e (r <= L; T_d = 0 gives r = L). The linear law
  T = EA (L - r) / r of eq. 3.9, r = EA L / (EA + T), is the first iterate: it leaves a force
  error of (3/2) T^2 / EA to first order (the Green strain of the elements; 1.2 N at 25 N on
  the 1-4(D) SBC tendons). r is set at every sample and held over the step (a winch servo
  faster than the sample: the tension is T_d at the start of each step and follows the FE
  tendon's stiffness within it).

With it the FE plant's tendon forces are the COM's at the same measured q: the controller
holds the prestress it was designed for, whatever the FE tendon lengths (the SBC's bars bend
at H_1j, so its tendons are not the COM's lengths at the rigid-fit q).
"""
from __future__ import annotations

import numpy as np

from tmfem.control.deployment.limits import tendon_lengths
from tmfem.errors import ConvergenceError, InputError

#: how a plant's tendons follow the controller's rest lengths: set them (the dissertation's
#: actuators) or hold the COM's tension at the measured configuration (module docstring)
ACTUATIONS = ("rest-length", "force")


def tension_demand(com, q, u) -> np.ndarray:
    """T_d = max(0, k (|d(q)| - u)) [N] (module docstring): the COM's tendon forces (eq. 3.8,
    the rates k = EA / u_0 of eq. 5.19) at bar coordinates q under rest lengths u."""
    L = tendon_lengths(com.system, q)
    return np.maximum(0.0, com.k * (L - np.asarray(u, dtype=float)))


def fe_element_lengths(dyn, x) -> np.ndarray:
    """Lengths [m] of the FE tendon elements (``topology.tendon_conn`` order, k per tendon,
    ``topology.tendon_of_element``) at the free-dof state x of the FE plant ``dyn``."""
    xf = dyn.positions(x)
    a, b = dyn.model.topology.tendon_conn
    return np.linalg.norm(xf[:, b] - xf[:, a], axis=0)


def fe_tendon_lengths(dyn, x) -> np.ndarray:
    """Length [m] of every FE tendon (the sum of its elements' lengths, through its internal
    nodes) at the free-dof state x of the FE plant ``dyn``, in ``system.tendons`` order."""
    topo = dyn.model.topology
    return np.bincount(topo.tendon_of_element, weights=fe_element_lengths(dyn, x),
                       minlength=len(dyn.model.system.tendons))


def rest_length_for_tension(mtc, element_lengths, T, *, tol: float = 1e-12,
                            max_iter: int = 50) -> np.ndarray:
    """The FE rest lengths r [m] whose FE tendon forces (the mean of each tendon's element
    forces) at the element lengths ``element_lengths`` (n_t k,) are T >= 0 [N], under the
    tendon law of the MTC model ``mtc`` (the SBC model's: cable), capped at the tendon lengths
    (module docstring). Newton's method on r, vectorised over the tendons, to a force
    residual of ``tol`` x (1 N + T)."""
    T = np.asarray(T, dtype=float)
    if np.any(~(T >= 0)):
        raise InputError(f"tendon tension demand: expected T >= 0 (a tendon cannot push), found {T}")
    topo = mtc.topology
    e, k = topo.tendon_of_element, topo.tendon_elements
    n_t = T.size
    a = k * np.asarray(element_lengths, dtype=float)              # lambda_e = a_e / r
    L = np.bincount(e, weights=element_lengths, minlength=n_t)
    EA, cable = mtc.tendon_EA, mtc.tendon_law == "cable"
    # the linear law, eq. 3.9; a zero demand is r = L exactly (EA L / EA can be an ulp off)
    r = np.where(T == 0.0, L, EA * L / (EA + T))
    for _ in range(max_iter):
        lam = a / r[e]
        taut = lam > 1.0
        scale = EA[e] if cable else EA[e] * r[e] / mtc.nominal_rest_lengths[e]
        N = np.where(taut, 0.5 * scale * (lam**2 - 1.0) * lam, 0.0)
        # dN/dr: cable -EA (3 lam^2 - 1) lam / (2 r); fixed rate -EA_e lam^3 / r
        dN = np.where(taut, -0.5 * scale * (3 * lam**2 - 1.0) * lam / r[e] if cable
                      else -scale * lam**3 / r[e], 0.0)
        f = np.bincount(e, weights=N, minlength=n_t) / k - T
        df = np.bincount(e, weights=dN, minlength=n_t) / k
        done = (np.abs(f) <= tol * (1.0 + T)) | (T == 0.0)
        if np.all(done):
            break
        step = np.where(done | (df == 0.0), 0.0, f / np.where(df == 0.0, 1.0, df))
        r = r - step
    else:
        raise ConvergenceError(f"tension actuator: Newton's method on the rest lengths did not "
                               f"reach |T - T_d| <= {tol:g} (1 N + T_d) in {max_iter} iterations, "
                               f"found {np.max(np.abs(f)):.3g} N")
    return np.minimum(r, L)
