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

from tmfem.control.linear.hinf_lmi import GeneralizedPlant, HinfDesign, hinf_lmi, hinf_riccati, verify
from tmfem.control.linear.hinf_central import hinf_central
from tmfem.control.linear.pbh import PBHResult, pbh_ss
from tmfem.control.linear.generalized_plant import DEPLOYED, DeployedPlant, deployed_plant, generalized_plant
from tmfem.errors import InputError

log = logging.getLogger(__name__)

#: synthesis methods of :func:`deployed_hinf`
METHODS = ("lmi", "riccati", "central")


@dataclass
class DeployedDesign:
    """A deployed system's plant, PBH verdicts and H-infinity design."""

    plant: DeployedPlant
    generalized: GeneralizedPlant
    pbh: PBHResult
    design: HinfDesign | None
    u_m: float

    def summary(self) -> dict:
        out = {"system": self.plant.model.system.name,
               "open_loop_f_max_hz": self.plant.f_max_hz,
               "open_loop_f_max_printed_hz": DEPLOYED.get(self.plant.model.system.name, {}).get("f_max_hz"),
               "n_states": int(self.plant.ss.nstates), "n_inputs": int(self.plant.ss.ninputs),
               "membrane_points": [list(p) for p in self.plant.points],
               "u_m": self.u_m, "pbh": self.pbh.as_dict()}
        if self.design is not None:
            d = self.design.summary()
            out.update({"gamma": d["gamma"], "alpha": d["alpha"],
                        "closed_loop_max_real_part": d["closed_loop_max_real_part"],
                        "closed_loop_hinf_norm": d["closed_loop_hinf_norm"],
                        "controller_order": d["controller_order"], "method": d["kind"],
                        "cond_I_minus_RS": d["cond_I_minus_RS"], "solver": d["solver"]})
        return out


def deployed_hinf(system, *, alpha: float | None = None, u_m: float | None = None,
                  membrane_modes: int | None = None, solver: str = "ARE",
                  synthesize: bool = True, pbh_tol: float | None = None,
                  method: str = "lmi") -> DeployedDesign:
    """Plant, PBH and H-infinity controller of a deployed system (7.3-7.4).

    Parameters
    ----------
    alpha, u_m, membrane_modes : optional
        alpha_1, u_m of W_u = I/u_m, and K; defaults: 7.4's values for the system
        (:data:`tmfem.control.linear.generalized_plant.DEPLOYED`), required for other systems.
    solver : {"ARE", "CLARABEL", "SCS"}
        How the eliminated LMIs are solved (:func:`~tmfem.control.linear.hinf_lmi.hinf_lmi`); default
        their Riccati characterisation (the plants of Fig. 7.1 are regular: D12 = [0; W_u],
        D21 = [-[I; 0], W_d I]), 0.3-3 s for the three systems against 3 s, 30 s and a
        failure with Clarabel (docs/control.md).
    synthesize : bool
        False: plant and PBH only (``tmfem control pbh``).
    method : {"lmi", "riccati", "central"}
        Eliminated LMIs (:func:`~tmfem.control.linear.hinf_lmi.hinf_lmi`), the Riccati route on the
        alpha-shifted plant (:func:`~tmfem.control.linear.hinf_lmi.hinf_riccati`) or the central
        (minimum-entropy) controller at 1.01 gamma_opt
        (:func:`~tmfem.control.linear.hinf_central.hinf_central`: solver-independent; the default
        of the deployments, docs/control.md).
    """
    if method not in METHODS:
        raise InputError(f"method: expected one of {METHODS}, found {method!r}")
    d = DEPLOYED.get(system.name, {})
    alpha = d.get("alpha") if alpha is None else alpha
    u_m = d.get("u_m") if u_m is None else u_m
    if synthesize and (alpha is None or u_m is None):
        raise InputError(f"system {system.name!r} has no 7.4 defaults: expected alpha and u_m, "
                         f"found alpha = {alpha}, u_m = {u_m}")
    plant = deployed_plant(system, membrane_modes=membrane_modes)
    kw = {} if pbh_tol is None else {"tol": pbh_tol}
    res = pbh_ss(plant.ss, **kw)
    gen = generalized_plant(plant, u_m=u_m if u_m is not None else 1.0)
    design = None
    if synthesize:
        if method == "lmi":
            design = hinf_lmi(gen, alpha=alpha, solver=solver, operating_point=plant.operating_point)
        elif method == "central":
            design = hinf_central(gen, alpha=alpha, operating_point=plant.operating_point)
        else:
            design = hinf_riccati(gen, alpha=alpha, operating_point=plant.operating_point)
    return DeployedDesign(plant=plant, generalized=gen, pbh=res, design=design,
                          u_m=float(u_m) if u_m is not None else None)


def save_design(design: HinfDesign, path) -> None:
    """Write plant (A, B1, B2, C1, C2, D11, D12, D21, D22), controller (Ak, Bk, Ck, Dk),
    gamma, alpha, signal names and the operating point to an ``.npz`` (docs/control.md)."""
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
