"""Size and memory of the interior-point SDP of :func:`tmfem.control.lpv.lpvsyn`, before it is built.

The gridded LMIs (:mod:`tmfem.control.lpv.gridded_synthesis`) are one semidefinite cone per
design point and rate vertex, of order d = n + nw + np (state feedback) or 2 n + nw + np
(output feedback), and per design point the positivity and (in the back-off re-solve) the
bound cones: state feedback P (n), P <= b I (n), [[b I, Q], [Q^T, b I]] (nu + n); output
feedback [[Y - t I, I], [I, X]] (2 n), X <= b I, Y <= b I (n each). An interior-point solver
(Clarabel) keeps for every cone of order d its Nesterov-Todd scaling as a dense block of
t^2 entries, t = d (d + 1) / 2, in the KKT matrix and its factor, and cvxpy's canonicalisation
holds the cones' vectorised maps besides, so the memory grows as

    bytes = BASE_BYTES + BYTES_PER_SCALING_ENTRY sum_cones t^2

(:data:`BYTES_PER_SCALING_ENTRY` measured, see there). Decision variables
(basis functions n_L of the Lyapunov matrices, n_G of the gains): state feedback n_L n (n +
1) / 2 + n_G nu n; output feedback (X constant with ``constant="X"``, Y with ``"Y"``) n_X n (n
+ 1) / 2 + n_Y n (n + 1) / 2 + n_G (n^2 + n ny + nu n + nu ny), plus gamma.
"""
from __future__ import annotations

from dataclasses import dataclass

from tmfem.resources import BASE_BYTES, require_memory

#: Peak resident memory per entry of the cones' dense scaling blocks (module docstring),
#: measured with random plants (benchmarks/bench_lpvsyn.py --states N --feedback state --basis
#: trigonometric --points 7, 2 shared cores): n = 20 (2.8e6 entries) 0.63 GB, n = 40
#: (3.2e7 entries) 5.1 GB and still in the gamma minimisation at 300 s: 117 and 151 bytes
#: per entry above the interpreter's base
BYTES_PER_SCALING_ENTRY = 160.0


@dataclass
class LPVSynCost:
    """What :func:`lpvsyn_cost` estimates: decision variables, the gridded LMIs (count and
    order), all semidefinite cones' orders and the interior-point memory in bytes."""

    decision_variables: int
    lmis: int
    lmi_size: int
    cone_orders: list
    memory_bytes: float

    def to_dict(self) -> dict:
        return {"decision_variables": self.decision_variables, "lmis": self.lmis, "lmi_size": self.lmi_size,
                "cones": len(self.cone_orders), "memory_gib": self.memory_bytes / 2**30}


def lpvsyn_cost(*, n: int, nw: int, np_: int, nu: int, ny: int, points: int, vertices: int,
                lyapunov_basis: int, gain_basis: int, constant: str | None = "X") -> LPVSynCost:
    """The size of :func:`~tmfem.control.lpv.gridded_synthesis.lpvsyn`'s SDP (module
    docstring); ``ny = 0`` is state feedback."""
    tri = n * (n + 1) // 2
    if ny == 0:
        nvar = lyapunov_basis * tri + gain_basis * nu * n
        d = n + nw + np_
        per_point = [n, n, nu + n]
    else:
        n_x = 1 if constant == "X" else lyapunov_basis
        n_y = 1 if constant == "Y" else lyapunov_basis
        nvar = (n_x + n_y) * tri + gain_basis * (n * n + n * ny + nu * n + nu * ny)
        d = 2 * n + nw + np_
        per_point = [2 * n, n, n]
    cones = [d] * (points * vertices) + per_point * points
    mem = BASE_BYTES + BYTES_PER_SCALING_ENTRY * sum((k * (k + 1) / 2) ** 2 for k in cones)
    return LPVSynCost(decision_variables=nvar + 1, lmis=points * vertices, lmi_size=d, cone_orders=cones,
                      memory_bytes=mem)


def check_lpvsyn_cost(cost: LPVSynCost, *, what: str) -> LPVSynCost:
    """Refuse an SDP whose memory estimate exceeds :func:`tmfem.resources.memory_limit`
    (:class:`tmfem.errors.ResourceLimit` naming the sizes); ``what`` names the problem."""
    require_memory(cost.memory_bytes, given=what,
                   what=f"the interior-point SDP ({cost.lmis} LMIs of order {cost.lmi_size}, "
                        f"{len(cost.cone_orders)} cones, {cost.decision_variables:,} variables)")
    return cost
