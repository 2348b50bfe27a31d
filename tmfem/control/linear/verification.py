"""A controller's closed loop, assembled and verified (the certificate every synthesis
route returns).

* :func:`closed_loop`: the lower LFT T_pw = F_l(P, K) on the named signals
  (python-control ``interconnect``);
* :func:`hinf_norm`: ||T||_inf of a stable system by SLICOT AB13DD (python-control
  ``norm(T, "inf")``) cross-checked by a frequency sweep (a logarithmic grid plus the
  frequencies of the poles): the larger of the two is returned, so a sharp peak that one
  method misses cannot lower the reported value;
* :func:`check_loop` / :func:`verify`: poles left of -alpha_1 and ||T_pw||_inf <= gamma, or
  :class:`~tmfem.errors.InfeasibleController` naming which check failed.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from tmfem.control.linear.lmi import SolverReport
from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tmfem.errors import InfeasibleController

log = logging.getLogger(__name__)


@dataclass
class HinfDesign:
    """An H-infinity controller and its certificate.

    ``gamma`` is the level the controller is certified for (the route's optimum ``gamma_lmi``
    relaxed by its tolerance), never below ``closed_loop_norm``, the verified ||T_pw||_inf;
    ``gamma_lower`` a certified lower bound of the optimum where the route has one (None
    otherwise); ``info`` route-specific details (for example the levels where a Riccati
    test failed numerically).

    ``controller`` is a python-control ``StateSpace`` from the measured outputs y (inputs,
    named as the plant's y) to the control inputs u (outputs, named as the plant's u).
    ``operating_point`` holds what the design is linearised about (e.g. q_e, u_e): the
    applied input is u_e + controller output (7.3: the plant describes perturbations).
    """

    controller: object
    gamma: float
    alpha: float
    closed_loop: object
    closed_loop_norm: float
    closed_loop_max_real_part: float
    solver: SolverReport
    plant: GeneralizedPlant
    kind: str
    R: np.ndarray | None = None
    S: np.ndarray | None = None
    cond_I_minus_RS: float | None = None
    operating_point: dict = field(default_factory=dict)
    gamma_lmi: float | None = None
    gamma_lower: float | None = None
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        # a reported level is never below the verified achieved norm
        if self.closed_loop_norm > self.gamma:
            log.info("%s: gamma %.8g raised to the verified closed-loop norm %.8g", self.kind,
                     self.gamma, self.closed_loop_norm)
            self.gamma = float(self.closed_loop_norm)

    def summary(self) -> dict:
        return {"kind": self.kind, "gamma": self.gamma, "gamma_lmi": self.gamma_lmi,
                "gamma_lower": self.gamma_lower, "alpha": self.alpha,
                "closed_loop_hinf_norm": self.closed_loop_norm,
                "closed_loop_max_real_part": self.closed_loop_max_real_part,
                "controller_order": int(self.controller.nstates),
                "cond_I_minus_RS": self.cond_I_minus_RS, "solver": self.solver.as_dict()}


def closed_loop(plant: GeneralizedPlant, controller):
    """Lower LFT of the plant with the controller (u = K y): the ``StateSpace`` from w to
    p, with python-control ``interconnect`` on the named signals."""
    import control
    P = plant.to_ss(name="P")
    w, p = list(plant.w_names), list(plant.p_names)
    return control.interconnect([P, controller], inplist=w, outlist=p, inputs=w, outputs=p,
                                name="T_pw")


def verify(plant: GeneralizedPlant, controller, *, gamma: float, alpha: float,
           rtol: float = 1e-3) -> tuple:
    """Closed-loop check: all poles with Re < -alpha (within ``rtol`` alpha + 1e-9) and
    ``control.norm(T_pw, 'inf') <= gamma (1 + rtol)``. Returns (T_pw, norm, max Re).

    Raises
    ------
    InfeasibleController
        when either check fails (poles first: ``control.norm`` does not check stability).
    """
    T = closed_loop(plant, controller)
    nrm, re = check_loop(T, gamma=gamma, alpha=alpha, rtol=rtol, what="closed loop")
    return T, nrm, re


def hinf_norm(T, *, n_sweep: int = 400) -> tuple:
    """(||T||_inf, sweep peak, frequency of the sweep peak in rad/s) of a stable
    ``StateSpace`` T (module docstring). Stability is the caller's check (AB13DD returns a
    finite value for unstable systems too)."""
    import control
    ab = float(control.norm(T, p="inf"))
    A = np.asarray(T.A)
    D = np.asarray(T.D)
    if A.shape[0] == 0:
        sv = float(np.linalg.norm(D, 2)) if D.size else 0.0
        return max(ab, sv), sv, 0.0
    lam = np.linalg.eigvals(A)
    mag = np.abs(lam[np.abs(lam) > 0])
    lo = np.log10(max(mag.min() / 100, 1e-8)) if mag.size else -3.0
    hi = np.log10(max(mag.max() * 100, 1e-6)) if mag.size else 3.0
    w = np.unique(np.concatenate([np.logspace(lo, hi, n_sweep), np.abs(lam.imag), mag, [0.0]]))
    H = np.asarray(T(1j * w)).reshape(T.noutputs, T.ninputs, w.size)
    s = np.linalg.svd(np.moveaxis(H, 2, 0), compute_uv=False)[:, 0]
    k = int(np.argmax(s))
    sweep = float(s[k])
    if sweep > ab * (1 + 1e-6) + 1e-12:
        log.warning("H-infinity norm: AB13DD gave %.8g, the frequency sweep %.8g at %.4g rad/s: "
                    "using the sweep", ab, sweep, w[k])
    return max(ab, sweep), sweep, float(w[k])


def check_loop(T, *, gamma: float, alpha: float, rtol: float, what: str,
               sweep: bool = True) -> tuple:
    """(||T||_inf, max Re of its poles) of a closed loop T, or :class:`InfeasibleController`
    when a pole lies right of -alpha (within ``rtol`` alpha + 1e-9) or the norm
    (:func:`hinf_norm`; AB13DD alone with ``sweep=False``, for the intermediate steps of a
    bisection) exceeds gamma (1 + rtol); poles first."""
    import control
    re = float(np.max(np.real(T.poles()))) if T.nstates else -np.inf
    if not re < -alpha + rtol * max(alpha, 1e-6) + 1e-9:
        raise InfeasibleController(f"{what}: expected all poles with Re < -alpha_1 = "
                                   f"{-alpha:g}, found max Re = {re:.6g}")
    nrm = hinf_norm(T)[0] if sweep else float(control.norm(T, p="inf"))
    if not nrm <= gamma * (1 + rtol):
        raise InfeasibleController(f"{what}: expected ||T_pw||_inf <= gamma = {gamma:.6g}, "
                                   f"found {nrm:.6g}")
    return nrm, re


def controller_ss(plant: GeneralizedPlant, Ak, Bk, Ck, Dk):
    """The controller (A_k, B_k, C_k, D_k) as a ``StateSpace`` from the plant's measured
    signals y to its control inputs u, named as the plant's."""
    import control
    nk = np.shape(Ak)[0]
    return control.ss(Ak, Bk, Ck, Dk, inputs=list(plant.y_names), outputs=list(plant.u_names),
                      states=[f"xk_{i + 1}" for i in range(nk)], name="K")
