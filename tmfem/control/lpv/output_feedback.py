"""Output-feedback LPV control: the scheduled state feedback of eqs. 5.95-5.99 with a gridded
Kalman estimator (the output feedback that 9.2 names as future work).

Formulation (observer-based, frozen-parameter verified; docs/guides/lpv.md). The plant of
:func:`~tmfem.control.lpv.synthesis.interconnection_8_1` is measured through

    y_m = C_m(rho) x_z + W_n n,          (the bar coordinates q and the K membrane points of eq. 5.17)

with measurement noise n. The controller is

    x^' = A(rho) e + B(rho) (u - u_e(rho)) + L(rho) (y_m - y_e(rho) - C_m(rho) e),  e = x^ - x_e(rho)
    xi' = q_d - q_m                       (q_m: the measured q, noisy; eq. 5.98)
    u   = u_e(rho) + K(rho) [e; xi],      K(rho) = Q(rho) P(rho)^-1 (eq. 5.99)

with rho read from the measured theta_13, psi_13. L_i is the steady-state Kalman gain of each
grid plant for process noise W_d n_d entering as the input disturbance of Fig. 8.1 and
measurement noise W_n n (white, intensities W_d^2 I and W_n^2 I):

    A S + S A^T + W_d^2 B B^T - S C_m^T C_m S / W_n^2 = 0,     L = S C_m^T / W_n^2,

and L(rho) is interpolated between grid points (multilinearly, or by splines:
:class:`~tmfem.control.lpv.plant.GriddedLPV`), as are A, B, C_m, x_e, u_e, y_e of the
estimator's model, whose grid may be finer than the design's; K(rho) is the rational function
of the state-feedback design.

What is guaranteed. K(rho) carries the rate-bounded certificate of eqs. 5.95-5.96 on the
design grid (for *state* feedback). The output-feedback loop's own rate-bounded certificate is
:mod:`tmfem.control.lpv.certificate`; without it, at a design grid point the frozen closed loop has the eigenvalues of A
+ B2 K and of A - L C_m
(separation principle); between grid points and for the closed-loop H-infinity norm from
w = [q_d, n_d, n] to p = [e_r, e_u], :func:`verify_output_feedback` checks frozen plants of a
finer grid (frozen-parameter stability and norm only; nothing about varying rho), and the
sampled-data loop at the controller's sample time.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from tmfem.control.lpv.controller import Scheduled
from tmfem.control.lpv.plant import GriddedLPV, grid_point_text
from tmfem.control.lpv.certificate import closed_loop_lpv
from tmfem.control.lpv.generalized_plant import state_scaling
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.control.lpv.verify import verify
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


def kalman_gain(A, B, C, *, W_d: float, W_n: float, eps: float = 0.0) -> np.ndarray:
    """Steady-state Kalman gain L = S C^T / W_n^2 of x' = A x + B W_d n_d, y = C x + W_n n
    (module docstring; ``eps`` I is added to the process-noise intensity). Solved in the
    diagonally balanced coordinates of A (x = T x_s) and returned in the original ones.

    Raises
    ------
    InfeasibleController
        When the filter Riccati equation has no stabilising solution ((A, C) not detectable).
    """
    T = state_scaling(A)
    Ti = 1.0 / T
    As, Bs, Cs = Ti[:, None] * A * T[None, :], Ti[:, None] * B, C * T[None, :]
    Qn = W_d ** 2 * Bs @ Bs.T + eps * np.eye(A.shape[0])
    try:
        S = sla.solve_continuous_are(As.T, Cs.T, Qn, W_n ** 2 * np.eye(C.shape[0]))
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise InfeasibleController(f"Kalman filter Riccati equation: expected a stabilising solution, "
                                   f"found none ({exc})") from None
    L = (S @ Cs.T) / W_n ** 2
    return T[:, None] * L


@dataclass
class LPVOutputFeedback:
    """Observer-based scheduled output feedback (module docstring).

    Attributes
    ----------
    state_feedback : LPVStateFeedback
        K(rho) over [x_z, xi] (states of ``interconnection_8_1``).
    estimator : GriddedLPV
        The estimator's model on the design grid: A, B = [B, L], C = C_m (measured rows),
        D = 0, with the equilibria x_e, u_e = [u_e, 0], y_e (measured rows).
    measured : list of str
        Names of the measured signals (outputs or states of the design plant).
    tracked_rows : ndarray
        Positions of the tracked q in the measured vector (the integrators' order).
    W_d, W_n : float
        Process- (input-disturbance) and measurement-noise weights of the filter design.
    """

    state_feedback: LPVStateFeedback
    estimator: GriddedLPV
    measured: list
    tracked_rows: np.ndarray
    W_d: float
    W_n: float

    @property
    def nx(self) -> int:
        return self.estimator.nx

    @property
    def nu(self) -> int:
        return self.estimator.nu - len(self.measured)

    def model(self, rho):
        """(A, B, C_m, L, K_x, K_xi) of the controller at ``rho`` (module docstring)."""
        A, BL, C, _ = self.estimator.at(rho)
        K = self.state_feedback.gain(rho)
        return A, BL[:, :self.nu], C, BL[:, self.nu:], K[:, :self.nx], K[:, self.nx:]

    def frozen_closed_loop(self, A, B, C_m, rho, *, W_e: float, W_u: float, W_d: float | None = None,
                           W_n: float | None = None):
        """The frozen closed loop of the true plant (A, B, C_m) and the controller at ``rho``.

        States [x_z, xi, e], exogenous w = [q_d, n_d, n] (n_d the input disturbance of
        Fig. 8.1, weight W_d; n the measurement noise, weight W_n; default the design's),
        regulated p = [W_e (q_d - q), W_u u] with q = T_q x_z the tracked rows of C_m:

            x_z' = A x_z + B (K_x e + K_xi xi) + W_d B n_d
            xi'  = q_d - T_q x_z - W_n S_q n
            e'   = L C_m x_z + (A^ + B^ K_x - L C^) e + B^ K_xi xi + W_n L n

        (hats: the controller's interpolated model). Returns (A_cl, B_cl, C_cl, D_cl).
        """
        W_d = self.W_d if W_d is None else W_d
        W_n = self.W_n if W_n is None else W_n
        Am, Bm, Cm, L, Kx, Kxi = self.model(rho)
        n, nu, ny, nq = A.shape[0], B.shape[1], C_m.shape[0], self.tracked_rows.size
        Tq = C_m[self.tracked_rows]
        Sq = np.eye(ny)[self.tracked_rows]
        Z = np.zeros
        Acl = np.block([[A, B @ Kxi, B @ Kx],
                        [-Tq, Z((nq, nq)), Z((nq, n))],
                        [L @ C_m, Bm @ Kxi, Am + Bm @ Kx - L @ Cm]])
        Bcl = np.block([[Z((n, nq)), W_d * B, Z((n, ny))],
                        [np.eye(nq), Z((nq, nu)), -W_n * Sq],
                        [Z((n, nq)), Z((n, nu)), W_n * L]])
        Ccl = np.block([[-W_e * Tq, Z((nq, nq)), Z((nq, n))],
                        [Z((nu, n)), W_u * Kxi, W_u * Kx]])
        Dcl = np.block([[W_e * np.eye(nq), Z((nq, nu + ny))], [Z((nu, nq + nu + ny))]])
        return Acl, Bcl, Ccl, Dcl

    def step_matrices(self, rho, dt: float):
        """(Phi, Gamma_u, Gamma_y) of the estimator over one sample dt at frozen rho: the exact
        zero-order-hold solution e(t + dt) = Phi e + Gamma_u (u - u_e) + Gamma_y (y_m - y_e)
        of e' = (A - L C_m) e + B (u - u_e) + L (y_m - y_e)."""
        A, BL, C, _ = self.estimator.at(rho)
        n, m, nu = A.shape[0], BL.shape[1], self.nu
        E = sla.expm(np.block([[A - BL[:, nu:] @ C, BL], [np.zeros((m, n + m))]]) * dt)
        return E[:n, :n], E[:n, n:n + nu], E[:n, n + nu:]

    def save(self, path) -> None:
        """The state-feedback coefficients (``LPVStateFeedback.save``) with the gridded gains
        L_i (``L``), the measured names, the noise weights and the estimator's interpolation,
        in one ``.npz``."""
        np.savez(path, **self.state_feedback.arrays(), L=self.estimator.B[..., self.nu:],
                 measured=np.array(self.measured), tracked_rows=self.tracked_rows, W_d=self.W_d,
                 W_n=self.W_n, interpolation=self.estimator.interpolation)


def design_output_feedback(state_feedback: LPVStateFeedback, plant: GriddedLPV, *, tracked,
                           measured, W_d: float = 1e-3, W_n: float = 1e-3,
                           eps: float = 0.0, interpolation: str = "multilinear") -> LPVOutputFeedback:
    """The gridded Kalman estimator of ``plant`` for the signals ``measured`` and the
    output-feedback controller with ``state_feedback``.

    Parameters
    ----------
    measured : list of str
        Measured outputs or states of ``plant`` (2-3: the bar coordinates q and the membrane
        point coordinates wr_k of eq. 5.17).
    tracked : list of str
        The tracked outputs q (the integrators of ``state_feedback``, in its order).
    W_d, W_n : float
        Filter weights (module docstring; 8.3's W_d = 0.001 and 7.4's measurement-noise
        weight 0.001 by default).
    interpolation : {"multilinear", "spline"}
        How the estimator's model and gains are evaluated between grid points
        (:class:`~tmfem.control.lpv.plant.GriddedLPV`). Splines bring the model 13-16 x closer
        to the true 2-3 plant between the 6 x 3 design points (docs/guides/lpv.md), where it
        couples the estimation error to the state.
    """
    measured, tracked = list(measured), list(tracked)
    known = list(plant.output_names) + list(plant.state_names)
    bad = [m for m in measured if m not in known]
    if bad or not measured:
        raise InputError(f"output feedback: measured signals must be plant outputs or states, found "
                         f"unknown {bad or 'none given'}")
    missing = [t for t in tracked if t not in measured]
    if missing:
        raise InputError(f"output feedback: the tracked outputs must be measured, found {missing} not in "
                         f"the measured signals")
    for nm, v in (("W_d", W_d), ("W_n", W_n)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"output feedback: {nm} expected > 0, found {v!r}")
    n, nq = plant.nx, len(tracked)
    if state_feedback.P[0].shape[0] != n + nq:
        raise InputError(f"output feedback: expected a state feedback over {n} + {nq} states, found "
                         f"{state_feedback.P[0].shape[0]}")
    C, y_e = plant.measurement(measured)
    ny = len(measured)
    L = np.zeros(plant.grid_shape + (n, ny))
    for idx, rho in plant.points():
        L[idx] = kalman_gain(plant.A[idx], plant.B[idx], C[idx], W_d=W_d, W_n=W_n, eps=eps)
        ev = np.linalg.eigvals(plant.A[idx] - L[idx] @ C[idx]).real.max()
        log.info("Kalman estimator at %s: max Re(A - L C) = %.3e", grid_point_text(plant.parameter_names, rho), ev)
    shp = plant.grid_shape
    est = GriddedLPV(axes=plant.axes, parameter_names=plant.parameter_names, A=plant.A,
                     B=np.concatenate([plant.B, L], -1), C=C, D=np.zeros(shp + (ny, plant.nu + ny)),
                     rate_bounds=plant.rate_bounds, state_names=plant.state_names,
                     input_names=list(plant.input_names) + [f"innovation_{m}" for m in measured],
                     output_names=measured, x_e=plant.x_e,
                     u_e=np.concatenate([plant.u_e, np.zeros(shp + (ny,))], -1), y_e=y_e,
                     interpolation=interpolation)
    return LPVOutputFeedback(state_feedback=state_feedback, estimator=est, measured=measured,
                             tracked_rows=np.array([measured.index(t) for t in tracked], dtype=int),
                             W_d=float(W_d), W_n=float(W_n))


@dataclass
class OutputFeedbackVerification:
    """Frozen-parameter checks of an :class:`LPVOutputFeedback` on a (finer) grid: the
    largest closed-loop eigenvalue real part, the largest closed-loop H-infinity norm from
    w = [q_d, n_d, n] to p (python-control ``norm``, SLICOT ab13dd) and, with a sample time,
    the largest spectral radius of the sampled-data loops of the output feedback and of the
    state feedback alone (:class:`~tmfem.control.lpv.controller.LPVController`'s discretisation),
    each with the parameter values where it occurs. With a rate-bounded certificate
    (:mod:`tmfem.control.lpv.certificate`) also its analysis LMI with the certificate's X(rho)
    and gamma re-checked on this grid (``certificate_check``, a
    :class:`~tmfem.control.lpv.verify.Verification`; None when no certificate was found)."""

    grid: tuple
    max_cl_real: float
    max_cl_real_at: list
    max_hinf: float
    max_hinf_at: list
    dt: float | None
    max_sampled_radius: float | None
    max_sampled_radius_at: list | None
    state_feedback_sampled_radius: float | None
    passed: bool
    certificate: object = None
    certificate_check: object = None

    def to_dict(self) -> dict:
        cert = {}
        if self.certificate is not None:
            cert = self.certificate.to_dict()
            chk = self.certificate_check
            cert.update({"rate_bounded_verification_max_eig": None if chk is None else chk.max_lmi_eig,
                         "rate_bounded_verification_max_eig_at": None if chk is None else chk.max_lmi_eig_at})
        return {**cert, "verification_grid": list(self.grid), "output_feedback_closed_loop_max_real": self.max_cl_real,
                "output_feedback_closed_loop_max_real_at": self.max_cl_real_at,
                "output_feedback_hinf_max": self.max_hinf, "output_feedback_hinf_max_at": self.max_hinf_at,
                "sample_time_s": self.dt, "output_feedback_sampled_max_radius": self.max_sampled_radius,
                "output_feedback_sampled_max_radius_at": self.max_sampled_radius_at,
                "state_feedback_sampled_max_radius": self.state_feedback_sampled_radius,
                "output_feedback_passed": self.passed}


def sampled_closed_loops(design: LPVOutputFeedback, A, B, C_m, rho, dt: float):
    """Transition matrices of the sampled-data frozen loops at ``rho`` (references and noise
    zero, deviation coordinates): the plant (A, B) held over dt (zero-order hold), the
    integrator xi+ = xi - dt T_q x_z (forward Euler, as the controllers), and

    * output feedback, states [x_z, xi, e]: e+ = Phi e + Gamma_u u + Gamma_y C_m x_z,
      u = K_x e + K_xi xi (:meth:`LPVOutputFeedback.step_matrices`);
    * state feedback, states [x_z, xi]: u = K_x x_z + K_xi xi.
    """
    n, nu = A.shape[0], B.shape[1]
    E = sla.expm(np.block([[A, B], [np.zeros((nu, n + nu))]]) * dt)
    Ad, Bd = E[:n, :n], E[:n, n:]
    _, _, _, _, Kx, Kxi = design.model(rho)
    Phi, Gu, Gy = design.step_matrices(rho, dt)
    Tq = C_m[design.tracked_rows]
    nq = Tq.shape[0]
    I, Z = np.eye(nq), np.zeros
    M_of = np.block([[Ad, Bd @ Kxi, Bd @ Kx], [-dt * Tq, I, Z((nq, n))],
                     [Gy @ C_m, Gu @ Kxi, Phi + Gu @ Kx]])
    M_sf = np.block([[Ad + Bd @ Kx, Bd @ Kxi], [-dt * Tq, I]])
    return M_of, M_sf


def verify_output_feedback(design: LPVOutputFeedback, plant: GriddedLPV, *, W_e: float, W_u: float,
                           dt: float | None = None, allow_failure: bool = False, certificate=None,
                           progress=None) -> OutputFeedbackVerification:
    """Check ``design`` on the frozen plants of ``plant`` (e.g. COM linearisations on a grid
    4x finer than the design's; :meth:`LPVOutputFeedback.frozen_closed_loop` with the
    weights W_e, W_u of Fig. 8.1). Passes when every frozen loop is stable and, with ``dt``,
    every sampled-data loop of the output feedback has spectral radius < 1. The H-infinity
    norms are reported, not judged (there is no synthesised bound for them). With ``certificate``
    (a found :class:`~tmfem.control.lpv.certificate.RateBoundedCertificate` of the design grid)
    its analysis LMI must also hold at every point and rate vertex of ``plant``: then the loop is
    stable for rho varying within the rate bounds and its L2 gain is below the certificate's gamma.

    Raises
    ------
    InfeasibleController
        When a check fails, unless ``allow_failure`` (then ``passed`` is False).
    """
    import control
    C, _ = plant.measurement(design.measured)
    cl, cl_at, hn, hn_at = -np.inf, None, -np.inf, None
    sr, sr_at, sf = (-np.inf, None, -np.inf) if dt else (None, None, None)
    for k, (idx, rho) in enumerate(plant.points()):
        A, B = plant.A[idx], plant.B[idx]
        Acl, Bcl, Ccl, Dcl = design.frozen_closed_loop(A, B, C[idx], rho, W_e=W_e, W_u=W_u)
        ev = float(np.linalg.eigvals(Acl).real.max())
        if ev > cl:
            cl, cl_at = ev, rho.tolist()
        nrm = float(control.norm(control.ss(Acl, Bcl, Ccl, Dcl), p="inf")) if ev < 0 else np.inf
        if nrm > hn:
            hn, hn_at = nrm, rho.tolist()
        if dt:
            M_of, M_sf = sampled_closed_loops(design, A, B, C[idx], rho, dt)
            r = float(np.abs(np.linalg.eigvals(M_of)).max())
            if r > sr:
                sr, sr_at = r, rho.tolist()
            sf = max(sf, float(np.abs(np.linalg.eigvals(M_sf)).max()))
        if progress is not None:
            progress(k + 1, int(np.prod(plant.grid_shape)))
    chk = None
    if certificate is not None and certificate.found:
        chk = verify(certificate.lyapunov, closed_loop_lpv(design, plant, W_e=W_e, W_u=W_u), allow_failure=True)
    ok = cl < 0 and (not dt or sr < 1) and (chk is None or chk.max_lmi_eig < 0)
    res = OutputFeedbackVerification(grid=plant.grid_shape, max_cl_real=cl, max_cl_real_at=cl_at, max_hinf=hn,
                                     max_hinf_at=hn_at, dt=dt, max_sampled_radius=sr, max_sampled_radius_at=sr_at,
                                     state_feedback_sampled_radius=sf, passed=bool(ok), certificate=certificate,
                                     certificate_check=chk)
    at = lambda rho: grid_point_text(plant.parameter_names, rho)          # noqa: E731
    log.info("LPV output feedback on %s: max closed-loop Re %.3e at %s, max ||T_pw|| %.4g at %s, "
             "sampled radius %s at %s", plant.grid_shape, cl, at(cl_at), hn, at(hn_at), sr, at(sr_at))
    if not ok and not allow_failure:
        raise InfeasibleController(
            f"LPV output feedback fails its frozen-parameter verification on a {plant.grid_shape} grid: "
            f"largest closed-loop real part {cl:.3e} at {at(cl_at)}"
            + (f", largest sampled-data spectral radius {sr:.6f} at {at(sr_at)} (dt = {dt} s)" if dt else "")
            + (f", rate-bounded LMI (gamma = {certificate.gamma:.5g}) largest relative eigenvalue "
               f"{chk.max_lmi_eig:.3e} at {at(chk.max_lmi_eig_at)}" if chk is not None else "")
            + "; expected < 0" + (" and < 1" if dt else ""))
    return res


class LPVOutputController(Scheduled):
    """The observer-based scheduled controller of the module docstring as a simulation
    controller (protocol of :mod:`tmfem.simulation.controllers`).

    Controller state [x^, xi] (the absolute state estimate and the integrators). Per sample
    dt, rho is read from the measured signals (``schedule="measured"``, as 8.4 schedules the
    state feedback) or from the estimate x^ (``"estimate"``: the parameters are states of the
    plant, theta_13 and psi_13 for 2-3; the estimate filters the measurement noise out of
    x_e(rho), u_e(rho) and K(rho)) and held inside the design grid; the estimate
    advances by the exact zero-order-hold solution of the frozen estimator
    (:meth:`LPVOutputFeedback.step_matrices`, rho and the commanded u held over the step),
    the integrators by forward Euler (as :class:`~tmfem.control.lpv.controller.LPVController`).
    The estimator is driven by the commanded input, or with ``input_limits`` by the input the
    plant is expected to receive after a saturation downstream (the rest-length limits of
    7.4: the estimate otherwise drifts from the plant while a limit acts).

    Parameters
    ----------
    design : LPVOutputFeedback
    measured_index : sequence of int
        Positions in the plant's output vector y of the measured signals (``design.measured``).
    rho_index : sequence of int
        Positions in y of the scheduling parameters (measured: for 2-3 theta_13 and psi_13,
        which are also among the measured signals); with ``schedule="estimate"`` used at
        :meth:`reset` only.
    schedule : {"measured", "estimate"}
    reference_rho : callable, optional
        t -> rho_r(t), the parameters of the reference: the control law is then taken about
        the equilibrium the reference passes through, u = u_e(rho_r) + K(rho) [x^ - x_e(rho_r);
        xi] (as :class:`~tmfem.control.lpv.controller.LPVController` with ``reference_rho``);
        the estimator keeps its model about the scheduling rho.
    input_limits : callable, optional
        (u, y_m) -> the saturated input, e.g. u clipped to [r_min, |tendon|(q_m)] with the
        measured q (:func:`tmfem.control.deployment.limits.tendon_lengths`).
    reference : callable
        t -> q_d(t) (absolute values, as the measured q).
    """

    def __init__(self, design: LPVOutputFeedback, *, measured_index, rho_index, reference,
                 schedule: str = "measured", reference_rho=None, input_limits=None, name: str = "lpv-output"):
        self.design, self.name = design, name
        self.measured_index = np.asarray(measured_index, dtype=int)
        est = design.estimator
        self._schedule(est.axes, rho_index, reference, "LPV output controller", reference_rho)
        if self.measured_index.size != len(design.measured) or self.rho_index.size != len(est.axes):
            raise InputError(f"LPV output controller: expected {len(design.measured)} measured and "
                             f"{len(est.axes)} scheduling indices, found {self.measured_index.size} and "
                             f"{self.rho_index.size}")
        if schedule not in ("measured", "estimate"):
            raise InputError(f"LPV output controller: schedule expected 'measured' or 'estimate', found "
                             f"{schedule!r}")
        self._from_estimate = None
        if schedule == "estimate":
            missing = [p for p in est.parameter_names if p not in est.state_names]
            if missing:
                raise InputError(f"LPV output controller: schedule='estimate' needs the parameters among the "
                                 f"plant states, found {missing} not in them")
            self._from_estimate = np.array([est.state_names.index(p) for p in est.parameter_names])
        if input_limits is not None and not callable(input_limits):
            raise InputError("LPV output controller: expected input_limits as a callable (u, y_m) -> u")
        self.input_limits = input_limits
        self._last = None

    @property
    def read_index(self) -> np.ndarray:
        """The entries of y the controller reads (the measured signals and rho)."""
        return np.concatenate([self.measured_index, self.rho_index])

    def _read(self, t, y, xc):
        key = (t, np.asarray(y, dtype=float).tobytes(), np.asarray(xc, dtype=float).tobytes())
        if self._last is not None and self._last[0] == key:        # output, then update, of one step
            return self._last[1]
        self._last = (key, self._evaluate(t, y, xc))
        return self._last[1]

    def _evaluate(self, t, y, xc):
        """Measured signals, scheduling rho, estimator deviation e = x^ - x_e(rho) with u_e(rho),
        and the input u."""
        est, n = self.design.estimator, self.design.nx
        ym = np.asarray(y, dtype=float)[self.measured_index]
        rho = self.rho(y) if self._from_estimate is None else \
            np.clip(xc[self._from_estimate], self._lo, self._hi)
        x_e, ue = est.interpolate(("x_e", "u_e"), rho)
        ue = ue[:self.design.nu]
        x_c, u_c = x_e, ue
        if self.reference_rho is not None:
            x_c, u_c = est.interpolate(("x_e", "u_e"), self.operating_rho(t, rho))
            u_c = u_c[:self.design.nu]
        u = u_c + self.design.state_feedback.gain(rho) @ np.concatenate([xc[:n] - x_c, xc[n:]])
        return ym, rho, xc[:n] - x_e, ue, u, x_e

    def reset(self, t0, y0, dt):
        """x^ starts at the equilibrium of the measured rho (bumpless from an equilibrium), xi = 0."""
        self._sample_time(dt)
        self._last = None
        rho = self.rho(y0)
        return np.concatenate([self.design.estimator.interpolate("x_e", rho),
                               np.zeros(self.design.tracked_rows.size)])

    def output(self, t, y, xc):
        return self._read(t, y, xc)[4]

    def update(self, t, y, xc):
        ym, rho, e, ue, u, x_e = self._read(t, y, xc)
        if self.input_limits is not None:
            u = np.asarray(self.input_limits(u, ym), dtype=float)
        Phi, Gu, Gy = self.design.step_matrices(rho, self._dt)
        ye = self.design.estimator.interpolate("y_e", rho)
        n = self.design.nx
        xi = xc[n:] + self._dt * (np.asarray(self.reference(t), dtype=float) - ym[self.design.tracked_rows])
        return np.concatenate([x_e + Phi @ e + Gu @ (u - ue) + Gy @ (ym - ye), xi])
