"""Cost estimates of the inputs that scale the work, checked before anything is built.

Every input whose size drives memory or run time -- the stages and bars of a system and its
tendons (the equilibrium design's dense matrices), the membrane mesh and the members' elements
(the finite-element models' DOFs), the control-oriented model's membrane modes -- has an
estimate here. A job over the limit raises :class:`tmfem.errors.ResourceLimit` (exit 3) whose
message names the input, the estimate and the limit (docs/guides/cli.md, "Limits"). The limit is
:data:`MEMORY_FRACTION` of the machine's physical memory: the machines are shared.
"""
from __future__ import annotations

import math
import os

from tmfem.errors import InputError, ResourceLimit

MEMORY_FRACTION = 0.6         # of the physical memory: the machine is shared

# Measured on the 1-4 MTC model (modal, 12 modes): peak RSS grows by ~8-11 kB per free
# DOF from n = 20 (5 067 DOFs, 0.17 GB) to n = 80 (78 000 DOFs, 0.81 GB); 16 kB leaves
# room for the fill of larger factorisations. Base: the interpreter with numpy/scipy/VTK.
BYTES_PER_DOF = 16e3
BASE_BYTES = 0.3e9
#: The PETSc backend on one rank, by the model's DOFs per membrane node (the estimate's DOFs,
#: :func:`mesh_dofs`). 3, the MTC membrane (benchmarks/bench_memory_ranks.py, 1-4 static +
#: 12 modes): the peak grows by 4.1 / 3.9 / 3.9 kB per DOF above the start-up at 78k / 309k /
#: 1.23 M DOFs; 6 kB leaves room for the fill of larger factorisations. 6, the SBC shells
#: (`tmfem modal --model sbc --preset 1-4 --mesh n --backend petsc`, peak RSS): 0.50 / 1.48 /
#: 3.14 GB at n = 30 / 60 / 90, 15 kB per DOF; 20 kB leaves room.
PETSC_BYTES_PER_DOF = {3: 6e3, 6: 20e3}
#: Under mpiexec every rank holds the mesh and the state whole (~0.2 kB per DOF, measured
#: at 309k DOFs) beside its share of the rest.
RANK_WHOLE_BYTES_PER_DOF = 0.2e3

#: Largest K of the control-oriented model: its equations are built symbolically (CasADi)
#: at a cost that grows faster than K^2 (1-4, measured under load: K = 10: 8 s, 20: 9 s,
#: 40: 24 s; K = 1000 would run for hours).
MAX_MEMBRANE_MODES = 40


def machine_memory() -> float:
    """Physical memory of this machine in bytes (24 GiB on the project's machines)."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):     # pragma: no cover - non-POSIX
        return 24.0 * 2**30


def memory_limit() -> float:
    """Bytes a job may use: :data:`MEMORY_FRACTION` of :func:`machine_memory`."""
    return MEMORY_FRACTION * machine_memory()


def require_memory(need: float, *, given: str, what: str) -> float:
    """Refuse ``need`` bytes over :func:`memory_limit`: ``given`` names the input (an option
    or a file's field), ``what`` says what it builds. Returns ``need``."""
    limit = memory_limit()
    if need > limit:
        raise ResourceLimit(f"{given}: {what} needs about {need / 2**30:.1f} GiB; the limit is "
                            f"{limit / 2**30:.1f} GiB ({MEMORY_FRACTION:.0%} of this machine's "
                            f"{machine_memory() / 2**30:.0f} GiB)")
    return need


def fe_bytes(dofs: int, *, backend: str = "scipy", ranks: int = 1,
             ranks_here: int | None = None, dofs_per_node: int = 3) -> float:
    """Peak memory [bytes] on this machine of a finite-element model of ``dofs`` DOFs
    (``dofs_per_node`` per membrane node) solved with ``backend`` (``"scipy"`` or
    ``"petsc"``) on ``ranks`` MPI ranks, ``ranks_here`` of them on this machine (default
    all):

        scipy:  BASE_BYTES + BYTES_PER_DOF dofs
        petsc:  P_h (BASE_BYTES + w dofs) + b dofs (P_h / P) (1 + 0.15 log2 P)

    with b = :data:`PETSC_BYTES_PER_DOF` of ``dofs_per_node`` (the largest for another
    count) and w = :data:`RANK_WHOLE_BYTES_PER_DOF` for P > 1 (0 on one rank): each rank's
    start-up and what it holds whole, and its share of what divides, the busiest rank's
    share growing with P (MUMPS' fronts divide unevenly: on 2 ranks the busiest holds
    1.15-1.2 x half, on 8 ranks 0.18 of the factor entries against 1/8)."""
    if backend != "petsc":
        return BASE_BYTES + BYTES_PER_DOF * dofs
    P = max(1, int(ranks))
    here = P if ranks_here is None else min(P, max(1, int(ranks_here)))
    whole = RANK_WHOLE_BYTES_PER_DOF * dofs if P > 1 else 0.0
    per_dof = PETSC_BYTES_PER_DOF.get(dofs_per_node, max(PETSC_BYTES_PER_DOF.values()))
    share = per_dof * dofs * (here / P) * (1.0 + 0.15 * math.log2(P))
    return here * (BASE_BYTES + whole) + share


def mesh_dofs(*, N: int, n: int, dofs_per_node: int = 3, extra_dofs: int = 0) -> int:
    """DOFs of N n x n quadrilateral membrane patches (about N (n + 1)^2 nodes) with
    ``dofs_per_node`` unknowns each, plus ``extra_dofs`` (members)."""
    return dofs_per_node * N * (n + 1) ** 2 + int(extra_dofs)


def check_mesh_budget(*, N: int, n: int, option: str = "--mesh", dofs_per_node: int = 3,
                      extra_dofs: int = 0, extra_text: str = "", plan=None) -> int:
    """Refuse a membrane mesh whose FE model would not fit this machine.

    The DOFs are :func:`mesh_dofs`; the estimated peak memory, :func:`fe_bytes` of the
    backend that will solve it, must stay under :func:`memory_limit`. ``plan``: None (the
    scipy estimate) or a callable ``plan(dofs) -> (backend, ranks, ranks_here)``.
    Returns the DOF estimate.

    Raises
    ------
    ResourceLimit
        with the estimate and the limit.
    """
    dofs = mesh_dofs(N=N, n=n, dofs_per_node=dofs_per_node, extra_dofs=extra_dofs)
    given = option if " " in option else f"{option} {n}"    # "--mesh n ..." or the flag
    name, ranks, here = ("scipy", 1, 1) if plan is None else plan(dofs)
    on = "" if name != "petsc" else (" with the PETSc backend" if ranks == 1 else
                                     f" with the PETSc backend on {ranks} ranks ({here} here)")
    require_memory(fe_bytes(dofs, backend=name, ranks=ranks, ranks_here=here,
                            dofs_per_node=dofs_per_node), given=given,
                   what=f"the membrane mesh {N} x {n} x {n}"
                   + (f" with {extra_text}" if extra_text else "") + f" gives about {dofs:,} "
                   f"DOFs and{on}")
    return dofs


def design_bytes(*, M: int, N: int, n_tendons: int, deployable: bool = False) -> float:
    """Peak memory [bytes] of the equilibrium design of an M-N system (ch. 3): the dense node
    Jacobian dX/dq (3 n_nodes x n_q, built from two arrays of the bar ends of the same size,
    eqs. 3.1-3.2) and the full SVD of the n_q x n_t equilibrium matrix A_T (eq. 3.16:
    U n_q^2, V n_t^2 and the scaled copy), 8 bytes each, plus :data:`BASE_BYTES`."""
    n_q = 2 * N + 5 * N * (M - 1)
    n_nodes = 2 * M * N + (N if deployable else 0)
    entries = 3 * (3 * n_nodes * n_q) + n_q**2 + n_tendons**2 + 2 * n_q * n_tendons
    return BASE_BYTES + 8.0 * entries


def check_system_budget(system, *, source: str = "the system") -> float:
    """Refuse a system whose equilibrium design (:func:`design_bytes`) would not fit this
    machine, before anything is built; ``source`` names where it comes from (the file).
    Every command starts from the design, so this bounds the stages, bars per stage and
    tendons of a system file. Returns the estimate in bytes."""
    M, N, nt = system.M, system.N, len(system.tendons)
    stages = f"{M} stage{'s' if M != 1 else ''}"
    return require_memory(design_bytes(M=M, N=N, n_tendons=nt, deployable=system.deployable),
                          given=f"{source}: {stages} x {N} bars, {nt} tendons",
                          what="the equilibrium design (dense node Jacobian and the SVD of "
                               "the equilibrium matrix, eqs. 3.1-3.16)")


def check_membrane_modes(K: int, *, given: str = "--membrane-modes") -> None:
    """Membrane modes K of the control-oriented model: 0 <= K <= :data:`MAX_MEMBRANE_MODES`
    (``given`` names the input: the option or the file's ``[models.com] membrane_modes``)."""
    if not 0 <= K <= MAX_MEMBRANE_MODES:
        cls = ResourceLimit if K > MAX_MEMBRANE_MODES else InputError
        raise cls(f"{given} {K}: expected 0 <= K <= {MAX_MEMBRANE_MODES} (the model's "
                  f"equations are built symbolically; K = 40 takes ~25 s, the cost grows faster "
                  f"than K^2)")



#: CPU seconds of the control-oriented model's set-up (the constraint solver, the membrane
#: basis and the CasADi graphs of eqs. 5.19-5.34, built symbolically) with n_q coordinates and
#: K membrane modes: ``t0 + a n_q^p + b K^2`` (t0, a, p, b), the least-squares fit of
#: benchmarks/bench_com_setup.py (towers of 2 to 128 stages of three bars, n_q 21 to 1911, K
#: 4 to 40; 128 stages: 25 s).
COM_SETUP_FIT = (0.59, 1.26e-4, 1.613, 2.23e-3)
#: Peak memory of the same set-up over :data:`BASE_BYTES`: ``c n_q^2 + d K^2`` bytes (c, d),
#: rounded up from the same measurements (n_q = 1911: 1.29 GB; K = 40: +0.25 GB).
COM_MEMORY_FIT = (300.0, 1.5e5)
#: Longest set-up of the control-oriented model a command starts [CPU s]: about 340 stages of
#: three bars (docs/guides/cli.md, "Limits").
MAX_COM_SETUP_S = 120.0


def com_setup_seconds(*, n_q: int, K: int) -> float:
    """CPU seconds to set up the control-oriented model (:data:`COM_SETUP_FIT`)."""
    t0, a, p, b = COM_SETUP_FIT
    return t0 + a * float(n_q) ** p + b * float(K) ** 2


def com_setup_bytes(*, n_q: int, K: int) -> float:
    """Peak memory [bytes] of that set-up: :data:`BASE_BYTES` + :data:`COM_MEMORY_FIT`."""
    c, d = COM_MEMORY_FIT
    return BASE_BYTES + c * float(n_q) ** 2 + d * float(K) ** 2


def check_com_budget(system, *, K: int, source: str = "") -> float:
    """Refuse a control-oriented model whose set-up would exceed :data:`MAX_COM_SETUP_S` or
    the memory limit, before anything is built; the message names the stages, bars and
    coordinates, the membrane modes K (:func:`check_membrane_modes`) and the estimate.
    ``source`` names the system (default its name). Returns the time estimate [CPU s]."""
    check_membrane_modes(K, given="membrane_modes")
    M, N, n_q = system.M, system.N, len(system.q_names)
    given = (f"{source or system.name}: {M} stage{'s' if M != 1 else ''} x {N} bars ({n_q} "
             f"coordinates q), membrane_modes {K}")
    what = "the control-oriented model's set-up (symbolic equations of motion, eqs. 5.19-5.34)"
    require_memory(com_setup_bytes(n_q=n_q, K=K), given=given, what=what)
    t = com_setup_seconds(n_q=n_q, K=K)
    if t > MAX_COM_SETUP_S:
        raise ResourceLimit(f"{given}: {what} takes about {t:.0f} s of CPU; the limit is "
                            f"{MAX_COM_SETUP_S:.0f} s")
    return t


#: CPU seconds of :func:`tmfem.control.linear.hinf_synthesis.hinfsyn` by route for a plant of
#: n states: the Riccati bisection ``a n^3`` (dense Hamiltonian Schur forms of size 2n at every
#: level; measured 5 s at n = 100, 19 s at n = 200) and the LMI route ``b (n / 20)^5.5`` (an
#: SDP in X, Y of n(n + 1)/2 unknowns each; measured 2.2 s at n = 20, 100 s at n = 40).
SYNTHESIS_FIT = {"riccati": 5e-6, "lmi": 2.2}
#: Peak memory of the LMI route over :data:`BASE_BYTES`: ``c n^4`` bytes (the interior-point
#: solver's dense Schur complement in the unknowns; measured 0.93 GB at n = 40).
LMI_BYTES_PER_N4 = 500.0
#: Longest H-infinity synthesis a call starts [CPU s] (docs/guides/cli.md, "Limits").
MAX_SYNTHESIS_S = 3600.0


def synthesis_seconds(*, route: str, n: int) -> float:
    """CPU seconds of the H-infinity synthesis route ``route`` ("riccati", "slicot": the
    Riccati estimate; "lmi") for a plant of ``n`` states (:data:`SYNTHESIS_FIT`)."""
    if route == "lmi":
        return SYNTHESIS_FIT["lmi"] * (n / 20.0) ** 5.5
    return SYNTHESIS_FIT["riccati"] * float(n) ** 3


def check_synthesis_budget(*, route: str, n: int, given: str = "hinfsyn") -> float:
    """Refuse an H-infinity synthesis whose estimate (:func:`synthesis_seconds`, and the LMI
    route's memory) exceeds :data:`MAX_SYNTHESIS_S` or the memory limit, naming the route and
    the plant's states. Returns the time estimate [CPU s]."""
    where = f"{given}: a plant of {n} states by the {route} route"
    if route == "lmi":
        require_memory(BASE_BYTES + LMI_BYTES_PER_N4 * float(n) ** 4, given=where,
                       what="the LMI synthesis (an SDP in two n x n symmetric unknowns)")
    t = synthesis_seconds(route=route, n=n)
    if t > MAX_SYNTHESIS_S:
        raise ResourceLimit(f"{where} takes about {t:.0f} s of CPU; the limit is "
                            f"{MAX_SYNTHESIS_S:.0f} s (reduce the plant: fewer membrane modes, "
                            "a balanced truncation)")
    return t


def check_lpv_budget(*, design_points: int, verify_points: int, vertices: int, n: int, m: int,
                     p: int, given: str = "lpvsyn") -> float:
    """Refuse a gridded LPV synthesis whose plant data and LMIs cannot fit the memory limit:
    the plant's matrices ((n + p) x (n + m)) at every design and verification point, and one
    dense LMI of size 2n + m + p per design point and rate vertex, three copies each (the
    problem, the solver's scaling and its factor), 8 bytes an entry. A lower bound of the
    solver's needs; it bounds the grid a call may ask for. Returns the estimate in bytes."""
    s = 2 * n + m + p
    need = BASE_BYTES + 8.0 * ((n + p) * (n + m) * (design_points + verify_points)
                               + 3.0 * s * s * design_points * vertices)
    return require_memory(need, given=f"{given}: {design_points:,} design points x {vertices} rate "
                                      f"vertices, {verify_points:,} verification points, a plant of "
                                      f"{n} states",
                          what="the gridded plant and its LMIs")
