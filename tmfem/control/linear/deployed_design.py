"""H-infinity design at a deployed configuration, end to end (7.3-7.4), and its files.

``deployed_hinf(system)`` = :func:`~tmfem.control.linear.generalized_plant.deployed_plant` (eq. 5.62) +
:func:`~tmfem.control.linear.generalized_plant.generalized_plant` (Fig. 7.1, weights of 7.4) + PBH (eq. 5.71) +
:func:`~tmfem.control.linear.hinf_lmi.hinf_lmi` (eqs. 5.63-5.67). The controller is a python-control
``StateSpace`` from the measured ``y_<state>`` (state perturbation minus reference) to the
rest-length perturbations ``r_<tendon>``; ``design.operating_point`` holds q_e, u_e, z_e:
the applied rest lengths are u_e + K y.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from tmfem.control.linear.verification import HinfDesign, verify
from tmfem.control.linear.hinf_central import hinf_central
from tmfem.control.linear.hinf_lmi import hinf_lmi
from tmfem.control.linear.hinf_slicot import hinf_slicot
from tmfem.control.linear.hinf_synthesis import hinfsyn
from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tmfem.control.linear.pbh import PBHResult, pbh_ss
from tmfem.control.linear.generalized_plant import DeployedPlant, deployed_plant, generalized_plant
from tmfem.errors import InfeasibleController, InputError
from tmfem.system.problem import UNCONTROLLABLE, default_u_m

log = logging.getLogger(__name__)

#: synthesis methods of :func:`deployed_hinf`
METHODS = ("auto", "lmi", "riccati", "central")
#: default synthesis method of :func:`deployed_hinf` and ``tmfem control hinf``: the route of
#: :func:`tmfem.control.linear.hinf_synthesis.hinfsyn` that is right on the whole regression family
DEFAULT_METHOD = "auto"
#: default solver of the eliminated LMIs for ``method="lmi"`` (their verified Riccati test)
DEFAULT_SOLVER = "ARE"


@dataclass
class DeployedDesign:
    """A deployed system's plant, PBH verdicts and H-infinity design."""

    plant: DeployedPlant
    generalized: GeneralizedPlant
    pbh: PBHResult
    design: HinfDesign | None
    u_m: float
    notes: tuple = ()
    excluded_modes: tuple = ()

    def summary(self) -> dict:
        out = {"system": self.plant.model.system.name,
               "open_loop_f_max_hz": self.plant.f_max_hz,
               "open_loop_f_max_printed_hz": self.plant.model.system.printed.get("f_max_hz"),
               "n_states": int(self.plant.ss.nstates), "n_inputs": int(self.plant.ss.ninputs),
               "membrane_points": [list(p) for p in self.plant.points],
               "membrane_modes": self.plant.membrane_modes.K,
               "membrane_mode_choice": self.plant.membrane_modes.to_dict(),
               "u_m": self.u_m, "pbh": self.pbh.as_dict()}
        if self.excluded_modes:
            out["excluded_modes"] = [{"eigenvalue": [float(m.real), float(m.imag)],
                                      "frequency_hz": float(abs(m) / (2 * np.pi))} for m in self.excluded_modes]
        notes = list(self.notes)
        if self.design is not None:
            d = self.design.summary()
            out.update({"gamma": d["gamma"], "alpha": d["alpha"],
                        "closed_loop_max_real_part": d["closed_loop_max_real_part"],
                        "closed_loop_hinf_norm": d["closed_loop_hinf_norm"],
                        "controller_order": d["controller_order"], "method": d["kind"],
                        "cond_I_minus_RS": d["cond_I_minus_RS"], "solver": d["solver"]})
            nrm = d["closed_loop_hinf_norm"]
            if np.isfinite(nrm) and nrm < 0.9 * d["gamma"]:
                notes.append(
                    f"gamma = {d['gamma']:.4g} bounds the closed loop's gain on the line Re s = "
                    f"-alpha_1 = -{d['alpha']:g} (the alpha_1-shifted plant of eqs. 5.64-5.65, "
                    "which places the poles left of -alpha_1); on the imaginary axis the loop "
                    f"achieves ||T_pw||_inf = {nrm:.4g}: the shift makes gamma a conservative "
                    "bound, the norm is the loop's")
        out["notes"] = notes
        return out


def deployed_hinf(system, *, alpha: float | None = None, u_m: float | None = None,
                  membrane_modes: int | None = None, solver: str | None = None,
                  synthesize: bool = True, pbh_tol: float | None = None,
                  method: str = DEFAULT_METHOD, uncontrollable: str | None = None) -> DeployedDesign:
    """Plant, PBH and H-infinity controller of a deployed system (7.3-7.4).

    Parameters
    ----------
    alpha, u_m, membrane_modes : optional
        alpha_1 [1/s], u_m [m] of W_u = I/u_m, and K; defaults: the system file's ``[control]``
        alpha and u_m (7.4's values for the deployed presets), else :func:`default_alpha` and
        :func:`tmfem.system.problem.default_u_m` (the system's own scales); K from
        ``[models.com]``.
    solver : {"ARE", "CLARABEL", "SCS"}, optional
        How the eliminated LMIs are solved with ``method="lmi"``
        (:func:`~tmfem.control.linear.hinf_lmi.hinf_lmi`); default :data:`DEFAULT_SOLVER`,
        their Riccati characterisation with a verified bisection (the plants of Fig. 7.1 are
        regular: D12 = [0; W_u], D21 = [-[I; 0], W_d I]). With ``method="auto"`` the SDP
        solver of a fallback to the LMIs (CLARABEL or SCS).
    synthesize : bool
        False: plant and PBH only (``tmfem control pbh``).
    method : {"auto", "lmi", "riccati", "central"}
        ``"auto"`` (default): :func:`~tmfem.control.linear.hinf_synthesis.hinfsyn`'s default route
        (the verified Riccati bisection with the central controller on regular plants, the
        LMIs otherwise); the eliminated LMIs (:func:`~tmfem.control.linear.hinf_lmi.hinf_lmi`),
        python-control's hinfsyn on the alpha-shifted plant
        (:func:`~tmfem.control.linear.hinf_slicot.hinf_slicot`) or the central
        (minimum-entropy) controller at 1.01 gamma_opt
        (:func:`~tmfem.control.linear.hinf_central.hinf_central`: the deployments' controller).
    uncontrollable : {"refuse", "exclude"}, optional
        What to do with modes that no tendon reaches (PBH, eq. 5.71; on the undamped COM they
        sit on the imaginary axis, so no controller makes the loop stable); default the file's
        ``[control] uncontrollable`` (itself "refuse" by default): ``"refuse"`` names them;
        ``"exclude"`` designs for the plant without them
        (:meth:`~tmfem.control.linear.partitioned_plant.GeneralizedPlant.reachable_part`: in
        Fig. 7.1 no exogenous input drives the states either, so the loop from w to p is
        unchanged) and lists them: in closed loop they keep their open-loop dynamics.
    """
    if uncontrollable not in (None,) + UNCONTROLLABLE:
        raise InputError(f"uncontrollable: expected one of {list(UNCONTROLLABLE)}, found {uncontrollable!r}")
    if method not in METHODS:
        raise InputError(f"method: expected one of {METHODS}, found {method!r}")
    if solver is not None and method not in ("lmi", "auto"):
        raise InputError(f"solver: applies to method 'lmi' or 'auto', found method {method!r}")
    if method == "auto" and solver not in (None, "CLARABEL", "SCS"):
        raise InputError(f"solver: expected CLARABEL or SCS with method 'auto' (the SDP solver of "
                         f"its LMI fallback), found {solver!r}")
    w = system.problem.control
    uncontrollable = uncontrollable or w.uncontrollable
    notes = []
    if u_m is None and w.u_m is None:
        u_m = default_u_m(system)
        notes.append(f"u_m = {u_m:.4g} m from the system's scale (0.5 % of the mean bar length; "
                     "set [control] u_m in the file or --u-m)")
    elif u_m is None:
        u_m = w.u_m
    plant = deployed_plant(system, membrane_modes=membrane_modes)
    if alpha is None and w.alpha is None:
        alpha = default_alpha(plant)
        notes.append(f"alpha_1 = {alpha:.4g} 1/s from the system's scale (0.1 x 2 pi f_1, f_1 = "
                     f"{np.min(plant.frequencies_hz):.4g} Hz the lowest open-loop frequency; set "
                     "[control] alpha in the file or --alpha)")
    elif alpha is None:
        alpha = w.alpha
    kw = {} if pbh_tol is None else {"tol": pbh_tol}
    res = pbh_ss(plant.ss, **kw)
    gen = generalized_plant(plant, u_m=u_m, W_e=w.W_e, W_d=w.W_d)
    hidden = tuple(res.eigenvalues[res.controllability_margin <= res.tol])
    listed = ", ".join(f"{f:.4g} Hz" for f in mode_frequencies_hz(hidden))
    if synthesize and hidden and uncontrollable == "refuse" and np.max(np.real(hidden)) > -alpha:
        raise InfeasibleController(
            f"{system.name}: the modes at {listed} are not reached by any tendon (PBH margin <= "
            f"{res.tol:g}, eq. 5.71), so no controller places them left of -alpha_1 = -{alpha:.4g}; "
            "design without them (option --exclude-uncontrollable of `tmfem control hinf`, `deploy` "
            "and `report`, or uncontrollable = \"exclude\" in the file's [control] table: they stay "
            "open loop, neither damped nor excited by the controller) or change the actuation")
    if uncontrollable == "exclude" and hidden:
        gen = _without(gen, hidden, tol=res.tol)
        notes.append(f"modes no tendon reaches (PBH margin <= {res.tol:g}) left out of the design: {listed}; "
                     "no input excites them, and in closed loop they keep their open-loop (undamped) dynamics")
    design = None
    if synthesize:
        if method == "auto":
            syn = hinfsyn(gen, gen.C2.shape[0], gen.B2.shape[1], alpha=alpha, solver=solver or "CLARABEL")
            design = syn.design
            design.operating_point = dict(plant.operating_point)
            design.info["route"] = {k: syn.info[k] for k in ("method", "route_reason", "feedthrough_bound",
                                                             "feedthrough_sets_gamma", "solver_times_s")}
        elif method == "lmi":
            design = hinf_lmi(gen, alpha=alpha, solver=solver or DEFAULT_SOLVER,
                              operating_point=plant.operating_point)
        elif method == "central":
            design = hinf_central(gen, alpha=alpha, operating_point=plant.operating_point)
        else:
            design = hinf_slicot(gen, alpha=alpha, operating_point=plant.operating_point)
    return DeployedDesign(plant=plant, generalized=gen, pbh=res, design=design, u_m=float(u_m),
                          notes=tuple(notes), excluded_modes=hidden if uncontrollable == "exclude" else ())


def with_uncontrollable(system, choice: str):
    """``system`` with ``[control] uncontrollable = choice`` (``"refuse"`` or ``"exclude"``,
    :func:`deployed_hinf`)."""
    import dataclasses
    if choice not in UNCONTROLLABLE:
        raise InputError(f"uncontrollable: expected one of {list(UNCONTROLLABLE)}, found {choice!r}")
    pr = system.problem
    return system.replace(problem=dataclasses.replace(
        pr, control=dataclasses.replace(pr.control, uncontrollable=choice)))


def mode_frequencies_hz(modes) -> list:
    """|lambda| / 2 pi [Hz] of the eigenvalues ``modes`` with Im >= 0 (one per complex pair),
    ascending."""
    return sorted(float(abs(m) / (2 * np.pi)) for m in modes if m.imag >= 0)


def _without(gen: GeneralizedPlant, hidden: tuple, *, tol: float) -> GeneralizedPlant:
    """``gen`` without the ``hidden`` modes (uncontrollable from u by PBH): its reachable part,
    which must have dropped exactly as many states (else an exogenous input drives one of
    them, and it cannot be left out)."""
    reduced = gen.reachable_part(tol=tol)
    dropped = gen.A.shape[0] - reduced.A.shape[0]
    if dropped != len(hidden):
        raise InputError(f"uncontrollable modes: expected the {len(hidden)} modes no tendon reaches to be "
                         f"out of reach of every input, found {dropped} states removed by the "
                         "controllable staircase of (A, [B1 B2]): an exogenous input drives them, so "
                         "they cannot be left out of the design")
    return reduced


def default_alpha(plant: DeployedPlant) -> float:
    """alpha_1 of eq. 5.66 [1/s] when the file gives none: the system's own scale, 0.1 x 2 pi
    f_1 with f_1 the lowest open-loop natural frequency of the deployed plant [Hz] (a decay
    rate of a tenth of the slowest mode's angular frequency; 7.4's 0.5, 0.4, 0.4 for 1-4(D),
    1-6(D), 2-3 are 0.07-0.14 of theirs: f_1 = 1.07, 0.46, 0.56 Hz)."""
    f = np.asarray(plant.frequencies_hz, dtype=float)
    f = f[np.isfinite(f) & (f > 0)]
    if f.size == 0:
        raise InputError(f"alpha_1: the deployed plant of {plant.model.system.name} has no positive "
                         "natural frequency to scale it with; expected --alpha (or [control] alpha)")
    return float(0.1 * 2 * np.pi * f.min())


def save_design(design: HinfDesign, path) -> None:
    """Write plant (A, B1, B2, C1, C2, D11, D12, D21, D22), controller (Ak, Bk, Ck, Dk),
    gamma, alpha, signal names and the operating point to an ``.npz`` (docs/guides/control.md)."""
    P, K = design.plant, design.controller
    op = design.operating_point
    np.savez(path, A=P.A, B1=P.B1, B2=P.B2, C1=P.C1, C2=P.C2, D11=P.D11, D12=P.D12, D21=P.D21,
             D22=P.D22, Ak=K.A, Bk=K.B, Ck=K.C, Dk=K.D, gamma=design.gamma, alpha=design.alpha,
             state_names=np.array(P.state_names), w_names=np.array(P.w_names),
             u_names=np.array(P.u_names), p_names=np.array(P.p_names),
             y_names=np.array(P.y_names),
             q_e=np.asarray(op.get("q_e", [])), u_e=np.asarray(op.get("u_e", [])),
             z_e=np.asarray(op.get("z_e", [])))


def load_design(path) -> tuple:
    """Read an ``.npz`` of :func:`save_design`: (GeneralizedPlant, controller StateSpace, data)."""
    import control
    from tmfem.io.npz import read_npz
    f = read_npz(path, expected="an .npz design file written by `tmfem control hinf --save`")
    need = ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22", "Ak", "Bk", "Ck", "Dk")
    missing = [k for k in need if k not in f]
    if missing:
        raise InputError(f"design file {path}: expected arrays {need}, missing {missing}")
    names = {k: [str(s) for s in f[k]] for k in ("state_names", "w_names", "u_names", "p_names", "y_names")}
    P = GeneralizedPlant(**{k: f[k] for k in need[:9]}, **names)
    K = control.ss(f["Ak"], f["Bk"], f["Ck"], f["Dk"], inputs=names["y_names"],
                   outputs=names["u_names"], name="K")
    data = {k: f[k] for k in f.files if k not in need}
    return P, K, data


def recheck(path) -> dict:
    """Re-verify a saved design: closed-loop poles and H-infinity norm against its gamma."""
    P, K, data = load_design(path)
    T, nrm, re = verify(P, K, gamma=float(data["gamma"]), alpha=float(data["alpha"]))
    return {"gamma": float(data["gamma"]), "alpha": float(data["alpha"]),
            "closed_loop_hinf_norm": nrm, "closed_loop_max_real_part": re}
