"""Rate-bounded certificate of the output-feedback LPV loop (:mod:`tmfem.control.lpv.output_feedback`):
an analysis LMI with a parameter-dependent Lyapunov matrix (docs/guides/lpv.md).

The loop of plant, integrators and gridded estimator (states x = [x_z, xi, e], w = [q_d, n_d, n],
p = [W_e e_q, W_u u]; :meth:`~tmfem.control.lpv.output_feedback.LPVOutputFeedback.frozen_closed_loop`)

    x' = A(rho) x + B(rho) w,    p = C(rho) x + D(rho) w

is stable with ||p||_2 < gamma ||w||_2 for every parameter trajectory in the grid's box with
rates in the rate box when there is X(rho) = X_0 + sum_k rho_k X_k > 0 (normalised rho, the
span of eq. 5.99) with, at every rate vertex,

    [[A X + X A^T - dX/dt, B, X C^T], [B^T, -gamma I, D^T], [C X, D, -gamma I]] < 0

(eq. 5.95 of the state feedback with the loop in place of A + B2 K: the bounded real lemma
with V = x^T X(rho)^-1 x, dV/dt + |p|^2 / gamma - gamma |w|^2 < 0 after the congruence with
X^-1). Gridded: imposed at the grid points and re-checked on a finer grid, as the state-feedback
LMI of 8.3; solved by the EIGOPT bisection of :mod:`tmfem.control.lpv.bisect` on the loop as a
generalised plant without control input. Its proven lower bound is the largest frozen-loop
H-infinity norm of the design grid (a constant rho is an admissible trajectory).

Start (the separation structure): at a design point the estimation error eps = x_z - e obeys
eps' = (A - L C_m) eps + W_d B n_d - W_n L n, and [x_z, xi] the state-feedback loop driven by
-B K_x eps. With the state feedback's own P(rho) (eqs. 5.95-5.99) and a rate-bounded Z(rho) of
the error system (:func:`estimator_error_lpv`: the same LMI, output eps, one EIGOPT level at 4 x
its largest frozen norm), X = M diag(P, beta Z) M^T (M: eps -> e = x_z - eps) meets the LMI for
beta in a range where beta Z absorbs the noise into eps and the coupling -B K_x beta Z stays
below the state feedback's margin; beta is the best of a logarithmic sweep on the design grid.
Generic starts fail at the 2-3 size (121 states): the pointwise Riccati fit (largest scaled
eigenvalue +0.98 after 587 evaluations) and a Z fitted to the pointwise Lyapunov solutions of
A - L C_m (indefinite at 3 of the 18 points: the error dynamics' Lyapunov matrices rotate with
theta as the plant's do); docs/guides/lpv.md.

Not covered: the estimator's state is the absolute x^ and the law reads x^ - x_e(rho), so a
moving rho adds dx_e/dt terms that this (as every linearised LPV analysis) leaves out; the
sampled loops are checked frozen only (:func:`~tmfem.control.lpv.output_feedback.verify_output_feedback`).
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg as sla

from tmfem.control.lpv.bisect import bisect_gamma
from tmfem.control.lpv.coordinates import Coordinates, Tm_back, design_points_in
from tmfem.control.lpv.generalized_plant import GeneralizedLPV, lmi_matrix
from tmfem.control.lpv.plant import GriddedLPV, grid_point_text
from tmfem.control.lpv.refinement import next_cut, resolve_on_points
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.control.lpv.verify import verify
from tmfem.errors import InfeasibleController, InputError

log = logging.getLogger(__name__)


def closed_loop_lpv(design, plant: GriddedLPV, *, W_e: float, W_u: float) -> GeneralizedLPV:
    """The frozen closed loops of ``design`` with the plants of ``plant``'s grid (its A, B and
    measured C_m; the controller interpolated there) as a generalised plant without control
    input: its eq. 5.95 is the analysis LMI of the module docstring."""
    C, _ = plant.measurement(design.measured)
    loops = [design.frozen_closed_loop(plant.A[idx], plant.B[idx], C[idx], rho, W_e=W_e, W_u=W_u)
             for idx, rho in plant.points()]
    shp = plant.grid_shape
    A, B1, C1, D11 = (np.array([lp[k] for lp in loops]).reshape(shp + loops[0][k].shape) for k in range(4))
    n = A.shape[-1]
    gp = GeneralizedLPV.from_matrices(axes=plant.axes, parameter_names=plant.parameter_names,
                                      rate_bounds=plant.rate_bounds, A=A, B1=B1, B2=np.zeros(shp + (n, 0)), C1=C1,
                                      D11=D11, D12=np.zeros(shp + (C1.shape[-2], 0)))
    gp.state_names = (list(plant.state_names) + [f"int_e_{design.measured[i]}" for i in design.tracked_rows]
                      + [f"est_{s}" for s in plant.state_names])
    return gp


def estimator_error_lpv(design, plant: GriddedLPV) -> GeneralizedLPV:
    """The estimation error of ``design`` on the grid of ``plant`` as a generalised plant
    without control input: eps' = (A - L C_m) eps + [W_d B, -W_n L] [n_d; n], p = eps
    (module docstring). The gains L are the estimator's at ``plant``'s points: its own grid
    may be finer (it must contain them, as the separation start assumes its model exact
    there)."""
    for a, e, name in zip(plant.axes, design.estimator.axes, plant.parameter_names):
        if not np.all(np.min(np.abs(a[:, None] - e[None, :]), axis=1) <= 1e-12 * max(1.0, np.abs(e).max())):
            raise InputError(f"rate-bounded certificate: expected the estimator's grid to contain the design "
                             f"points, found {name} values {a.tolist()} against the estimator's {e.tolist()}")
    C, _ = plant.measurement(design.measured)
    shp, n = plant.grid_shape, plant.nx
    L = np.array([design.model(rho)[3] for _, rho in plant.points()]).reshape(shp + (n, C.shape[-2]))
    B1 = np.concatenate([design.W_d * plant.B, -design.W_n * L], -1)
    gp = GeneralizedLPV.from_matrices(axes=plant.axes, parameter_names=plant.parameter_names,
                                      rate_bounds=plant.rate_bounds, A=plant.A - L @ C, B1=B1,
                                      B2=np.zeros(shp + (n, 0)), C1=np.broadcast_to(np.eye(n), shp + (n, n)),
                                      D11=np.zeros(shp + (n, B1.shape[-1])), D12=np.zeros(shp + (n, 0)))
    gp.state_names = [f"eps_{s}" for s in plant.state_names]
    return gp


def _frozen_norms(gp: GeneralizedLPV):
    """The largest frozen H-infinity norm over the grid of a generalised plant without input
    (python-control ``norm``) and where; refuses an unstable frozen system."""
    import control
    lo, lo_at = -np.inf, None
    for idx in np.ndindex(*gp.grid_shape):
        rho = [float(a[i]) for a, i in zip(gp.axes, idx)]
        if np.linalg.eigvals(gp.A[idx]).real.max() >= 0:
            raise InfeasibleController(f"rate-bounded certificate: the frozen loop at "
                                       f"{grid_point_text(gp.parameter_names, rho)} is unstable "
                                       "(expected stable at every design point)")
        nrm = float(control.norm(control.ss(gp.A[idx], gp.B1[idx], gp.C1[idx], gp.D11[idx]), p="inf"))
        if nrm > lo:
            lo, lo_at = nrm, rho
    return lo, lo_at


def separation_start(design, plant: GriddedLPV, gp: GeneralizedLPV, gamma: float, *, time_budget: float,
                     betas=np.logspace(-4, 6, 11)):
    """X(rho) = M diag(P(rho), beta Z(rho)) M^T of the module docstring (an LPVStateFeedback
    with no gain, coefficients in the state feedback's normalised parameters), beta the one of
    ``betas`` with the smallest largest relative LMI eigenvalue on the grid of ``gp`` at
    ``gamma``; and (gamma of Z, beta, that eigenvalue).

    Raises
    ------
    InfeasibleController
        No rate-bounded Z of the error system within ``time_budget``.
    """
    sf = design.state_feedback
    n, nq = design.nx, design.tracked_rows.size
    err = estimator_error_lpv(design, plant)
    lo, _ = _frozen_norms(err)
    Z, _ = bisect_gamma(err, lower=lo, upper=4 * lo, rtol=0.75, time_budget=time_budget)   # one level
    M = np.zeros((2 * n + nq, 2 * n + nq))
    M[:n + nq, :n + nq] = np.eye(n + nq)
    M[n + nq:, :n] = np.eye(n)
    M[n + nq:, n + nq:] = -np.eye(n)
    c0 = np.asarray(sf.center, dtype=float)
    steps = [c0 + np.eye(c0.size)[k] * sf.half_width[k] for k in sf.varying]
    Zs = [Z.P_of(c0)] + [Z.P_of(r) - Z.P_of(c0) for r in steps]       # Z(rho) in the basis of P(rho)
    best = None
    for beta in betas:
        Xk = [M @ sla.block_diag(Pk, beta * Zk) @ M.T for Pk, Zk in zip(sf.P, Zs)]
        X = LPVStateFeedback(gamma=gamma, P=Xk, Q=[np.zeros((0, 2 * n + nq))] * len(Xk), center=sf.center,
                             half_width=sf.half_width, varying=sf.varying, axes=sf.axes,
                             parameter_names=sf.parameter_names, rate_bounds=sf.rate_bounds,
                             state_names=list(gp.state_names), solver="separation", status=f"beta = {beta:.1e}",
                             solve_time=0.0, build_time=0.0, sizes={}, max_lmi_eig=np.nan, min_P_eig=np.nan)
        e = verify(X, gp, allow_failure=True).max_lmi_eig
        log.info("rate-bounded certificate: separation start beta = %.1e, largest relative LMI eigenvalue %.3e",
                 beta, e)
        if best is None or e < best[0]:
            best = (e, X, beta)
    return best[1], {"estimator_error_gamma": Z.gamma, "beta": float(best[2]), "start_max_eig": float(best[0])}


@dataclass
class RateBoundedCertificate:
    """Result of :func:`rate_bounded_certificate`. ``lyapunov``: X(rho) as the P(rho) of an
    :class:`~tmfem.control.lpv.synthesis.LPVStateFeedback` (no gain: Q has no rows), None when
    no level was found; ``gamma``: its certified L2-gain bound; ``lower_bound``: the largest
    frozen-loop norm of the design grid (proven: no certificate below it); ``bracket``: the
    :class:`~tmfem.control.lpv.bisect.GammaBracket`, or None; ``message``: why none was found;
    ``start``: the separation start's gamma of Z, beta and largest relative LMI eigenvalue;
    ``refinement``: the rounds of :func:`refine_certificate` (empty without it)."""

    lyapunov: LPVStateFeedback | None
    gamma: float | None
    lower_bound: float
    lower_bound_at: list
    bracket: object
    time_s: float
    message: str = ""
    start: dict = field(default_factory=dict)
    refinement: dict = field(default_factory=dict)

    @property
    def found(self) -> bool:
        return self.lyapunov is not None

    def to_dict(self) -> dict:
        d = {"rate_bounded_certificate": self.found, "rate_bounded_gamma": self.gamma,
             "rate_bounded_frozen_norm_max": self.lower_bound, "rate_bounded_frozen_norm_max_at": self.lower_bound_at,
             "rate_bounded_time_s": self.time_s, "rate_bounded_message": self.message,
             **{f"rate_bounded_start_{k}": v for k, v in self.start.items()}}
        if self.bracket is not None:
            d["rate_bounded_levels"] = self.bracket.levels
        d.update({f"rate_bounded_refinement_{k}": v for k, v in self.refinement.items()})
        return d


def rate_bounded_certificate(design, plant: GriddedLPV, *, W_e: float, W_u: float, upper: float | None = None,
                             rtol: float = 0.05, time_budget: float = 300.0, max_iter: int = 150,
                             progress=None) -> RateBoundedCertificate:
    """X(rho) and the lowest gamma found for the analysis LMI of the module docstring on the
    design grid of ``plant`` (the plants ``design`` was made for), by the EIGOPT bisection
    between the largest frozen norm and ``upper`` (default 2 x the larger of it and the state
    feedback's gamma: the separation start holds P(rho) of that level), from
    :func:`separation_start` at ``upper``.

    Returns a certificate with ``found`` False (and the reason) when no point is found at the
    upper level within the budget: that proves nothing either way (EIGOPT is local).

    Raises
    ------
    InfeasibleController
        When a frozen loop of the design grid is unstable (no certificate can exist).
    """
    if upper is not None and not (np.isfinite(upper) and upper > 0):
        raise InputError(f"rate-bounded certificate: expected an upper level > 0, found {upper!r}")
    t0 = time.perf_counter()
    gp = closed_loop_lpv(design, plant, W_e=W_e, W_u=W_u)
    lo, lo_at = _frozen_norms(gp)
    hi = 2.0 * max(lo, design.state_feedback.gamma) if upper is None else upper
    if not hi > lo:
        raise InputError(f"rate-bounded certificate: expected an upper level above the largest frozen norm "
                         f"{lo:.6g} (no certificate below it), found {hi!r}")
    log.info("rate-bounded certificate: %d-state loops on %s, frozen norms up to %.6g at %s; levels (%.6g, %.6g]",
             gp.A.shape[-1], gp.grid_shape, lo, grid_point_text(gp.parameter_names, lo_at), lo, hi)
    info = {}
    try:
        start, info = separation_start(design, plant, gp, hi, time_budget=time_budget / 3)
        left = max(time_budget - (time.perf_counter() - t0), 1e-9)
        X, br = bisect_gamma(gp, lower=lo, upper=hi, rtol=rtol, time_budget=left, max_iter=max_iter, start=start,
                             progress=progress)
    except InfeasibleController as exc:
        return RateBoundedCertificate(lyapunov=None, gamma=None, lower_bound=lo, lower_bound_at=lo_at,
                                      bracket=None, time_s=time.perf_counter() - t0, message=str(exc), start=info)
    return RateBoundedCertificate(lyapunov=X, gamma=X.gamma, lower_bound=lo, lower_bound_at=lo_at, bracket=br,
                                  time_s=time.perf_counter() - t0, message=X.status, start=info)


def pointwise_lmi_eigs(lyapunov: LPVStateFeedback, gp: GeneralizedLPV, gamma: float | None = None):
    """The largest relative eigenvalue of the analysis LMI (module docstring; over the rate
    vertices, divided by the matrix's largest |entry| as in :func:`tmfem.control.lpv.verify.verify`)
    and the smallest eigenvalue of X(rho), at every point of ``gp``'s grid (arrays of the grid's
    shape), with X(rho) = ``lyapunov.P_of`` and ``gamma`` (default the Lyapunov matrix's)."""
    g = lyapunov.gamma if gamma is None else gamma
    dXs = [sum((v[k] / lyapunov.half_width[k]) * lyapunov.P[1 + j] for j, k in enumerate(lyapunov.varying))
           if lyapunov.varying else 0.0 * lyapunov.P[0] for v in gp.rate_vertices()]
    lmi, minX = np.full(gp.grid_shape, -np.inf), np.full(gp.grid_shape, np.inf)
    for idx in np.ndindex(*gp.grid_shape):
        rho = np.array([a[i] for a, i in zip(gp.axes, idx)])
        X = lyapunov.P_of(rho)
        minX[idx] = np.linalg.eigvalsh((X + X.T) / 2).min()
        for dX in dXs:
            M = lmi_matrix(A=gp.A[idx], B1=gp.B1[idx], B2=gp.B2[idx], C1=gp.C1[idx], D11=gp.D11[idx],
                           D12=gp.D12[idx], P=X, Q=np.zeros((0, X.shape[0])), dP=dX, gamma=g)
            lmi[idx] = max(lmi[idx], float(np.linalg.eigvalsh((M + M.T) / 2).max() / np.abs(M).max()))
    return lmi, minX


def refine_certificate(certificate: RateBoundedCertificate, design, fine: GriddedLPV, *, W_e: float, W_u: float,
                       per_round: int = 4, max_rounds: int = 8, time_budget: float = 600.0, max_iter: int = 150,
                       margin: float = 1e-8, t_schedule=(1e-2, 1e-3, 1e-4), gamma: float | None = None,
                       progress=None) -> RateBoundedCertificate:
    """Cutting-plane refinement of a design-grid certificate until its LMI holds on ``fine``.

    The certificate's LMI is imposed at the design grid points only; between them the loop of
    the true plant and the controller's interpolated model (:func:`closed_loop_lpv` on ``fine``,
    as :func:`~tmfem.control.lpv.output_feedback.verify_output_feedback` builds it) may violate it. Each
    round re-checks X(rho) at every point and rate vertex of ``fine`` (:func:`pointwise_lmi_eigs`);
    if some fail, the ``per_round`` worst of them join the imposed points (with all rate vertices)
    and EIGOPT (:class:`~tmfem.control.lpv.eigopt.EigOpt` on the imposed points, balanced on the
    current X) re-solves the LMI at the certificate's gamma from the current X(rho); X(rho) stays
    affine in rho. A small relative eigenvalue of the fine-grid check (divided by the matrix's
    largest |entry| in the original coordinates) is not a small violation: for the 2-3 loop,
    +1.4e-5 there is +1.1 in EIGOPT's scaled, balanced coordinates (docs/guides/lpv.md), so the
    smoothing schedule ``t_schedule`` is the bisection's (1e-2, 1e-3, 1e-4), and each round
    reports the start's largest scaled eigenvalue (``start_scaled_eig``). Ends when the fine grid
    passes (``refinement["passed"]``), after ``max_rounds`` re-solves, when ``time_budget`` seconds
    are spent, or when a re-solve finds no point (reported, not a proof: EIGOPT is local).

    ``fine`` must contain the design grid (e.g. ``plant.resampled(plant.refined(4))`` or the
    COM linearisations on ``plant.refined(4)``): the imposed points are points of ``fine``.
    ``gamma``: the level of the re-check and the re-solves (default the certificate's; a level
    above it relaxes the w and p blocks, not the Lyapunov block A X + X A^T - dX/dt, which any
    level needs negative). Returns a new certificate (gamma that level): X(rho) the last one
    found (the input's when no round found one), ``refinement`` the rounds (points added, largest fine-grid eigenvalue
    before each round,
    evaluations, times) and ``passed``.

    Raises
    ------
    InputError
        No found certificate, bad options, or a ``fine`` grid that misses a design point.
    """
    if not certificate.found:
        raise InputError("certificate refinement: expected a found rate-bounded certificate, found none "
                         f"({certificate.message})")
    if gamma is not None and not (np.isfinite(gamma) and gamma >= certificate.gamma):
        raise InputError(f"certificate refinement: expected a level gamma >= the certificate's "
                         f"{certificate.gamma:.6g} (its X(rho) holds there on the design grid), found {gamma!r}")
    if not (int(per_round) == per_round >= 1 and int(max_rounds) == max_rounds >= 0 and time_budget > 0):
        raise InputError(f"certificate refinement: expected per_round >= 1, max_rounds >= 0 (integers) and a "
                         f"time budget > 0, found {per_round!r}, {max_rounds!r}, {time_budget!r}")
    X = certificate.lyapunov
    design_idx = design_points_in(X.axes, fine.axes, what="certificate refinement")
    t0, c0 = time.perf_counter(), time.process_time()
    deadline = t0 + time_budget
    gp = closed_loop_lpv(design, fine, W_e=W_e, W_u=W_u)
    co = Coordinates.of(gp)
    gamma, imposed, rounds = (X.gamma if gamma is None else float(gamma)), list(design_idx), []
    if gamma != X.gamma:
        X = replace(X, gamma=gamma)
    passed, stopped = False, "rounds"
    while True:
        t1, c1 = time.perf_counter(), time.process_time()
        lmi, minX = pointwise_lmi_eigs(X, gp)
        worst = float(lmi.max())
        at = [float(a[i]) for a, i in zip(gp.axes, np.unravel_index(int(np.argmax(lmi)), lmi.shape))]
        check_s = time.perf_counter() - t1
        fail = [tuple(int(i) for i in k) for k in np.argwhere((lmi >= 0) | (minX <= 0))]
        log.info("certificate refinement: %d imposed points, fine grid %s: %d failing, largest relative LMI "
                 "eigenvalue %.3e at %s (%.1f s)", len(imposed), gp.grid_shape, len(fail), worst, at, check_s)
        if not fail:
            passed, stopped = True, "passed"
            rounds.append({"round": len(rounds), "fine_max_eig": worst, "fine_max_eig_at": at, "failing": 0,
                           "check_s": check_s})
            break
        row = {"round": len(rounds), "fine_max_eig": worst, "fine_max_eig_at": at, "failing": len(fail),
               "check_s": check_s}
        new, stop = next_cut(fail, lmi, imposed, per_round=per_round, rounds_done=len(rounds),
                             max_rounds=max_rounds, deadline=deadline, axes=gp.axes, row=row)
        if stop:
            rounds.append(row)
            stopped = stop
            break
        imposed += new
        found, reason = resolve_on_points(gp, co, co.coefficients_of(X, gp), gamma=gamma, points=imposed, row=row,
                                          started=(t1, c1), what="certificate refinement", max_iter=max_iter,
                                          margin=margin, t_schedule=t_schedule, deadline=deadline)
        rounds.append(row)
        if progress is not None:
            progress(len(rounds))
        if found is None:
            stopped = "time budget" if reason == "time" else "not found"
            break
        Ps, _ = found
        X = LPVStateFeedback(gamma=gamma, P=[Tm_back(P, co.T) for P in Ps], Q=[np.zeros((0, gp.A.shape[-1]))] * len(Ps),
                             center=co.center, half_width=co.half, varying=co.varying,
                             axes=[a.copy() for a in X.axes], parameter_names=list(X.parameter_names),
                             rate_bounds=X.rate_bounds.copy(), state_names=list(X.state_names), solver="EIGOPT",
                             status=f"refined: {len(imposed)} points imposed", solve_time=0.0, build_time=0.0,
                             sizes={}, max_lmi_eig=row["largest_scaled_eig"], min_P_eig=np.nan)
    ref = {"passed": passed, "stopped": stopped, "rounds": rounds, "points_added": len(imposed) - len(design_idx),
           "points_imposed": len(imposed), "fine_grid": list(gp.grid_shape), "time_s": time.perf_counter() - t0,
           "cpu_s": time.process_time() - c0}
    log.info("certificate refinement: %s after %d rounds, %d points added (%.1f s)", stopped, len(rounds),
             ref["points_added"], ref["time_s"])
    return replace(certificate, lyapunov=X, gamma=gamma, refinement=ref,
                   message=certificate.message + f"; refined on {list(gp.grid_shape)}: {stopped}")
