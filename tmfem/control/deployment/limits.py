"""Rest-length limits of a deployment (dissertation 7.4): r_min <= r <= |tendon|(q).

A tendon cannot push: its rest length may not exceed its current length, and it stays
positive ("tendon lengths are treated as control limits", 7.4). :func:`tendon_lengths`
evaluates |tendon|(q) (eq. 3.8) by a compiled casadi function of the system's kinematics
(:func:`tmfem.models.com.kinematics.tendon_lengths_sx`), keeping the last evaluation so that
the controller and the saturation of one sample share it. :class:`RestLengthLimits`
saturates every commanded input to [r_min, |tendon|(q)] at each sample, records the samples
where a limit is active (an input saturated or at a bound: a tendon at zero tension) and the
smallest margin |tendon| - r.
"""
from __future__ import annotations

import weakref

import numpy as np

from tmfem.errors import InputError
from tmfem.models.com.graphs import BufferedFunction
from tmfem.models.com.kinematics import tendon_lengths_sx

#: compiled functions by id(system), with a weak reference that identifies the system
_FUNCTIONS: dict = {}


def tendon_lengths(system, q) -> np.ndarray:
    """|d_k|(q) of every tendon (eq. 3.8), in ``system.tendons`` order."""
    q = np.asarray(q, dtype=float)
    entry = _FUNCTIONS.get(id(system))
    if entry is None or entry["system"]() is not system:
        import casadi as ca
        qs = ca.SX.sym("q", q.size)
        f = ca.Function("tendon_lengths", [qs], [ca.densify(tendon_lengths_sx(system, qs))])
        entry = {"f": BufferedFunction(f),
                 "system": weakref.ref(system, lambda _, k=id(system): _FUNCTIONS.pop(k, None)),
                 "q": None, "L": None}
        _FUNCTIONS[id(system)] = entry
    if entry["q"] is None or not np.array_equal(entry["q"], q):
        entry["q"], entry["L"] = q.copy(), entry["f"](q)
    return entry["L"]


class RestLengthLimits:
    """Saturation of a controller's rest lengths to [r_min, |tendon|(q)] (module docstring)."""

    def __init__(self, controller, *, model, r_min: float = 1e-3):
        if not r_min > 0:
            raise InputError(f"r_min: expected > 0, found {r_min!r}")
        self.inner, self.model, self.r_min = controller, model, float(r_min)
        self.active: list = []
        self.margins: list = []

    @property
    def name(self) -> str:
        return self.inner.name

    def reset(self, t0, y0, dt):
        self.active, self.margins = [], []
        return self.inner.reset(t0, y0, dt)

    def output(self, t, y, xc):
        u = np.asarray(self.inner.output(t, y, xc), dtype=float)
        L = tendon_lengths(self.model.system, np.asarray(y)[: self.model.nq])
        us = np.clip(u, self.r_min, L)
        self.active.append((float(t), int(np.sum((us != u) | (us >= L) | (us <= self.r_min)))))
        self.margins.append(float(np.min(L - us)))
        return us

    def update(self, t, y, xc):
        return self.inner.update(t, y, xc)
