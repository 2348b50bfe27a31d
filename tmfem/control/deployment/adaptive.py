"""The adaptive collocated-PFL deployment controller (dissertation eqs. 5.42-5.58, 5.69, 5.72).

Control law (eq. 5.58), sampled every dt with a zero-order hold:

    u = B_q^-1 (-F_q - W_F^T Phi_F - q_d'' + D_q (q' - q_d') + K_q (q - q_d)),
    W_F' = Proj(W_F, -Gamma Phi_F (e^T P_2 + e'^T P_3)),   e = q - q_d,

with P_2 = alpha I, P_3 = beta I (eq. 5.50), D_q = d_q(t) I, K_q = k_q(t) I and (eq. 5.69)

    omega(t) = omega_0 + omega_e (1 - exp(-t / tau)),  d_q = 2 d_c omega,  k_q = omega^2.

B_q is exact (eq. 5.42); F_q is the controller's nominal model of F_q* (eq. 5.41), with the
uncertainty models of 7.4:

``"initial"``   F_q = F_q* at the initial configuration (q_0, q' = 0, eta = 0), eq. 5.72 (1-4(D));
``"no-MG"``     F_q from F_hat without the term M(x) G of eq. 5.28 (1-6(D), 2-3);
``"exact"``     F_q = F_q* (no model error; a check).

The controller reads the full state: the plant outputs are y = [z, z'] (the dissertation
assumes full-state measurement in 7.2; :class:`tmfem.control.deployment.run.StatePlant`).

Rest-length limits (7.4, "treated as control limits"): with ``allocation="bounded"`` the
inversion of eq. 5.58 honours r_min <= u <= |tendon|(q) by
:func:`tmfem.control.deployment.pfl.bounded_inversion` (the admissible u closest in acceleration);
``"clip"`` returns eq. 5.58 unchanged and leaves the limits to the plant-side saturation
(:class:`tmfem.control.deployment.run.RestLengthLimits`). The dissertation does not say how it
treats an active limit; the two differ only while one is active.

Where the model terms are evaluated (``evaluation``): ``"state"`` (eq. 5.58 as printed) takes
M_hat, F_hat, B_hat (eq. 5.28) at the measured state (q, q', eta, eta'); the law then cancels
the structure's own stiffness and puts k_q in its place, so a plant whose stiffness differs
from the model's by more than k_q / omega_i^2 in a stiff direction i is unstable in closed
loop (the 2-3 stage-2 bars moving in the membrane's plane: omega_i^2 up to 3.2e3 s^-2
against k_q = 1-47 s^-2 over the first 1.4 s, a tolerance of 0.03-1.5 %; docs/guides/fe-plant.md).
``"reference"`` takes them at the reference (q_d, q_d') with the measured membrane
coordinates (eta, eta'): a feedforward along the reference plus the feedback
D_q e' + K_q e (the "PD+" of robot control). The linearised closed loop then keeps the
plant's own tangent stiffness, q'' = -M_q^-1 K_p e - k_q e - d_q e', so an error of the
model's stiffness changes the tracking error, not the stability (K_p is positive definite at
the stable equilibria of the path). The error e, the rates and the RBF input v_q stay the
measured ones.

The tendon model (``tendon_law``): the control-oriented model writes the tendon forces as
B(x) u (eq. 5.19) with the rates k = EA / u_0 of the final rest lengths. For a plant whose
tendons keep their EA while their rest length changes (k = EA / u, eq. 3.9; the MTC plant's
``"cable"`` law) the tendon force T = EA (|d| / u - 1) is affine in w = 1/u, and eq. 5.46 is
solved for w with B_q' = -B_q diag(u_0 |d|) (:meth:`AdaptivePFL._cable`).

Damped feedback inversion (``feedback_damping`` = mu > 0, our option): the bracket of
eq. 5.58 splits into the feedforward v_ff = -F_q - W_F^T Phi_F - q_d'' (its value at
e = e' = 0) and the feedback v_fb = D_q e' + K_q e; the rest lengths are
u = B_q^-1 v_ff + du with du the damped least-squares solution of B_q du = v_fb (Tikhonov
factor mu s_1 in the metric of M_q, :func:`tmfem.control.deployment.pfl.bounded_inversion`; the limits
on u + du). The COM's B_q of a 1-N(D) system is ill-conditioned (1-4(D): condition number
~220): in its weak directions -- combinations of SL and SU whose bar accelerations almost
cancel on the rigid bars -- eq. 5.46 commands large tendon-force changes that an elastic
structure answers differently (docs/guides/fe-plant.md); the damping leaves the strong
directions inverted and bounds the gain of the weak ones at 1 / (2 mu s_1).

Over-actuated systems (M >= 3 stages: n_t > n_q, a wide B_q of full row rank): eq. 5.58 is
met by an affine space of rest lengths (the null space of B_q: self-stress changes that
leave the bar accelerations alone); the controller takes the one closest to a reference
u_ref, u = u_ref + B_q^+ (v - B_q u_ref)
(:func:`tmfem.control.deployment.pfl.exact_inversion`); with active limits the bounded
problem is regularised toward u_ref (:func:`tmfem.control.deployment.pfl.bounded_inversion`).
u_ref is the reference trajectory's own rest lengths u_d(t) (``rest_length_reference``: the
self-stress of the path's equilibrium at the progress s(t), scaled to the membrane force,
:func:`tmfem.equilibrium.deployment_path.path_rest_lengths`): the null-space part of u then
carries the prestress the path was designed with. Without it, the previous sample's rest
lengths (the first sample: ``u_initial``) give the smallest actuator change per sample, but
the prestress then drifts with the rotating null space of B_q (on the 3-3 of the tests its
R_2 and S_3 tendons reach their tendon lengths, slack, for 6 s).

The limits of 7.4 (r_min <= u <= |tendon|) let a tendon go slack at its upper bound, and the
solution closest to u_d does so where the commanded acceleration lowers a tendon's force
below zero (on the 3-3: R_2 and S_3 for 7 s, although a solution with every tendon in
tension exists). With a reference u_d(t) the extra tendons are used to keep the prestress:
the upper limit becomes |tendon| - f (L_d - u_d), L_d the tendon lengths at the reference
configuration and f the tension floor (``tension_floor``, the file's ``[deployment]
tension_floor``, default 0.5), so every tendon keeps at least the fraction f of its elongation
(its force, at a given rate) along the path; the bounded problem finds the acceleration within these
limits. A square B_q leaves no such freedom and keeps the limits of 7.4.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from tmfem.control.deployment.pfl import (PFLTerms, bounded_inversion, check_input_matrix,
                                          exact_inversion, partition)
from tmfem.control.deployment.limits import tendon_lengths
from tmfem.control.deployment.rbf import GaussianRBF, euler_step
from tmfem.errors import InputError, SingularInputMatrix
from tmfem.system.problem import TENSION_FLOOR

UNCERTAINTY = ("initial", "no-MG", "exact")
ALLOCATION = ("bounded", "clip")
EVALUATION = ("state", "reference")
TENDON_LAWS = ("fixed-rate", "cable")


@dataclass
class Gains:
    """Time-varying gains of eq. 5.69 (Table 7.1)."""

    omega_0: float
    omega_e: float
    tau: float
    d_c: float

    def __post_init__(self):
        values = (self.omega_0, self.omega_e, self.tau, self.d_c)
        if not (np.all(np.isfinite(values)) and self.omega_0 > 0 and self.omega_e >= 0
                and self.tau > 0 and self.d_c > 0):
            raise InputError(f"PFL gains (eq. 5.69): expected omega_0 > 0, omega_e >= 0 [rad/s], "
                             f"tau > 0 [s] and d_c > 0, found omega_0 = {self.omega_0}, "
                             f"omega_e = {self.omega_e}, tau = {self.tau}, d_c = {self.d_c}")

    def __call__(self, t: float) -> tuple[float, float]:
        """(d_q, k_q) at time t (eqs. 5.47, 5.69)."""
        w = self.omega_0 + self.omega_e * (1 - np.exp(-t / self.tau))
        return 2 * self.d_c * w, w * w


class AdaptivePFL:
    """Controller hook (``tmfem.simulation.controllers``) of eq. 5.58.

    Parameters
    ----------
    model : ControlOrientedModel
        The controller's model (modal coordinates: z = [q, eta]).
    reference : callable
        ``reference(t) -> (q_d, q_d', q_d'')``.
    gains : Gains
    rbf : GaussianRBF
        Network on v_q = [q; q'] (eq. 5.44).
    w_bar : float
        Column bound of the projection (eqs. 5.51-5.52).
    gamma, alpha, beta : float
        Adaptation gain Gamma and the weights of eq. 5.50 (7.4: 0.01, 1, 1).
    uncertainty : {"initial", "no-MG", "exact"}
    z_initial : array, optional
        Configuration at which ``"initial"`` evaluates F_q* (default: q_d(0), eta = 0).
    allocation : {"bounded", "clip"}
        Treatment of the rest-length limits (module docstring).
    r_min : float
        Smallest rest length [m] of the limits.
    cond_every : int
        The condition number of B_q (eq. 5.46) is computed and checked every ``cond_every``
        samples (an exactly singular B_q fails its solve at any sample and is named then).
    evaluation : {"state", "reference"}
        Where M_hat, F_hat, B_hat are evaluated (module docstring): at the measured state
        (eq. 5.58) or at the reference (q_d, q_d') with the measured membrane coordinates.
    tendon_law : {"fixed-rate", "cable"}
        The controller's tendon model (module docstring): the model's rates k = EA / u_0
        (eq. 5.19, the COM) or k = EA / u (eq. 3.9 at the commanded rest length, a cable of
        fixed EA), for which eq. 5.46 is solved in 1/u.
    feedback_damping : float
        mu >= 0 (module docstring, "Damped feedback inversion"): 0 inverts eq. 5.58 as
        printed; mu > 0 inverts the feedforward part exactly and the feedback part
        D_q e' + K_q e by the damped least squares of
        :func:`tmfem.control.deployment.pfl.bounded_inversion`.
    u_initial : array, optional
        Rest lengths [m] at the start (the packaged configuration's), the reference of the
        first sample's inversion of a wide B_q (module docstring, "Over-actuated systems");
        default the model's u_0.
    rest_length_reference : callable, optional
        ``u_d(t)`` [m], the rest lengths of the reference trajectory's equilibria, the
        reference of the inversion of a wide B_q (module docstring); default: the previous
        sample's commanded rest lengths.
    tension_floor : float
        f in [0, 1): with ``rest_length_reference``, the fraction of each tendon's path
        elongation L_d - u_d that the upper limit keeps (module docstring).
    """

    name = "adaptive-pfl"

    def __init__(self, *, model, reference, gains: Gains, rbf: GaussianRBF, w_bar: float,
                 gamma: float = 0.01, alpha: float = 1.0, beta: float = 1.0,
                 uncertainty: str = "initial", z_initial=None, allocation: str = "bounded",
                 r_min: float = 1e-3, cond_every: int = 10, evaluation: str = "state",
                 tendon_law: str = "fixed-rate", feedback_damping: float = 0.0, u_initial=None,
                 rest_length_reference=None, tension_floor: float = TENSION_FLOOR):
        if not (np.isfinite(tension_floor) and 0 <= tension_floor < 1):
            raise InputError(f"tension_floor: expected a number in [0, 1), found {tension_floor!r}")
        self.tension_floor = float(tension_floor)
        if not (np.isfinite(feedback_damping) and feedback_damping >= 0):
            raise InputError(f"feedback_damping: expected a number >= 0, found {feedback_damping!r}")
        self.feedback_damping = float(feedback_damping)
        if tendon_law not in TENDON_LAWS:
            raise InputError(f"tendon_law: expected one of {TENDON_LAWS}, found {tendon_law!r}")
        if tendon_law == "cable" and uncertainty == "initial":
            raise InputError("tendon_law='cable': expected uncertainty 'no-MG' or 'exact' (the "
                             "'initial' model freezes F_q with the fixed rates of eq. 5.19), "
                             "found 'initial'")
        self.tendon_law = tendon_law
        if evaluation not in EVALUATION:
            raise InputError(f"evaluation: expected one of {EVALUATION}, found {evaluation!r}")
        self.evaluation = evaluation
        if uncertainty not in UNCERTAINTY:
            raise InputError(f"uncertainty: expected one of {UNCERTAINTY}, found {uncertainty!r}")
        if allocation not in ALLOCATION:
            raise InputError(f"allocation: expected one of {ALLOCATION}, found {allocation!r}")
        if not r_min > 0:
            raise InputError(f"r_min: expected > 0, found {r_min!r}")
        if not (isinstance(cond_every, (int, np.integer)) and cond_every >= 1):
            raise InputError(f"cond_every: expected an integer >= 1, found {cond_every!r}")
        self.allocation, self.r_min = allocation, float(r_min)
        if model.membrane_points is not None:
            raise InputError("adaptive PFL: expected a model in modal coordinates "
                             "(membrane_points=None), found point coordinates")
        if rbf.centers.shape[1] != 2 * model.nq:
            raise InputError(f"RBF centres: expected {2 * model.nq} columns (v_q = [q; q']), "
                             f"found {rbf.centers.shape[1]}")
        if not (gamma > 0 and alpha > 0 and beta > 0):
            raise InputError(f"expected Gamma, alpha, beta > 0, found {gamma}, {alpha}, {beta}")
        self.model, self.reference, self.gains, self.rbf = model, reference, gains, rbf
        self.w_bar, self.gamma, self.alpha, self.beta = float(w_bar), gamma, alpha, beta
        self.uncertainty = uncertainty
        nq, nz = model.nq, model.nz
        self.nq, self.nz = nq, nz
        self._F_initial = None
        if uncertainty == "initial":
            z0 = np.concatenate([reference(0.0)[0], np.zeros(model.K)]) if z_initial is None \
                else np.asarray(z_initial, dtype=float)
            M, F, B = model.matrices(z0, np.zeros(nz))
            self._F_initial = partition(M, F, B, nq=nq).F_q
        self._cache = (None, None)
        self.condition_numbers: list = []
        self.allocation_active: list = []
        self.cond_every = int(cond_every)
        self._samples = 0
        self._u_initial = model.u0 if u_initial is None else np.asarray(u_initial, dtype=float)
        self._u_previous = self._u_initial
        self.rest_length_reference = rest_length_reference
        self.dt = None

    def reset(self, t0, y0, dt):
        """W_F(0) = 0 (7.4); the controller state is vec(W_F) (m x n_q, column-major)."""
        self.dt = dt
        self.condition_numbers = []
        self.allocation_active = []
        self._samples = 0
        self._u_previous = self._u_initial
        self._cache = (None, None)
        return np.zeros(self.rbf.m * self.nq)

    def _terms(self, t, y, xc):
        key = (t, xc.tobytes(), np.asarray(y).tobytes())
        if self._cache[0] == key:
            return self._cache[1]
        nq, nz = self.nq, self.nz
        y = np.asarray(y, dtype=float)
        z, zd = y[:nz], y[nz:2 * nz]
        q, qd = z[:nq], zd[:nq]
        if self.evaluation == "reference":
            z, zd = z.copy(), zd.copy()
            z[:nq], zd[:nq] = self.reference(t)[:2]
        M, F, B = self.model.matrices(z, zd)
        try:
            if self.uncertainty == "no-MG":
                both = partition(M, np.column_stack([F, F - self.model.mg_term(z, zd)]), B, nq=nq)
                exact = PFLTerms(M_q=both.M_q, F_q=both.F_q[:, 0], B_q=both.B_q, M12=both.M12,
                                 M22=both.M22, F2=both.F2[:, 0])
                F_q = both.F_q[:, 1]
            else:
                exact = partition(M, F, B, nq=nq)
                F_q = exact.F_q if self.uncertainty == "exact" else self._F_initial
            if self._samples % self.cond_every == 0:
                self.condition_numbers.append(check_input_matrix(exact.B_q,
                                                                 where=f" at t = {t:.4g} s"))
            self._samples += 1
            return self._law(t, q, qd, xc, exact, F_q, key, z[:nq])
        except np.linalg.LinAlgError as exc:
            raise SingularInputMatrix(f"eq. 5.46 at t = {t:.4g} s: expected invertible M_q and "
                                      f"B_q, found a singular matrix ({exc})") from None

    def _law(self, t, q, qd, xc, exact, F_q, key, q_model):
        """Eq. 5.58 and the adaptation term Y of eq. 5.51 from the PFL terms (evaluated at
        the configuration ``q_model``)."""
        nq = self.nq
        q_d, qd_d, qdd_d = self.reference(t)
        e, ed = q - q_d, qd - qd_d
        d_q, k_q = self.gains(t)
        W = xc.reshape(self.rbf.m, nq, order="F")
        phi = self.rbf(np.concatenate([q, qd]))
        v_fb = d_q * ed + k_q * e
        v = -F_q - W.T @ phi - qdd_d + v_fb
        L = tendon_lengths(self.model.system, q).copy()
        # over-actuated (wide B_q): the solution closest to u_d(t), else to the previous sample's
        u_ref = self._u_previous if self.rest_length_reference is None else self.rest_length_reference(t)
        if self.rest_length_reference is not None:
            L_d = tendon_lengths(self.model.system, self.reference(t)[0])
            L = L - self.tension_floor * np.maximum(L_d - u_ref, 0.0)
        if self.tendon_law == "cable":
            terms, v, lower, upper = self._cable(exact, v, q_model, L)
            u_ref = 1.0 / u_ref
        else:
            terms, lower, upper = exact, self.r_min, L
        # the feedforward (v at e = e' = 0) inverted exactly, the feedback part damped
        u_ff = exact_inversion(terms.B_q, v - v_fb, u_ref=u_ref) if self.feedback_damping else 0.0
        v_inv = v_fb if self.feedback_damping else v
        u_ref = None if self.feedback_damping else u_ref
        if self.allocation == "bounded":
            u, active = bounded_inversion(terms, v_inv, lower=lower - u_ff, upper=upper - u_ff,
                                          damping=self.feedback_damping, u_ref=u_ref)
            if active:
                self.allocation_active.append(float(t))
        else:
            u = bounded_inversion(terms, v_inv, lower=-np.inf, upper=np.inf,
                                  damping=self.feedback_damping, u_ref=u_ref)[0]
        u = u + u_ff
        if self.tendon_law == "cable":
            u = 1.0 / u
        self._u_previous = u
        Y = -self.gamma * np.outer(phi, self.alpha * e + self.beta * ed)        # eq. 5.51
        out = (u, Y, W, e)
        self._cache = (key, out)
        return out

    def _cable(self, terms, v, q_model, L):
        """Eq. 5.46 in w = 1/u for tendons of fixed EA (module docstring): the tendon part
        -B_q (L - u) of the model's rate k = EA / u_0 becomes -B_q diag(u_0 L) w + B_q u_0,
        so B_q' = -B_q diag(u_0 L) and v' = v - B_q (L + u_0) (L at ``q_model``, where the
        terms are evaluated); the limits r_min <= u <= |tendon|(q) become 1/|tendon| <= w <=
        1/r_min. Returns (terms with B_q', v', lower, upper) of w."""
        u0 = self.model.u0
        Lm = tendon_lengths(self.model.system, q_model).copy()
        Bw = -terms.B_q * (u0 * Lm)[None, :]
        vw = v - terms.B_q @ (Lm + u0)
        return replace(terms, B_q=Bw), vw, 1.0 / L, 1.0 / self.r_min

    def output(self, t, y, xc):
        return self._terms(t, y, xc)[0]

    def update(self, t, y, xc):
        _, Y, W, _ = self._terms(t, y, xc)
        return euler_step(W, Y, dt=self.dt, bound=self.w_bar).ravel(order="F")

    def tracking_error(self, t, y) -> np.ndarray:
        """e = q - q_d at t."""
        return np.asarray(y)[: self.nq] - self.reference(t)[0]


def reference_centers(reference, *, t_end: float, m: int) -> tuple[np.ndarray, float]:
    """RBF centres on the reference: v_c,i = [q_d(t_i); q_d'(t_i)] at m times evenly spaced
    over [0, t_end], and the width sigma_q = the largest distance between consecutive
    centres (neighbouring Gaussians overlap at exp(-1/2)). Our choice: 7.4 does not print
    its centres or widths."""
    if m < 1:
        raise InputError(f"RBF: expected m >= 1 centres, found {m}")
    ts = np.linspace(0.0, t_end, m)
    C = np.array([np.concatenate(reference(t)[:2]) for t in ts])
    sig = float(np.max(np.linalg.norm(np.diff(C, axis=0), axis=1))) if m > 1 else 1.0
    return C, max(sig, 1e-3)
