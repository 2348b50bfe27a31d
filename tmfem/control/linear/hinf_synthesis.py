"""H-infinity synthesis with python-control's calling convention, verified by construction.

``hinfsyn(P, nmeas, ncon)`` takes a ``StateSpace`` or ``TransferFunction`` with inputs [w, u]
and outputs [p, y] (the last ``ncon`` inputs are u, the last ``nmeas`` outputs are y, as
python-control's and MATLAB's ``hinfsyn``) and returns ``(K, CL, gamma, info)``:

* the plant is checked first: continuous time (a discrete-time plant is refused: convert it
  or design in continuous time), real and finite data, at least one state, (A, B2)
  stabilisable and (C2, A) detectable with all closed-loop poles left of -alpha_1 (the mode
  that fails is named, :func:`tmfem.control.linear.pbh.require_stabilizable_detectable`);
* D22 != 0 is handled by loop shifting: the design is made for y0 = y - D22 u (D22 = 0) and
  the controller K0 is closed around -D22, K = K0 (I + D22 K0)^-1 (well posed when
  I + D_k0 D22 is invertible);
* every route returns a controller whose closed loop with the *given* plant was assembled
  and checked (poles left of -alpha_1; ||T_pw||_inf by AB13DD cross-checked by a frequency
  sweep, :mod:`tmfem.control.linear.verification`), and ``gamma`` is never below that norm.

Routes (``method``):

* ``"riccati"``: the Riccati test of the eliminated LMIs with a gamma bisection that moves
  down only on a verified central controller
  (:func:`tmfem.control.linear.hinf_central.hinf_central`); regular plants only (D12 full
  column rank, D21 full row rank, no imaginary-axis zeros of P12, P21);
* ``"lmi"``: the eliminated LMIs (eq. 5.65) with an interior-point SDP solver (Clarabel) and
  the controller recovered by eq. 5.67 (:func:`tmfem.control.linear.hinf_lmi.hinf_lmi`); any
  plant, O(n^6) time; refused when its controller is verified far below the SDP optimum
  (an inaccurate SDP solution, :func:`_lmi_backoff`);
* ``"slicot"``: python-control's ``hinfsyn`` (SB10AD), guarded and verified
  (:func:`tmfem.control.linear.hinf_slicot.hinf_slicot`);
* ``"auto"`` (default): ``"riccati"`` for a regular plant, else ``"lmi"``. Where the Riccati
  bisection met numerical failures (levels it could not decide) and the plant has at most
  :data:`AUTO_LMI_MAX_STATES` states, the LMI optimum is computed too and the LMI
  controller is used when it is verified lower (not tried when the LMI optimum lies below
  the Riccati route's certified lower bound: that SDP solution is inaccurate).

``alpha`` is alpha_1 of eq. 5.67 (closed-loop poles with Re < -alpha_1) by the shift A +
alpha_1 I of 7.3, in every route.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from tmfem.control.linear.verification import HinfDesign, check_loop, closed_loop, controller_ss
from tmfem.control.linear.hinf_central import hinf_central
from tmfem.control.linear.hinf_lmi import hinf_gamma, hinf_lmi, hinf_state_feedback
from tmfem.control.linear.hinf_riccati import (bisect_verified, check_regular, gamma_lower_bound,
                                               numerical_rank, state_feedback_gain,
                                               state_feedback_verdict)
from tmfem.control.linear.hinf_slicot import hinf_slicot
from tmfem.control.linear.lmi import SolverReport
from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tmfem.control.linear.pbh import require_stabilizable_detectable
from tmfem.errors import InfeasibleController, InputError
from tmfem.resources import check_synthesis_budget

log = logging.getLogger(__name__)

#: output-feedback routes of :func:`hinfsyn`
METHODS = ("auto", "riccati", "lmi", "slicot")
#: state-feedback routes of :func:`hinfsyn_state`
STATE_METHODS = ("auto", "riccati", "lmi")
#: largest plant for which "auto" cross-checks an undecided Riccati bisection with the LMIs
AUTO_LMI_MAX_STATES = 30


@dataclass
class HinfResult:
    """Result of :func:`hinfsyn` / :func:`hinfsyn_state`; unpacks as ``K, CL, gamma, info``.

    ``K``: controller (inputs named as the plant's measured outputs, or its states for state
    feedback; outputs named as its control inputs); ``CL``: closed loop from w to p;
    ``gamma``: the certified level (>= ``info["verified_norm"]``); ``info``: method, route
    choice, verified norm, certified lower bound, closed-loop poles, times;
    ``design``: the route's :class:`~tmfem.control.linear.verification.HinfDesign`.
    """

    K: object
    CL: object
    gamma: float
    info: dict
    design: HinfDesign

    def __iter__(self):
        return iter((self.K, self.CL, self.gamma, self.info))


def _plant(P, nmeas, ncon) -> GeneralizedPlant:
    if isinstance(P, GeneralizedPlant):
        if (nmeas, ncon) != (P.C2.shape[0], P.B2.shape[1]):
            raise InputError(f"hinfsyn: expected nmeas = {P.C2.shape[0]}, ncon = {P.B2.shape[1]} "
                             f"for this GeneralizedPlant, found {nmeas}, {ncon}")
        G = P
    else:
        G = GeneralizedPlant.from_system(P, nmeas=nmeas, ncon=ncon)
    if G.A.shape[0] == 0:
        raise InputError("hinfsyn: expected a plant with at least one state, found a static map")
    return G


def _check_options(alpha, gamma_tol, method, methods):
    if method not in methods:
        raise InputError(f"method: expected one of {methods}, found {method!r}")
    if not (isinstance(alpha, (int, float, np.floating)) and np.isfinite(alpha) and alpha >= 0):
        raise InputError(f"alpha: expected a finite value >= 0, found {alpha!r}")
    if not (isinstance(gamma_tol, (int, float, np.floating)) and 0 < gamma_tol < 1):
        raise InputError(f"gamma_tol: expected 0 < gamma_tol < 1, found {gamma_tol!r}")


def loop_shift(controller, D22: np.ndarray, plant: GeneralizedPlant):
    """K = K0 (I + D22 K0)^-1 in state space: the controller for y = y0 + D22 u from K0
    designed for y0 (module docstring). Raises InfeasibleController when I + D_k0 D22 is
    singular (the interconnection is not well posed)."""
    Ak, Bk, Ck, Dk = (np.asarray(M) for M in (controller.A, controller.B, controller.C, controller.D))
    E = np.eye(Dk.shape[0]) + Dk @ D22
    if np.linalg.cond(E) > 1e12:
        raise InfeasibleController(f"loop shifting: expected I + D_k D22 invertible, found "
                                   f"cond = {np.linalg.cond(E):.3g} (not well posed)")
    M = np.linalg.inv(E)
    return controller_ss(plant, Ak - Bk @ D22 @ M @ Ck, Bk @ (np.eye(D22.shape[0]) - D22 @ M @ Dk),
                         M @ Ck, M @ Dk)


#: relative levels above the LMI optimum at which :func:`hinfsyn`'s LMI route recovers a
#: controller, in turn, until one passes its closed-loop check (the stated tolerance of the
#: LMI route is the last one)
LMI_BACKOFF = (1e-2, 3e-2, 1e-1)


def _lmi_backoff(G0, *, alpha, solver, gamma_tol):
    """:func:`~tmfem.control.linear.hinf_lmi.hinf_lmi` at gamma_tol, then at the levels of
    :data:`LMI_BACKOFF` above it, until the recovered controller is verified; refused when
    the verified norm lies more than the last back-off below the SDP optimum (an inaccurate
    SDP solution: its level would be reported far above what the controller achieves)."""
    why = []
    for rel in (gamma_tol,) + tuple(r for r in LMI_BACKOFF if r > gamma_tol):
        try:
            d = hinf_lmi(G0, alpha=alpha, solver=solver, gamma_relax=rel)
        except InfeasibleController as exc:
            if "controller" not in str(exc):
                raise                 # the SDP itself failed: no level helps
            why.append(f"(1 + {rel:g}) gamma_LMI: {exc}")
            continue
        if d.closed_loop_norm * (1 + LMI_BACKOFF[-1]) < d.gamma_lmi:
            # the LMIs' optimum is the H-infinity optimum: a controller verified well below it
            # proves the SDP solution inaccurate, and the level it reports meaningless
            raise InfeasibleController(
                f"LMI route: expected the SDP optimum gamma_LMI = {d.gamma_lmi:.6g} at most "
                f"(1 + {LMI_BACKOFF[-1]:g}) x the verified norm of its own controller, found that "
                f"norm {d.closed_loop_norm:.6g}: the SDP solution is inaccurate (ill-conditioned or "
                "near-integrating data); use method='riccati' or 'auto'")
        d.info["lmi_backoff"] = rel
        return d
    raise InfeasibleController("LMI route: expected a verified controller at one of the levels "
                               f"{(gamma_tol,) + LMI_BACKOFF} above the LMI optimum, found: "
                               + " | ".join(why))


def _route(G0, method, alpha, gamma_tol, solver):
    """(design, route, reason, times) of one output-feedback route on a D22 = 0 plant."""
    times = {}

    def run(name):
        check_synthesis_budget(route=name, n=G0.A.shape[0])      # before the route starts
        t0 = time.perf_counter()
        try:
            if name == "riccati":
                return hinf_central(G0, alpha=alpha, tol=gamma_tol / 2, rtol=gamma_tol / 2)
            if name == "lmi":
                return _lmi_backoff(G0, alpha=alpha, solver=solver, gamma_tol=gamma_tol)
            return hinf_slicot(G0, alpha=alpha)
        finally:
            times[name] = time.perf_counter() - t0

    if method != "auto":
        return run(method), method, "requested", times
    try:
        check_regular(G0, alpha=alpha)
    except InputError as exc:
        return _singular_auto(G0, alpha=alpha, gamma_tol=gamma_tol, solver=solver, times=times,
                              why=str(exc))
    try:
        d = run("riccati")
    except InfeasibleController as exc:
        return run("lmi"), "lmi", f"Riccati route failed ({exc})", times
    unknown = d.info.get("unknown_levels", [])
    if unknown and G0.A.shape[0] <= AUTO_LMI_MAX_STATES:
        t0 = time.perf_counter()
        try:
            g_lmi, _ = hinf_gamma(G0, alpha=alpha, solver=solver)
        except InfeasibleController as exc:
            log.info("auto: the LMI cross-check failed (%s); keeping the Riccati design", exc)
            g_lmi = np.inf
        times["lmi gamma"] = time.perf_counter() - t0
        if d.gamma_lower is not None and g_lmi < d.gamma_lower * (1 - gamma_tol):
            # below a certificate of infeasibility: the SDP solution is inaccurate
            log.info("auto: LMI optimum %.6g below the certified lower bound %.6g; keeping the "
                     "Riccati design", g_lmi, d.gamma_lower)
        elif g_lmi * (1 + gamma_tol) < d.gamma / (1 + gamma_tol):
            try:
                d2 = run("lmi")
            except InfeasibleController as exc:
                log.warning("auto: LMI optimum %.6g below the Riccati level %.6g, but its "
                            "controller failed: %s", g_lmi, d.gamma, exc)
            else:
                if d2.gamma < d.gamma:
                    return d2, "lmi", (f"Riccati bisection undecided at {len(unknown)} levels; "
                                       f"LMI optimum {g_lmi:.6g} lower"), times
        return d, "riccati", f"regular plant; {len(unknown)} undecided levels cross-checked by the LMIs", times
    return d, "riccati", "regular plant", times


def regularized(G0: GeneralizedPlant, rel: float, *, states: bool = False) -> GeneralizedPlant:
    """The plant made regular: p gets the extra outputs eps_u u where D12 lacks column rank,
    y gets eps_y w' (new exogenous inputs w') where D21 lacks row rank, with eps_u = rel
    max(||C1||, ||D12||) and eps_y = rel max(||B1||, ||D21||). With ``states``, also p gets
    eps_x x and x' gets eps_x w'' (eps_x = rel max(||C1||, ||B1||)), which removes invariant
    zeros of P12 and P21 on the imaginary axis (an integrator p does not see). The closed
    loop of the original plant is a sub-block of the regularised one, so a controller's norm
    with the original plant is at most its norm with the regularised plant (and the
    regularised optimum decreases to the original one as rel -> 0)."""
    n, nw, nu, np_, ny = (G0.sizes[k] for k in ("n", "nw", "nu", "np", "ny"))
    A, B1, C1, C2, D11, D12, D21 = G0.A, G0.B1, G0.C1, G0.C2, G0.D11, G0.D12, G0.D21
    p_names, w_names = list(G0.p_names), list(G0.w_names)
    if states:
        e = rel * max(np.linalg.norm(C1, 2), np.linalg.norm(B1, 2), 1e-300)
        C1 = np.vstack([C1, e * np.eye(n)])
        D12 = np.vstack([D12, np.zeros((n, nu))])
        D11 = np.vstack([D11, np.zeros((n, nw))])
        p_names += [f"reg_{s}" for s in G0.state_names]
        B1 = np.hstack([B1, e * np.eye(n)])
        D21 = np.hstack([D21, np.zeros((ny, n))])
        D11 = np.hstack([D11, np.zeros((D11.shape[0], n))])
        w_names += [f"reg_w_{s}" for s in G0.state_names]
    if numerical_rank(D12) < nu:
        e = rel * max(np.linalg.norm(C1, 2), np.linalg.norm(D12, 2), 1e-300)
        C1 = np.vstack([C1, np.zeros((nu, n))])
        D11 = np.vstack([D11, np.zeros((nu, D11.shape[1]))])
        D12 = np.vstack([D12, e * np.eye(nu)])
        p_names += [f"reg_{s}" for s in G0.u_names]
    if numerical_rank(D21) < ny:
        e = rel * max(np.linalg.norm(B1, 2), np.linalg.norm(D21, 2), 1e-300)
        B1 = np.hstack([B1, np.zeros((n, ny))])
        D11 = np.hstack([D11, np.zeros((D11.shape[0], ny))])
        D21 = np.hstack([D21, e * np.eye(ny)])
        w_names += [f"reg_{s}" for s in G0.y_names]
    return GeneralizedPlant(A=A, B1=B1, B2=G0.B2, C1=C1, C2=C2, D11=D11, D12=D12, D21=D21,
                            D22=G0.D22, state_names=G0.state_names, w_names=w_names,
                            u_names=G0.u_names, p_names=p_names, y_names=G0.y_names)


#: relative regularisations of :func:`regularized` tried, in turn, by the "auto" route on a
#: singular plant
REGULARIZATIONS = (1e-2, 1e-3, 1e-4, 1e-5)


def _regularized_riccati(G0, *, alpha, gamma_tol, target):
    """The Riccati route on :func:`regularized` plants (:data:`REGULARIZATIONS` in turn, until
    the verified norm with the original plant is within gamma_tol of ``target``), each
    controller verified with the original plant: the best verified design, or
    InfeasibleController."""
    best, why = None, []
    for rel in REGULARIZATIONS:
        try:
            Gr = regularized(G0, rel)
            try:
                check_regular(Gr, alpha=alpha)
            except InputError as exc:
                if "invariant zero" not in str(exc):
                    raise
                Gr = regularized(G0, rel, states=True)
                check_regular(Gr, alpha=alpha)
            d = hinf_central(Gr, alpha=alpha, tol=gamma_tol / 2, rtol=gamma_tol / 2)
            T = closed_loop(G0, d.controller)
            nrm, re = check_loop(T, gamma=d.gamma, alpha=alpha, rtol=1e-6,
                                 what=f"regularised Riccati controller (rel {rel:g})")
        except (InfeasibleController, InputError) as exc:
            why.append(f"rel {rel:g}: {exc}")
            continue
        if best is None or nrm < best.closed_loop_norm:
            best = HinfDesign(controller=d.controller, gamma=nrm, alpha=float(alpha), closed_loop=T,
                              closed_loop_norm=nrm, closed_loop_max_real_part=re, solver=d.solver,
                              plant=G0, kind=f"output feedback (central, regularised plant, rel {rel:g})",
                              gamma_lmi=d.gamma_lmi, info={"regularization": rel})
        if nrm <= target * (1 + gamma_tol):
            break
    if best is None:
        raise InfeasibleController("regularised Riccati route: expected a verified controller, "
                                   "found: " + " | ".join(why))
    return best


def _singular_auto(G0, *, alpha, gamma_tol, solver, times, why):
    """"auto" on a plant outside the Riccati route: the LMIs, and where their controller fails
    or stays above the LMI optimum, the Riccati route on regularised plants; the lower
    verified design."""
    t0 = time.perf_counter()
    designs, errors = [], []
    try:
        d = _lmi_backoff(G0, alpha=alpha, solver=solver, gamma_tol=gamma_tol)
        designs.append((d, "lmi"))
        target = d.gamma_lmi
    except InfeasibleController as exc:
        errors.append(f"lmi: {exc}")
        target = 0.0              # no trusted optimum: every regularisation is tried
    times["lmi"] = time.perf_counter() - t0
    if not designs or designs[0][0].closed_loop_norm > target * (1 + gamma_tol):
        t0 = time.perf_counter()
        try:
            designs.append((_regularized_riccati(G0, alpha=alpha, gamma_tol=gamma_tol, target=target),
                            "regularized riccati"))
        except InfeasibleController as exc:
            errors.append(f"regularized riccati: {exc}")
        times["regularized riccati"] = time.perf_counter() - t0
    if not designs:
        raise InfeasibleController("auto route on a singular plant: expected a verified controller, "
                                   "found: " + " | ".join(errors))
    d, route = min(designs, key=lambda x: x[0].gamma)
    return d, route, f"singular plant for the Riccati route ({why})", times


def _result(G, design, K, T, route, reason, times, t0, *, alpha, gamma_tol, extra=None) -> HinfResult:
    if K is design.controller and T is design.closed_loop:
        nrm, re = design.closed_loop_norm, design.closed_loop_max_real_part     # verified by the route
    else:
        nrm, re = check_loop(T, gamma=design.gamma, alpha=alpha, rtol=1e-6, what="hinfsyn closed loop")
    gamma = max(float(design.gamma), nrm)
    bound = gamma_lower_bound(G)
    info = {"method": route, "route_reason": reason, "verified_norm": nrm,
            "gamma_lower": design.gamma_lower, "route_optimum": design.gamma_lmi,
            "closed_loop_poles": np.asarray(T.poles()), "closed_loop_max_real_part": re,
            "alpha": float(alpha), "feedthrough_bound": bound,
            # the level is the feedthrough bound (gamma = ||Pi_12 D11|| or ||D11 Pi_21||) to the
            # route's tolerance: no controller can lower it, the dynamics do not matter
            "feedthrough_sets_gamma": bool(bound > 0 and gamma <= bound * (1 + 2 * gamma_tol)),
            "solver_times_s": times, "time_s": time.perf_counter() - t0,
            "solver": design.solver.as_dict(), "kind": design.kind}
    info.update(extra or {})
    log.info("hinfsyn (%s): gamma %.8g, verified ||T_pw|| %.8g, max Re %.4g, %.2f s", route, gamma,
             nrm, re, info["time_s"])
    return HinfResult(K=K, CL=T, gamma=gamma, info=info, design=design)


def hinfsyn(P, nmeas: int, ncon: int, *, method: str = "auto", alpha: float = 0.0,
            gamma_tol: float = 1e-3, solver: str = "CLARABEL") -> HinfResult:
    """H-infinity output-feedback synthesis (module docstring), python-control's convention.

    Parameters
    ----------
    P : StateSpace, TransferFunction or GeneralizedPlant
        Inputs [w, u], outputs [p, y]; continuous time.
    nmeas, ncon : int
        Number of measured outputs y (the last outputs) and control inputs u (the last inputs).
    method : {"auto", "riccati", "lmi", "slicot"}
        Synthesis route (module docstring).
    alpha : float
        alpha_1 >= 0: closed-loop poles with Re < -alpha_1 (eq. 5.67 by the shift of 7.3).
    gamma_tol : float
        Relative distance of the returned level from the route's optimum.
    solver : {"CLARABEL", "SCS"}
        SDP solver of the LMI route (SCS results are refused when they fail verification).

    Returns
    -------
    HinfResult
        ``K, CL, gamma, info = hinfsyn(...)``.

    Raises
    ------
    InputError
        Bad plant data or options (what was expected and found).
    InfeasibleController
        Not stabilisable/detectable (the mode named), or no verified controller.
    """
    t0 = time.perf_counter()
    _check_options(alpha, gamma_tol, method, METHODS)
    G = _plant(P, nmeas, ncon)
    # before the PBH test, itself an eigendecomposition of A (the routes check their own)
    check_synthesis_budget(route="lmi" if method == "lmi" else "riccati", n=G.A.shape[0])
    require_stabilizable_detectable(G.A, G.B2, G.C2, alpha=alpha, state_names=G.state_names)
    shift = bool(np.any(G.D22 != 0))
    G0 = GeneralizedPlant(**{**G.__dict__, "D22": np.zeros_like(G.D22)}) if shift else G
    design, route, reason, times = _route(G0, method, alpha, gamma_tol, solver)
    K = loop_shift(design.controller, G.D22, G) if shift else design.controller
    T = closed_loop(G, K) if shift else design.closed_loop
    return _result(G, design, K, T, route, reason, times, t0, alpha=alpha,
                   gamma_tol=gamma_tol, extra={"loop_shifted_D22": shift})


def hinfsyn_state(P, ncon: int, *, method: str = "auto", alpha: float = 0.0,
                  gamma_tol: float = 1e-3, solver: str = "CLARABEL") -> HinfResult:
    """H-infinity static state feedback u = K x, verified (the state-feedback counterpart of
    :func:`hinfsyn`).

    ``P`` has inputs [w, u] (the last ``ncon`` are u) and outputs p only; the state is
    measured. Routes: ``"riccati"`` (bisection on the game Riccati equation that moves down
    only on a gain whose closed loop was checked; D12 of full column rank), ``"lmi"`` (the
    state-feedback LMI with Clarabel, :func:`tmfem.control.linear.hinf_lmi.hinf_state_feedback`),
    ``"auto"``: Riccati when D12 has full column rank, else the LMI.
    """
    import control
    t0 = time.perf_counter()
    _check_options(alpha, gamma_tol, method, STATE_METHODS)
    if isinstance(P, control.TransferFunction):
        P = control.ss(P)
    if isinstance(P, control.StateSpace):
        # y = x appended, so that the plant is partitioned as for output feedback
        n = P.nstates
        Px = control.ss(P.A, P.B, np.vstack([P.C, np.eye(n)]),
                        np.vstack([P.D, np.zeros((n, P.ninputs))]), inputs=list(P.input_labels),
                        outputs=list(P.output_labels) + [f"meas_{s}" for s in P.state_labels],
                        states=list(P.state_labels), dt=P.dt) if n else P
        G = _plant(Px, P.nstates, ncon)
    else:
        raise InputError(f"hinfsyn_state: expected a python-control StateSpace or TransferFunction, "
                         f"found {type(P).__name__}")
    # the Riccati estimate (the state-feedback LMI has one n x n unknown, the route's own cost)
    check_synthesis_budget(route="riccati", n=G.A.shape[0], given="hinfsyn_state")
    require_stabilizable_detectable(G.A, G.B2, np.eye(G.A.shape[0]), alpha=alpha,
                                    state_names=G.state_names)
    full_rank = numerical_rank(G.D12) == G.B2.shape[1]
    route = method if method != "auto" else ("riccati" if full_rank else "lmi")
    reason = "requested" if method != "auto" else ("D12 full column rank" if full_rank else
                                                    "D12 rank deficient")
    t1 = time.perf_counter()
    if route == "lmi":
        design = hinf_state_feedback(G, alpha=alpha, solver=solver, gamma_relax=gamma_tol)
    else:
        if not full_rank:
            raise InputError(f"hinfsyn_state: the Riccati route expects D12 of full column rank "
                             f"{G.B2.shape[1]}, found rank {numerical_rank(G.D12)}: use "
                             "method='lmi'")
        try:
            design = _state_feedback_riccati(G, alpha=alpha, gamma_tol=gamma_tol)
        except InfeasibleController as exc:
            if method != "auto":
                raise
            route, reason = "lmi", f"Riccati route failed ({exc})"
            design = hinf_state_feedback(G, alpha=alpha, solver=solver, gamma_relax=gamma_tol)
    times = {route: time.perf_counter() - t1}
    return _result(G, design, design.controller, design.closed_loop, route, reason, times, t0,
                   alpha=alpha, gamma_tol=gamma_tol)


def _state_feedback_riccati(G: GeneralizedPlant, *, alpha: float, gamma_tol: float) -> HinfDesign:
    """Verified Riccati bisection for u = K x (:func:`hinfsyn_state`)."""
    import control
    n = G.A.shape[0]
    Aa = G.A + alpha * np.eye(n)
    args = (Aa, G.B1, G.B2, G.C1, G.D11, G.D12)

    def loop(Kx, A):
        return control.ss(A + G.B2 @ Kx, G.B1, G.C1 + G.D12 @ Kx, G.D11,
                          inputs=list(G.w_names), outputs=list(G.p_names), name="T_pw")

    def certify(g):
        try:
            Kx = state_feedback_gain(*args, g)
            nrm, _ = check_loop(loop(Kx, Aa), gamma=g, alpha=0.0, rtol=1e-9,
                                what=f"state feedback at gamma = {g:.8g}")
        except InfeasibleController as exc:
            return False, None, str(exc)
        return True, Kx, ""

    it = bisect_verified(lambda g: state_feedback_verdict(*args, g), certify,
                         lower=float(np.linalg.norm(G.D11, 2)), rtol=gamma_tol / 2,
                         gamma_max=1e8, what="state-feedback Riccati test")
    gamma = it.gamma * (1 + gamma_tol / 2)
    ok, Kx, why = certify(gamma)
    if not ok:
        gamma, Kx = it.gamma, it.evidence
    T = loop(Kx, G.A)
    nrm, re = check_loop(T, gamma=gamma, alpha=alpha, rtol=1e-6, what="state feedback (Riccati)")
    Kss = control.ss(np.zeros((0, 0)), np.zeros((0, n)), np.zeros((G.B2.shape[1], 0)), Kx,
                     inputs=list(G.state_names), outputs=list(G.u_names), name="K_sf")
    rep = SolverReport(solver="ARE", status=f"verified Riccati bisection ({it.steps} steps)",
                       solve_time_s=it.time_s, n_variables=0, lmi_sizes={}, iterations=it.steps)
    return HinfDesign(controller=Kss, gamma=gamma, alpha=float(alpha), closed_loop=T,
                      closed_loop_norm=nrm, closed_loop_max_real_part=re, solver=rep, plant=G,
                      kind="state feedback (Riccati)", gamma_lmi=it.gamma, gamma_lower=it.lower,
                      info={"unknown_levels": it.unknown})
