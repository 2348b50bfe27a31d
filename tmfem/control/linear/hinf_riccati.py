"""The eliminated H-infinity LMIs solved through their Riccati equivalents (regular plants).

For a *regular* plant (D12 full column rank, D21 full row rank) the projection-lemma LMIs of
:mod:`tmfem.control.linear.hinf_lmi` (eq. 5.65 with the controller variables eliminated) have an exact
Riccati characterisation (Gahinet & Apkarian, Int. J. Robust Nonlinear Control 4 (1994)
421-448, sec. 5; Green & Limebeer, Linear Robust Control, 1995, ch. 6 and 8):

* the R-LMI (null space of [B2^T, D12^T]) is the full-information H-infinity condition. It
  is feasible iff ``gamma^2 I > D11^T Pi D11`` (Pi the projection onto ker D12^T) and the
  game Riccati equation

      A^T X + X A + C1^T C1 - (X B + C1^T D) Rm^-1 (B^T X + D^T C1) = 0,
      B = [B1 B2],  D = [D11 D12],  Rm = D^T D - diag(gamma^2 I, 0)

  has a stabilising solution X >= 0; R = gamma X^-1 lies on the boundary of the LMI (the
  bounded real lemma in the gamma-normalised form of eq. 5.64 is the gamma^2 form scaled by
  gamma);
* the S-LMI (null space of [C2, D21]) is the R-LMI of the dual plant (A^T, C1^T, C2^T, B1^T,
  D11^T, D21^T), so S = gamma Y^-1 with Y the dual game solution;
* [[R, I], [I, S]] > 0 is then rho(X Y) < gamma^2.

The test at one gamma (:func:`riccati_test`) has three outcomes: "feasible", "infeasible"
with a certificate (gamma at or below the feedthrough bound, a stabilising solution that is
indefinite, rho(XY) >= gamma^2, a Hamiltonian eigenvalue on the imaginary axis) or
"unknown" (no Riccati solver found a stabilising solution, and no certificate either: a
numerical failure, never read as infeasibility). Each Riccati equation is solved by scipy
and, if that fails, by SLICOT SG02AD, and a solution counts only if its closed-loop matrix is
Hurwitz. The bisection (:func:`bisect_verified`) moves its upper end only where a
controller built at that level has a verified closed loop, and its certified lower end
only on a certificate.

So the LMI optimum gamma is found by bisection on these tests (two Riccati equations of
order n per step, against an SDP whose interior-point iterations cost O(n^6) for a dense
Schur complement), and a strictly feasible LMI point for a gamma above the optimum comes from
the Riccati equations with C1^T C1 replaced by C1^T C1 + eps I (a strict Riccati inequality:
the LMI holds with margin). The LMIs are evaluated in floating point afterwards
(:func:`tmfem.control.linear.hinf_lmi.hinf_lmi` checks the residuals and recovers the controller by
eq. 5.67), so the certificate does not rest on this equivalence.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from tmfem.control.linear.lmi import projection_solution
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


def _projector_off(D: np.ndarray) -> np.ndarray:
    """Pi = I - D D^+ (projection onto ker D^T)."""
    if D.shape[1] == 0:
        return np.eye(D.shape[0])
    Q = sla.orth(D)
    return np.eye(D.shape[0]) - Q @ Q.T


def gamma_lower_bound(P) -> float:
    """The inertia bound of the game Riccati equations: gamma > max(||Pi_12 D11||,
    ||D11 Pi_21||) with Pi_12 onto ker D12^T, Pi_21 onto ker D21 (no controller reaches
    below it: the feedthrough w -> p outside the reach of u and y)."""
    a = np.linalg.norm(_projector_off(P.D12) @ P.D11, 2) if P.D11.size else 0.0
    b = np.linalg.norm(P.D11 @ _projector_off(P.D21.T), 2) if P.D11.size else 0.0
    return float(max(a, b))


def hamiltonian_schur_care(A, B, Q, Rm, S) -> np.ndarray:
    """The stabilising solution of A^T X + X A + Q - (X B + S) Rm^-1 (B^T X + S^T) = 0 by the
    ordered real Schur form of the Hamiltonian matrix (Laub 1979), Rm invertible:

        H = [[A_s, -B Rm^-1 B^T], [-(Q - S Rm^-1 S^T), -A_s^T]],   A_s = A - B Rm^-1 S^T,

    with the n eigenvalues in the left half plane first, H [U1; U2] = [U1; U2] T11, and
    X = U2 U1^-1. A matrix rather than a pencil: no QZ reordering, which fails where the
    pencil is too far from generalized Schur form (lightly damped plants of ~100 states).

    Raises
    ------
    numpy.linalg.LinAlgError
        Not n stable eigenvalues (an eigenvalue on the imaginary axis), or U1 singular."""
    n = A.shape[0]
    Ri_BT = np.linalg.solve(Rm, B.T)
    Ri_ST = np.linalg.solve(Rm, S.T)
    As = A - B @ Ri_ST
    H = np.block([[As, -B @ Ri_BT], [-(Q - S @ Ri_ST), -As.T]])
    _, Z, sdim = sla.schur(H, sort="lhp")
    if sdim != n:
        raise np.linalg.LinAlgError(f"{sdim} of {2 * n} Hamiltonian eigenvalues in the open left half plane, "
                                    f"expected {n}")
    return np.linalg.solve(Z[:n, :n].T, Z[n:, :n].T).T


def _stabilizing_care(A, B, Q, Rm, S) -> tuple:
    """(X, None) with X the stabilising solution of A^T X + X A + Q - (X B + S) Rm^-1
    (B^T X + S^T) = 0, or (None, reason). Three independent solvers are tried: scipy's
    (extended Hamiltonian pencil, QZ with the left half plane first; balanced, then
    unbalanced), SLICOT SG02AD (python-control ``care``), which does not share scipy's
    symmetry test that rejects defective (repeated) eigenvalues, and the ordered Schur form
    of the Hamiltonian matrix (:func:`hamiltonian_schur_care`, no pencil reordering). A result
    is accepted only if it is finite and A - B Rm^-1 (B^T X + S^T) is Hurwitz (scipy does not
    check that the ordered pencil has n stable eigenvalues, so a non-stabilising X can come
    back)."""
    import control
    reasons = []

    def solvers():
        for balanced in (True, False):
            yield (f"scipy (balanced={balanced})",
                   lambda b=balanced: sla.solve_continuous_are(A, B, Q, Rm, s=S, balanced=b))
        yield "SLICOT SG02AD", lambda: np.asarray(control.care(A, B, Q, Rm, S, np.eye(A.shape[0]))[0])
        yield "Hamiltonian Schur", lambda: hamiltonian_schur_care(A, B, Q, Rm, S)

    for name, fn in solvers():
        try:
            X = fn()
        except Exception as exc:     # LinAlgError, ValueError, slycot's own error types
            reasons.append(f"{name}: {exc}")
            continue
        X = (X + X.T) / 2
        if not np.all(np.isfinite(X)):
            reasons.append(f"{name}: non-finite solution")
            continue
        F = np.linalg.solve(Rm, B.T @ X + S.T)
        re = float(np.max(np.linalg.eigvals(A - B @ F).real))
        if re < 0:
            return X, None
        reasons.append(f"{name}: solution not stabilising (closed-loop eigenvalue with Re = {re:.3g})")
    return None, "; ".join(r.splitlines()[0][:160] for r in reasons)


def _axis_eigenvalue(A, B, Q, Rm, S) -> float | None:
    """Frequency (rad/s) of an eigenvalue of the Riccati equation's Hamiltonian pencil that
    lies on the imaginary axis (|Re| <= 1e-10 ||H||, |Im| >= 1e-6 ||H||: a genuine crossing,
    not a pole near the origin), or None."""
    n, m = A.shape[0], B.shape[1]
    H = np.block([[A, np.zeros((n, n)), B], [-Q, -A.T, -S], [S.T, B.T, Rm]])
    J = np.zeros_like(H)
    J[: 2 * n, : 2 * n] = np.eye(2 * n)
    q, _ = np.linalg.qr(H[:, -m:], mode="complete")
    Hd = q[:, m:].T @ H[:, : 2 * n]
    Jd = q[:2 * n, m:].T @ J[: 2 * n, : 2 * n]
    lam = sla.eigvals(Hd, Jd)
    lam = lam[np.isfinite(lam)]
    nh = max(np.linalg.norm(H, 1), 1e-300)
    on = lam[(np.abs(lam.real) <= 1e-10 * nh) & (np.abs(lam.imag) >= 1e-6 * nh)]
    return float(np.abs(on[0].imag)) if on.size else None


def game_riccati_verdict(A, B1, B2, C1, D11, D12, gamma: float, *, eps: float = 0.0) -> tuple:
    """The full-information game Riccati equation of the module docstring (with C1^T C1 +
    eps I) at ``gamma``: (X, status, reason) with status "feasible" (stabilising X >= 0),
    "infeasible" (a certificate: the stabilising solution is indefinite, or the
    Hamiltonian has an eigenvalue on the imaginary axis) or "unknown" (numerical failure)."""
    n, nw = A.shape[0], B1.shape[1]
    B = np.hstack([B1, B2])
    D = np.hstack([D11, D12])
    Rm = D.T @ D
    Rm[:nw, :nw] -= gamma ** 2 * np.eye(nw)
    Q = C1.T @ C1 + eps * np.eye(n)
    S = C1.T @ D
    X, reason = _stabilizing_care(A, B, Q, Rm, S)
    if X is None:
        w = _axis_eigenvalue(A, B, Q, Rm, S)
        if w is not None:
            return None, "infeasible", f"Hamiltonian eigenvalue on the imaginary axis at {w:.4g} rad/s"
        return None, "unknown", reason
    ev = np.linalg.eigvalsh(X)
    if ev[0] < -1e-8 * max(1.0, abs(ev[-1])):
        return None, "infeasible", f"stabilising solution indefinite (eigenvalue {ev[0]:.3g})"
    return X, "feasible", ""


def game_riccati(A, B1, B2, C1, D11, D12, gamma: float, *, eps: float = 0.0):
    """Stabilising solution X >= 0 of the full-information game Riccati equation (module
    docstring) with C1^T C1 + eps I, or None (:func:`game_riccati_verdict` says why)."""
    return game_riccati_verdict(A, B1, B2, C1, D11, D12, gamma, eps=eps)[0]


@dataclass
class Verdict:
    """Outcome of the Riccati test at one gamma: ``status`` "feasible", "infeasible" (with a
    certificate named in ``reason``) or "unknown" (numerical failure, named in ``reason``)."""

    status: str
    reason: str = ""
    X: np.ndarray | None = None
    Y: np.ndarray | None = None


def riccati_test(P, alpha: float, gamma: float, *, eps: float = 0.0) -> Verdict:
    """The three Riccati conditions of the module docstring for the plant shifted by alpha_1:
    gamma above the feedthrough bound, stabilising X >= 0 and Y >= 0, rho(X Y) < gamma^2."""
    n = P.A.shape[0]
    Aa = P.A + alpha * np.eye(n)
    lb = gamma_lower_bound(P)
    if gamma <= lb:
        return Verdict("infeasible", f"gamma <= max(||Pi_12 D11||, ||D11 Pi_21||) = {lb:.6g}")
    X, st, why = game_riccati_verdict(Aa, P.B1, P.B2, P.C1, P.D11, P.D12, gamma, eps=eps)
    if X is None:
        return Verdict(st, f"X: {why}")
    Y, st, why = game_riccati_verdict(Aa.T, P.C1.T, P.C2.T, P.B1.T, P.D11.T, P.D21.T, gamma, eps=eps)
    if Y is None:
        return Verdict(st, f"Y: {why}")
    rho = float(np.max(np.abs(np.linalg.eigvals(X @ Y))))
    if rho >= gamma ** 2 * (1 + 1e-8):
        return Verdict("infeasible", f"coupling rho(X Y) = {rho:.6g} >= gamma^2 = {gamma ** 2:.6g}", X, Y)
    if rho >= gamma ** 2:
        return Verdict("unknown", f"coupling rho(X Y) = {rho:.8g} at gamma^2 = {gamma ** 2:.8g}", X, Y)
    return Verdict("feasible", "", X, Y)


def check_regular(P, *, alpha: float = 0.0) -> None:
    """Refuse a plant outside the Riccati characterisation: D12 of full column rank, D21 of
    full row rank (relative to their largest singular value, 1e-9), and no invariant zeros
    of (A + alpha_1 I, B2, C1, D12) or (A + alpha_1 I, B1, C2, D21) on the imaginary axis
    (the rank conditions of Doyle, Glover, Khargonekar & Francis 1989, for the shifted
    plant).

    Raises
    ------
    InputError
        naming the failed condition (such plants go to the LMI route).
    """
    nu, ny = P.B2.shape[1], P.C2.shape[0]
    r12, r21 = numerical_rank(P.D12), numerical_rank(P.D21)
    if r12 < nu or r21 < ny:
        raise InputError(f"Riccati route: expected a regular plant (D12 full column rank {nu}, "
                         f"D21 full row rank {ny}), found ranks {r12} and {r21}: use the LMI "
                         "route (method='lmi')")
    Aa = P.A + alpha * np.eye(P.A.shape[0])
    for name, (B, C, D) in (("(A, B2, C1, D12)", (P.B2, P.C1, P.D12)),
                            ("(A, B1, C2, D21)", (P.B1, P.C2, P.D21))):
        z = invariant_zeros(Aa, B, C, D)
        z = z[np.isfinite(z)]
        scale = max(1.0, float(np.linalg.norm(P.A, 1)))
        on = z[np.abs(z.real) <= 1e-9 * scale]
        if on.size:
            raise InputError(f"Riccati route: expected no invariant zero of {name} on the "
                             f"imaginary axis, found one at {on[0]:.4g}: use the LMI route "
                             "(method='lmi')")


def invariant_zeros(A, B, C, D) -> np.ndarray:
    """Invariant zeros of (A, B, C, D): the finite s where the Rosenbrock pencil
    [[A - s I, B], [C, D]] loses rank, by SLICOT AB08ND (the reduction python-control's
    ``zeros`` uses) and the generalized eigenvalues of its reduced pencil. The workspace is
    at least SLICOT's documented minimum, max(1, min(p, m) + max(3 m - 1, n), min(p, n) +
    max(3 p - 1, n + p, n + m)), and slycot's default, n + 3 max(m, p), which the wrapper also
    requires but which is below that minimum when n < min(p, m) - 1."""
    import scipy.linalg as sla
    from slycot import ab08nd
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    if n == 0:
        return np.zeros(0, dtype=complex)
    ldwork = max(1, min(p, m) + max(3 * m - 1, n), min(p, n) + max(3 * p - 1, n + p, n + m),
                 n + 3 * max(m, p))
    out = ab08nd(n, m, p, A, B, C, D, ldwork=ldwork)
    nu = out[0]
    if nu == 0:
        return np.zeros(0, dtype=complex)
    return sla.eigvals(out[8][:nu, :nu], out[9][:nu, :nu]).astype(complex)


def numerical_rank(D: np.ndarray, rtol: float = 1e-9) -> int:
    """Number of singular values of D above ``rtol`` times the largest (the rank test of
    :func:`check_regular`)."""
    if D.size == 0:
        return 0
    s = np.linalg.svd(D, compute_uv=False)
    return int(np.sum(s > rtol * max(s[0], 1e-300)))


@dataclass
class GammaIteration:
    """Result of :func:`minimize_gamma`: ``gamma`` is the smallest level with verified
    evidence (``evidence``, what ``certify`` returned there); ``lower`` the largest level
    certified infeasible; ``unknown`` the levels where the test failed numerically, with
    the reasons (the bisection treated them as infeasible, but they certify nothing)."""

    gamma: float
    lower: float
    evidence: object
    steps: int
    time_s: float
    unknown: list = field(default_factory=list)


def minimize_gamma(P, *, alpha: float, certify, rtol: float = 1e-6,
                   gamma_max: float = 1e8) -> GammaIteration:
    """Smallest gamma of the eliminated LMIs (:func:`riccati_test` of the plant shifted by
    alpha_1) by :func:`bisect_verified` with ``certify``.

    Raises
    ------
    InputError
        A plant outside the Riccati characterisation (:func:`check_regular`).
    InfeasibleController
        No verified level up to ``gamma_max``, with the last reason.
    """
    check_regular(P, alpha=alpha)
    return bisect_verified(lambda g: riccati_test(P, alpha, g), certify,
                           lower=gamma_lower_bound(P), rtol=rtol, gamma_max=gamma_max,
                           what=f"Riccati test, alpha_1 = {alpha:g}")


def bisect_verified(test, certify, *, lower: float, rtol: float, gamma_max: float,
                    what: str) -> GammaIteration:
    """Bisection on gamma that moves only on verified evidence: the upper end moves to gamma
    only when ``test(gamma)`` (a :class:`Verdict`) is feasible there *and*
    ``certify(gamma)`` returns ``(True, evidence, "")`` (a controller whose closed loop was
    checked); the certified lower end moves on an infeasibility certificate; a numerical
    failure ("unknown", or a feasible test whose controller fails its check) moves the
    search bracket but not the certified bound. ``lower`` is a level known infeasible (or
    0). Stops when the bracket is below ``rtol`` relative.

    Raises
    ------
    InfeasibleController
        No verified level up to ``gamma_max``, with the last reason.
    """
    t0 = time.perf_counter()
    lo = lower
    steps, unknown = 0, []

    def attempt(g):
        v = test(g)
        if v.status != "feasible":
            return v.status, None, v.reason
        ok, evidence, why = certify(g)
        return ("verified", evidence, "") if ok else ("unknown", None, f"test feasible, {why}")

    hi = max(2.0 * lo, 1e-3)
    if lo > 0:
        # the optimum is often the known lower bound itself (a feedthrough sets gamma): one
        # verified step at lower (1 + rtol) settles it
        steps += 1
        st, ev, why = attempt(lo * (1 + rtol))
        if st == "verified":
            dt = time.perf_counter() - t0
            log.info("verified gamma iteration (%s): gamma = %.8g = the lower bound (1 + %g), "
                     "%.2f s", what, lo * (1 + rtol), rtol, dt)
            return GammaIteration(gamma=float(lo * (1 + rtol)), lower=float(lower), evidence=ev,
                                  steps=steps, time_s=dt, unknown=[])
    while True:
        steps += 1
        st, ev, why = attempt(hi)
        if st == "verified":
            break
        if st == "infeasible":
            lower = hi
        else:
            unknown.append((hi, why))
        lo, hi = hi, 4.0 * hi
        if hi > gamma_max:
            raise InfeasibleController(f"H-infinity gamma iteration ({what}): expected a verified "
                                       f"level gamma <= {gamma_max:g}, found none (last: {why})")
    evidence = ev
    while hi - lo > rtol * hi:
        mid = np.sqrt(lo * hi) if lo > 0 else hi / 2
        steps += 1
        st, ev, why = attempt(mid)
        if st == "verified":
            hi, evidence = mid, ev
        else:
            lo = mid
            if st == "infeasible":
                lower = mid
            else:
                unknown.append((mid, why))
    dt = time.perf_counter() - t0
    log.info("verified gamma iteration (%s): gamma = %.8g, certified lower bound %.8g, %d steps "
             "(%d unknown), %.2f s", what, hi, lower, steps, len(unknown), dt)
    return GammaIteration(gamma=float(hi), lower=float(lower), evidence=evidence, steps=steps,
                          time_s=dt, unknown=unknown)


def state_feedback_verdict(A, B1, B2, C1, D11, D12, gamma: float, *, eps: float = 0.0) -> Verdict:
    """Riccati test of static state feedback at ``gamma``: gamma > ||D11|| (the feedthrough
    no gain changes) and a stabilising solution X >= 0 of the game Riccati equation."""
    d = float(np.linalg.norm(D11, 2)) if D11.size else 0.0
    if gamma <= d:
        return Verdict("infeasible", f"gamma <= ||D11|| = {d:.6g}")
    X, st, why = game_riccati_verdict(A, B1, B2, C1, D11, D12, gamma, eps=eps)
    return Verdict(st, why, X)


def strict_point(P, *, alpha: float, gamma: float, eps_rel: float = 1e-6):
    """(R, S) strictly satisfying the eliminated LMIs at ``gamma`` (above the optimum):
    R = gamma X_eps^-1, S = gamma Y_eps^-1 from the Riccati equations with C1^T C1 + eps I,
    eps = ``eps_rel`` x ||C1^T C1|| (and the dual likewise).

    Raises
    ------
    InfeasibleController
        When the perturbed Riccati equations have no admissible solution or rho(X Y) >=
        gamma^2 (gamma too close to the optimum for this eps).
    """
    check_regular(P, alpha=alpha)
    scale = max(np.linalg.norm(P.C1, 2) ** 2, np.linalg.norm(P.B1, 2) ** 2, 1e-12)
    v = riccati_test(P, alpha, gamma, eps=eps_rel * scale)
    if v.status != "feasible":
        raise InfeasibleController(f"eliminated LMIs (Riccati) at gamma = {gamma:.6g}: expected "
                                   f"stabilising X, Y >= 0 with rho(X Y) < gamma^2, found "
                                   f"{v.status}: {v.reason}")
    X, Y = v.X, v.Y
    rho = float(np.max(np.abs(np.linalg.eigvals(X @ Y))))
    R = gamma * np.linalg.inv(X)
    S = gamma * np.linalg.inv(Y)
    return (R + R.T) / 2, (S + S.T) / 2, rho


def state_feedback_gamma(A, B1, B2, C1, D11, D12, *, eps: float = 1e-8, rtol: float = 1e-6,
                         gamma_max: float = 1e8) -> float:
    """Optimal level of static state feedback u = K x (the state-feedback LMI of
    :func:`tmfem.control.linear.hinf_lmi.hinf_state_feedback`), by bisection on its Riccati test:
    gamma > ||D11|| (the w -> p feedthrough no static gain changes) and the game Riccati
    equation of the module docstring (with C1^T C1 + eps I: modes on the imaginary axis
    that p does not see, such as integrators of a tracking error outside p, leave the
    unperturbed Hamiltonian without a stabilising solution; gamma(eps) decreases to the
    optimum as eps -> 0).

    Raises
    ------
    InfeasibleController
        No gamma up to ``gamma_max`` (not stabilisable).
    """
    if np.linalg.matrix_rank(D12) < D12.shape[1]:
        raise InputError(f"state-feedback Riccati test: expected D12 of full column rank "
                         f"{D12.shape[1]}, found rank {np.linalg.matrix_rank(D12)}")

    def ok(g):
        return state_feedback_verdict(A, B1, B2, C1, D11, D12, g, eps=eps).status == "feasible"

    lo = float(np.linalg.norm(D11, 2)) if D11.size else 0.0
    hi = max(2.0 * lo, 1e-3)
    while not ok(hi):
        lo, hi = hi, 4.0 * hi
        if hi > gamma_max:
            raise InfeasibleController(f"state-feedback Riccati test: expected a feasible gamma <= "
                                       f"{gamma_max:g}, found none (not stabilisable)")
    while hi - lo > rtol * hi:
        mid = np.sqrt(lo * hi) if lo > 0 else hi / 2
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return float(hi)


def state_feedback_gain(A, B1, B2, C1, D11, D12, gamma: float, *, eps: float = 1e-8) -> np.ndarray:
    """A static gain K (u = K x) meeting the state-feedback LMI at ``gamma`` (above the
    optimum): Y = gamma X^-1 from the game Riccati equation, W from the projection formula
    of :func:`tmfem.control.linear.lmi.projection_solution` applied to the LMI in W, K = W Y^-1.

    Raises
    ------
    InfeasibleController
        When the Riccati equation has no admissible solution or the LMI in W fails.
    """
    n, nw, npp = A.shape[0], B1.shape[1], C1.shape[0]
    X = game_riccati(A, B1, B2, C1, D11, D12, gamma, eps=eps)
    if X is None:
        raise InfeasibleController(f"state-feedback Riccati test: expected a stabilising solution at "
                                   f"gamma = {gamma:.6g}, found none")
    Y = gamma * np.linalg.inv(X)
    Y = (Y + Y.T) / 2
    Psi = np.block([[A @ Y + Y @ A.T, B1, Y @ C1.T], [B1.T, -gamma * np.eye(nw), D11.T],
                    [C1 @ Y, D11, -gamma * np.eye(npp)]])
    G = np.vstack([B2, np.zeros((nw, B2.shape[1])), D12])
    L = np.hstack([np.eye(n), np.zeros((n, nw + npp))])
    W, lam = projection_solution(Psi, G, L)
    if W is None or not lam < 0:
        raise InfeasibleController(f"state-feedback LMI at gamma = {gamma:.6g}: expected a gain, found "
                                   f"largest eigenvalue {lam:.3g}")
    return np.linalg.solve(Y, W.T).T
