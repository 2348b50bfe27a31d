"""Size, memory and CPU time of the LPV syntheses' SDPs (:func:`tmfem.control.lpv.lpvsyn` and the
conic program of :mod:`tmfem.control.lpv.synthesis`), before they are built.

The gridded LMIs (:mod:`tmfem.control.lpv.gridded_synthesis`) are one semidefinite cone per
design point and rate vertex, of order d = n + nw + np (state feedback) or 2 n + nw + np
(output feedback), and per design point the positivity and (in the back-off re-solve) the
bound cones: state feedback P (n), P <= b I (n), [[b I, Q], [Q^T, b I]] (nu + n); output
feedback [[Y - t I, I], [I, X]] (2 n), X <= b I, Y <= b I (n each). An interior-point solver
(Clarabel) keeps for every cone of order d its Nesterov-Todd scaling as a dense block of
t^2 entries, t = d (d + 1) / 2, in the KKT matrix and its factor, and cvxpy's canonicalisation
holds the cones' vectorised maps besides, so the memory grows as

    bytes = BASE_BYTES + BYTES_PER_SCALING_ENTRY sum_cones t^2

(:data:`BYTES_PER_SCALING_ENTRY` measured, see there). The first-order SCS keeps no scaling
blocks; its memory is the factor of its KKT matrix, dense in the variables (every LMI involves
all of them), ``SCS_BYTES_PER_VARIABLE_PAIR nvar^2``. Both solvers' programs are built as
sparse maps of :func:`conic_nonzeros` entries (one triangle of A P, B2 Q, C1 P, D12 Q per LMI
and basis function: n^3 + n^2 nu + np n^2 + np n nu), :data:`BYTES_PER_NONZERO` each. The
time of either solver grows as the cube of the variables (the dense factorisation in every
iteration): ``SECONDS_PER_VARIABLE_CUBED nvar^3`` CPU seconds for the conic program of
:mod:`tmfem.control.lpv.synthesis`, ``LPVSYN_SECONDS_PER_VARIABLE_CUBED nvar^3`` for
lpvsyn's (both measured, see there). Decision variables
(basis functions n_L of the Lyapunov matrices, n_G of the gains): state feedback n_L n (n +
1) / 2 + n_G nu n; output feedback (X constant with ``constant="X"``, Y with ``"Y"``) n_X n (n
+ 1) / 2 + n_Y n (n + 1) / 2 + n_G (n^2 + n ny + nu n + nu ny), plus gamma.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from tmfem.errors import ResourceLimit
from tmfem.resources import BASE_BYTES, MAX_SYNTHESIS_S, MEMORY_FRACTION, machine_memory, memory_limit

#: Peak resident memory per entry of the cones' dense scaling blocks (module docstring),
#: measured with random plants (benchmarks/bench_lpvsyn.py --states N --feedback state --basis
#: trigonometric --points 7, 2 shared cores): n = 20 (2.8e6 entries) 0.63 GB, n = 40
#: (3.2e7 entries) 5.1 GB and still in the gamma minimisation at 300 s: 117 and 151 bytes
#: per entry above the interpreter's base
BYTES_PER_SCALING_ENTRY = 160.0
#: CPU seconds per cubed decision variable of the conic solve, measured with Clarabel on
#: random state-feedback plants on a 2 x 2 grid with 4 rate vertices (benchmarks/bench_lpvsyn.py
#: --conic-states 8 16 24, 2 shared cores): 157 variables 0.25 s, 601: 14.8 s, 1333: 201 s
#: (6.5e-8, 6.8e-8, 8.5e-8 s nvar^-3); SCS at its tolerance 1e-7 took 4.5 s and 13 s at the
#: first two and over 300 s at the third, so for SCS this is a lower bound
SECONDS_PER_VARIABLE_CUBED = 8.5e-8
#: The same for :func:`~tmfem.control.lpv.gridded_synthesis.lpvsyn`'s SDP route (cvxpy's
#: canonicalisation, the gamma minimisation and the back-off re-solve), measured with
#: benchmarks/bench_lpvsyn.py --states 8 12 16 --points 7 --feedback state --basis
#: trigonometric --refine 1: 157 variables 1.2 s, 307: 3.8 s, 505: 28 s of CPU (3.1e-7,
#: 1.3e-7, 2.2e-7 s nvar^-3; the smallest is dominated by fixed costs)
LPVSYN_SECONDS_PER_VARIABLE_CUBED = 2.2e-7
#: Bytes per pair of decision variables of SCS's KKT factor (module docstring): the lower
#: triangle of a dense nvar x nvar block, 8 bytes an entry
SCS_BYTES_PER_VARIABLE_PAIR = 4.0
#: Peak bytes per nonzero of the conic program's sparse maps (the Kronecker products, their
#: sums and the solver's copy), measured with SCS (benchmarks/bench_lpvsyn.py --conic-states):
#: 368,640 nonzeros (n = 16) 0.097 GB, 720,000 (n = 20) 0.20 GB above the interpreter: 263
#: and 278 bytes
BYTES_PER_NONZERO = 300.0


@dataclass
class LPVSynCost:
    """What :func:`lpvsyn_cost` estimates: decision variables, the gridded LMIs (count and
    order), all semidefinite cones' orders and the interior-point memory in bytes."""

    decision_variables: int
    lmis: int
    lmi_size: int
    cone_orders: list
    memory_bytes: float
    seconds: float

    def to_dict(self) -> dict:
        return {"decision_variables": self.decision_variables, "lmis": self.lmis, "lmi_size": self.lmi_size,
                "cones": len(self.cone_orders), "memory_gib": self.memory_bytes / 2**30,
                "cpu_seconds": self.seconds}

    @property
    def text(self) -> str:
        """The estimate in one line: sizes, memory and CPU time."""
        return (f"{self.lmis} LMIs of order {self.lmi_size}, {len(self.cone_orders)} cones, "
                f"{self.decision_variables:,} variables: about {self.memory_bytes / 2**30:.2f} GiB and "
                f"{_duration(self.seconds)} of CPU")


def _duration(seconds: float) -> str:
    """``seconds`` in the largest unit that keeps it readable."""
    for unit, size in (("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"


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
                      memory_bytes=mem, seconds=LPVSYN_SECONDS_PER_VARIABLE_CUBED * float(nvar + 1) ** 3)


def conic_cost(sizes: dict, *, solver: str) -> LPVSynCost:
    """The cost of :func:`~tmfem.control.lpv.synthesis.synthesize_state_feedback`'s conic
    program from its ``sizes`` (:class:`~tmfem.control.lpv.coordinates.Coordinates`): the
    state-feedback SDP of :func:`lpvsyn_cost` with the affine basis (one coefficient matrix
    per varying parameter besides the constant one); with SCS the memory of its KKT factor
    (module docstring)."""
    n, nu = sizes["n_x"], sizes["n_u"]
    bases = (sizes["decision_variables"] - 1) // (n * (n + 1) // 2 + nu * n)
    c = lpvsyn_cost(n=n, nw=sizes["n_w"], np_=sizes["n_p"], nu=nu, ny=0, points=sizes["grid_points"],
                    vertices=sizes["rate_vertices"], lyapunov_basis=bases, gain_basis=bases)
    build = BYTES_PER_NONZERO * conic_nonzeros(n=n, nu=nu, np_=sizes["n_p"], lmis=c.lmis, bases=bases)
    c = replace(c, seconds=SECONDS_PER_VARIABLE_CUBED * float(c.decision_variables) ** 3)
    if solver == "SCS":
        return replace(c, memory_bytes=BASE_BYTES + build
                       + SCS_BYTES_PER_VARIABLE_PAIR * float(c.decision_variables) ** 2)
    return replace(c, memory_bytes=c.memory_bytes + build)


def conic_nonzeros(*, n: int, nu: int, np_: int, lmis: int, bases: int) -> float:
    """Nonzeros of the conic program's LMI maps (module docstring)."""
    return float(lmis) * bases * (n**3 + n * n * nu + np_ * n * n + np_ * n * nu)


def check_lpvsyn_cost(cost: LPVSynCost, *, what: str, time_limit: float = MAX_SYNTHESIS_S,
                      lifted_by: str = "") -> LPVSynCost:
    """Refuse an SDP whose memory estimate exceeds :func:`tmfem.resources.memory_limit` or
    whose time estimate exceeds ``time_limit`` CPU seconds (default the H-infinity synthesis'
    :data:`tmfem.resources.MAX_SYNTHESIS_S`): :class:`tmfem.errors.ResourceLimit` naming the
    sizes, the estimate and ``lifted_by``, the option that raises the time limit; ``what``
    names the problem."""
    over = []
    if cost.memory_bytes > memory_limit():
        over.append(f"the memory limit {memory_limit() / 2**30:.1f} GiB ({MEMORY_FRACTION:.0%} of this "
                    f"machine's {machine_memory() / 2**30:.0f} GiB)")
    if cost.seconds > time_limit:
        over.append(f"the time limit {time_limit:g} CPU s" + (f" ({lifted_by} raises it)" if lifted_by else ""))
    if over:
        raise ResourceLimit(f"{what}: the SDP ({cost.text}) exceeds " + " and ".join(over))
    return cost
