"""The same deployment on two plants: their deviation over time.

Both runs record the same named signals at the same sample times (the COM state read from
the plant -- the FE plants through :class:`tmfem.control.fe_plant.state_estimate.FEStatePlant` --,
the membrane deflections w_k its sensors measure, the commanded rest lengths), so they are
compared sample by sample over the common record (a run that stopped early ends it):

    d_q(t) = max_k |q_k^A(t) - q_k^B(t)|,   d_w(t) = max_k |w_k^A(t) - w_k^B(t)|,
    d_u(t) = max_j |u_j^A(t) - u_j^B(t)|,

d_q over the bar angles (theta, psi [rad]) and, apart, over the base positions of the upper
stages (x, y, z [m]; none for a one-stage system): a maximum over both would compare radians
with metres.
"""
from __future__ import annotations

import numpy as np

from tmfem.control.deployment.reference_trajectory import angle_mask
from tmfem.errors import InputError

#: times [s] at which the summary quotes the bar deviation (those within the common record)
QUOTE_TIMES = (0.1, 0.3, 1.0, 2.0, 5.0, 10.0, 20.0)


def plant_deviation(a, b) -> dict:
    """Deviation of deployment run ``b`` from run ``a`` (:class:`DeploymentResult`) over their
    common samples (module docstring): ``t`` [s], ``q`` the bar angles [rad], ``bases`` the
    base positions [m] (NaN without any), ``w`` [m], ``u`` [m]."""
    if a.names.get("q") != b.names.get("q") or a.t.size < 1 or b.t.size < 1:
        raise InputError("plant comparison: expected two runs of one deployment, found "
                         f"coordinates {a.names.get('q')} and {b.names.get('q')}")
    n = min(a.t.size, b.t.size)
    if not np.allclose(a.t[:n], b.t[:n], rtol=0, atol=1e-9):
        raise InputError("plant comparison: expected the same sample times in both runs")
    ang = angle_mask(a.names["q"])
    d = np.abs(a.z[:n, :ang.size] - b.z[:n, :ang.size])
    return {"t": a.t[:n], "q": np.max(d[:, ang], axis=1),
            "bases": np.max(d[:, ~ang], axis=1) if (~ang).any() else np.full(n, np.nan),
            "w": np.max(np.abs(a.w[:n] - b.w[:n]), axis=1) if a.w.size else np.zeros(n),
            "u": np.max(np.abs(a.u[:n] - b.u[:n]), axis=1)}


def deviation_summary(dev: dict) -> dict:
    """JSON figures of :func:`plant_deviation`: the largest bar-angle deviation and when, its
    rms, its value at :data:`QUOTE_TIMES`, the same of the base positions (absent without
    any), the largest w and rest-length deviations, the common record's end."""
    t, dq = dev["t"], dev["q"]
    k = int(np.argmax(dq))
    quote = [(f"{tq:g}", int(round(tq / (t[1] - t[0])))) for tq in QUOTE_TIMES
             if t.size > 1 and tq <= t[-1] + 1e-9]
    out = {"common_record_s": float(t[-1]), "max_bar_deviation_deg": float(np.degrees(dq[k])),
           "max_bar_deviation_time_s": float(t[k]),
           "rms_bar_deviation_deg": float(np.degrees(np.sqrt(np.mean(dq**2)))),
           "bar_deviation_at_times_deg": {s: float(np.degrees(dq[i])) for s, i in quote}}
    db = dev["bases"]
    if np.isfinite(db).all():
        j = int(np.argmax(db))
        out.update({"max_base_deviation_m": float(db[j]), "max_base_deviation_time_s": float(t[j]),
                    "base_deviation_at_times_m": {s: float(db[i]) for s, i in quote}})
    return {**out, "max_membrane_deflection_deviation_m": float(np.max(dev["w"])),
            "max_rest_length_deviation_m": float(np.max(dev["u"]))}
