"""python-control's ``hinfsyn`` (SLICOT SB10AD: Glover-Doyle formulas with its own gamma
iteration) as a synthesis route, guarded and verified.

SB10AD can loop for minutes on plants outside its assumptions and can report a gamma its
controller does not achieve (docs/guides/hinf.md), so this route:

* checks its assumptions before calling it: a regular plant (D12 full column rank, D21 full
  row rank), no invariant zeros of (A, B2, C1, D12) or (A, B1, C2, D21) on the imaginary
  axis (:func:`tmfem.control.linear.hinf_riccati.check_regular`), (A + alpha_1 I, B2)
  stabilisable and (C2, A + alpha_1 I) detectable
  (:func:`tmfem.control.linear.pbh.require_stabilizable_detectable`);
* runs it in a child process ended after :data:`TIMEOUT_S` seconds
  (:class:`~tmfem.errors.ResourceLimit`);
* never passes SB10AD's gamma on: the returned ``gamma`` is the verified norm of the
  assembled closed loop (:mod:`tmfem.control.linear.verification`).
"""
from __future__ import annotations

import time

import numpy as np

from tmfem.control.linear.verification import HinfDesign, closed_loop, controller_ss, hinf_norm
from tmfem.control.linear.hinf_riccati import check_regular
from tmfem.control.linear.lmi import SolverReport
from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tmfem.control.linear.pbh import require_stabilizable_detectable
from tmfem.errors import InfeasibleController, InputError, ResourceLimit


#: wall-time bound of one SB10AD call [s]
TIMEOUT_S = 120.0


def _sb10ad_child(conn, P, ny, nu):
    import control
    try:
        K, _, g, _ = control.hinfsyn(P, ny, nu)
        conn.send(("ok", (np.asarray(K.A), np.asarray(K.B), np.asarray(K.C), np.asarray(K.D)), float(g)))
    except Exception as exc:       # slycot raises its own error types
        conn.send(("error", str(exc), None))
    conn.close()


def _sb10ad_bounded(Pa: GeneralizedPlant, timeout_s: float):
    """python-control ``hinfsyn`` on ``Pa`` in a child process that is ended after
    ``timeout_s`` seconds (SB10AD cannot be interrupted in-process). Returns ((A_k, B_k,
    C_k, D_k), gamma reported by SB10AD)."""
    import multiprocessing as mp
    ctx = mp.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_sb10ad_child, args=(child, Pa.to_ss(), len(Pa.y_names), len(Pa.u_names)),
                       daemon=True)
    proc.start()
    child.close()
    try:
        if not parent.poll(timeout_s):
            raise ResourceLimit(f"hinfsyn (SLICOT SB10AD): expected a result within {timeout_s:g} s, "
                                "found none (its gamma iteration stalls on some plants): use "
                                "method='riccati' or 'lmi'")
        status, payload, g = parent.recv()
    except EOFError:
        raise InfeasibleController("hinfsyn (SLICOT SB10AD): its process ended without a result") from None
    finally:
        if proc.is_alive():
            proc.terminate()
        proc.join(5.0)
        parent.close()
    if status != "ok":
        raise InfeasibleController(f"hinfsyn (SLICOT SB10AD) on the alpha-shifted plant: expected a "
                                   f"controller, found the error: {payload}")
    return payload, g


def hinf_slicot(plant: GeneralizedPlant, *, alpha: float = 0.0, verify_rtol: float = 1e-3,
                timeout_s: float = TIMEOUT_S, operating_point=None) -> HinfDesign:
    """Output feedback by python-control ``hinfsyn`` (SLICOT SB10AD) on the alpha-shifted plant
    A + alpha_1 I, shifted back (A_k - alpha_1 I) as in
    :func:`tmfem.control.linear.hinf_lmi.hinf_lmi`; ``gamma`` is the verified closed-loop norm.

    Raises
    ------
    InputError
        alpha < 0, D22 != 0, or a plant outside SB10AD's assumptions (module docstring).
    InfeasibleController
        Not stabilisable/detectable (mode named), SB10AD's error, an unstable closed loop or
        a non-finite level.
    ResourceLimit
        SB10AD did not finish within ``timeout_s``.
    """
    if not (np.isfinite(alpha) and alpha >= 0):
        raise InputError(f"alpha_1: expected a finite value >= 0, found {alpha!r}")
    if np.any(plant.D22 != 0):
        raise InputError(f"generalised plant: expected D22 = 0, found max |D22| = "
                         f"{np.max(np.abs(plant.D22)):.3g}")
    Pa = plant.shifted(alpha)
    check_regular(plant, alpha=alpha)
    require_stabilizable_detectable(plant.A, plant.B2, plant.C2, alpha=alpha,
                                    state_names=plant.state_names)
    t0 = time.perf_counter()
    K, g = _sb10ad_bounded(Pa, timeout_s)
    dt = time.perf_counter() - t0
    if not np.isfinite(float(g)):
        raise InfeasibleController(f"hinfsyn (SLICOT SB10AD): expected a finite gamma, found {g}")
    Ak, Bk, Ck, Dk = K
    Kss = controller_ss(plant, Ak - alpha * np.eye(Ak.shape[0]), Bk, Ck, Dk)
    T = closed_loop(plant, Kss)
    re = float(np.max(np.real(T.poles())))
    if not re < -alpha + verify_rtol * max(alpha, 1e-6) + 1e-9:
        raise InfeasibleController(f"closed loop (SB10AD): expected all poles with Re < "
                                   f"{-alpha:g}, found max Re = {re:.6g}")
    nrm = hinf_norm(T)[0]
    rep = SolverReport(solver="hinfsyn (SLICOT SB10AD)", status=f"gamma reported {float(g):.6g}",
                       solve_time_s=dt, n_variables=0, lmi_sizes={})
    return HinfDesign(controller=Kss, gamma=nrm, alpha=float(alpha), closed_loop=T,
                      closed_loop_norm=nrm, closed_loop_max_real_part=re, solver=rep, plant=plant,
                      kind="output feedback (SB10AD, shifted plant)",
                      operating_point=dict(operating_point or {}))
