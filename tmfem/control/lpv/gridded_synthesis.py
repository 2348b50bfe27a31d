"""General gridded LPV H-infinity synthesis: state and output feedback, user basis functions.

Plant (continuous time, D22 = 0), known at every parameter value rho (a vector of n_p
scheduling parameters) and imposed on a rectangular design grid::

    x' = A x + B1 w + B2 u,   p = C1 x + D11 w + D12 u,   y = C2 x + D21 w

with rate bounds rho_k' in [lo_k, hi_k]. Parameter-dependent matrices are expanded in
basis functions, M(rho) = sum_i f_i(rho) M_i (:class:`~tmfem.control.lpv.basis.Basis`), so
dM/dt = sum_i (grad f_i . rho') M_i is affine in the rate and each LMI is imposed at every
design point and every vertex of the rate box (the gridding of Wu 1995; Apkarian & Adams 1998).

**State feedback** u = K(rho) x (dissertation eqs. 5.95-5.96 with a general basis for P and
Q; eq. 5.99 is the affine basis)::

    [[A P + B2 Q + (A P + B2 Q)^T - dP/dt, B1, (C1 P + D12 Q)^T],
     [B1^T, -g I, D11^T], [C1 P + D12 Q, D11, -g I]] < 0,   P(rho) > 0,   K = Q P^-1.

**Output feedback**, the linearising change of controller variables of Scherer, Gahinet &
Chilali (IEEE TAC 42 (1997) 896-911, Sec. IV) with parameter-dependent X(rho), Y(rho) and
their rates: the basic characterisation of Apkarian & Adams (IEEE TCST 6 (1998) 21-32,
Theorem 2.1, eqs. (7)-(8): (LMI-OF) below is their eq. (7) with the blocks of X and Y in the
other order, and [[Y, I], [I, X]] > 0 their eq. (8)); Wu, Yang, Packard & Becker (IJRNC 6
(1996) 983-998) give the eliminated equivalent::

    (LMI-OF)
    [[A Y + B2 C^ + (*) - Y',  *,                              *,     *    ],
     [A^ + (A + B2 D^ C2)^T,   X A + B^ C2 + (*) + X',         *,     *    ],
     [(B1 + B2 D^ D21)^T,      (X B1 + B^ D21)^T,              -g I,  *    ],
     [C1 Y + D12 C^,           C1 + D12 D^ C2,   D11 + D12 D^ D21,   -g I ]] < 0,
    [[Y, I], [I, X]] > 0,

with X, Y, A^, B^, C^, D^ expanded in bases (X', Y' their time derivatives). Derivation
(used for the reconstruction): the closed-loop Lyapunov matrix cal-P = [[X, N], [N^T, *]]
with inverse [[Y, M], [M^T, *]], X Y + N M^T = I, Pi_Y = [[Y, I], [M^T, 0]],
Pi_X = cal-P Pi_Y = [[I, X], [0, N^T]]; the congruence of the rate-bounded bounded-real
lemma by diag(Pi_Y, I, I) gives (LMI-OF) with Pi_Y^T cal-P' Pi_Y = [[-Y', *], [X'Y + N'M^T, X']]
and the controller (D22 = 0)::

    D_K = D^,   C_K = (C^ - D_K C2 Y) M^-T,   B_K = N^-1 (B^ - X B2 D_K),
    A_K = N^-1 (A^ + X Y' + N M'^T - X (A + B2 D_K C2) Y - X B2 C_K M^T - N B_K C2 Y) M^-T.

The factors are chosen so that the rate term X Y' + N M'^T vanishes when X or Y is constant:
X constant: N = I, M^T = I - X Y; otherwise M = I, N = I - X Y (then the term is X Y', and
with both X and Y parameter-dependent the controller's A_K depends on rho' affinely, as in
Wu's and Apkarian-Adams' general case). ``constant="X"`` (default) gives a controller that
does not need the rates; with C2 = I, D21 = 0 the Y block of (LMI-OF) is the state-feedback LMI
with Y = P, C^ = Q.

**Procedure.** States balanced (x = T x_s, LAPACK gebal of A at the grid centre), each basis
replaced by an equivalent one orthonormal on the design grid; gamma minimised (Clarabel via
cvxpy); then the **back-off**: the LMIs re-solved at gamma_b = (1 + backoff) gamma_min
maximising a margin t with the matrices bounded by ``budget`` times their largest norm at
gamma_min: every LMI <= -t I (room for the parameter values between grid points) and (state feedback: P >= t I, P <= b_P
I, |Q| <= b_Q, so cond P <= b_P / t and
|K| <= b_Q / t; output feedback: [[Y - t I, I], [I, X]] >= 0, X <= b_X I, Y <= b_Y I, so
Y - X^-1 >= t I keeps I - X Y away from singular). The returned controller and certificate are those at gamma_b.

**Verification** (:func:`verify_design`): on a grid ``verify_refine`` times finer (design
points kept) (a) the certificate: (LMI-OF) / the state-feedback LMI re-evaluated in floating
point with the basis functions and their derivatives at every rate vertex, and X, Y, P
positive; (b) the frozen loops: closed loop of the plant with the controller at rho' = 0,
poles in the open left half plane and ||T_pw||_inf (python-control ``norm``, SLICOT AB13DD)
at most gamma_b.
"""
from __future__ import annotations

import itertools
import logging
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from tmfem.control.linear.lmi import solve, sym
from tmfem.control.linear.pbh import pbh
from tmfem.control.lpv import eigopt_route
from tmfem.control.lpv.basis import Basis
from tmfem.control.lpv.cost import check_lpvsyn_cost, lpvsyn_cost
from tmfem.control.lpv.gridded_plant import PlantFunction, grid_axes, plant_function
from tmfem.control.lpv.defaults import GAMMA_RTOL, TIME_BUDGET
from tmfem.control.lpv.generalized_plant import state_scaling
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.errors import InfeasibleController, InputError, ResourceLimit
from tmfem.resources import check_lpv_budget

log = logging.getLogger(__name__)


# ---------------------------------------------------------------------- plant data at points
@dataclass
class Partitioned:
    """The blocks of a generalised plant at one rho (scaled states)."""

    A: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    C1: np.ndarray
    C2: np.ndarray
    D11: np.ndarray
    D12: np.ndarray
    D21: np.ndarray

    @classmethod
    def of(cls, plant: PlantFunction, rho, *, ncon: int, nmeas: int, T: np.ndarray) -> Partitioned:
        A, B, C, D = plant.at(rho)
        nw, npp = B.shape[1] - ncon, C.shape[0] - nmeas
        if nmeas and np.any(D[npp:, nw:] != 0):
            raise InputError(f"LPV plant at rho = {np.asarray(rho).tolist()}: expected D22 = 0, found "
                             f"max |D22| = {np.abs(D[npp:, nw:]).max():.3g} (shift the loop first)")
        Ti = 1.0 / T
        A = Ti[:, None] * A * T[None, :]
        B = Ti[:, None] * B
        C = C * T[None, :]
        return cls(A=A, B1=B[:, :nw], B2=B[:, nw:], C1=C[:npp], C2=C[npp:], D11=D[:npp, :nw],
                   D12=D[:npp, nw:], D21=D[npp:, :nw])


def _state_feedback_lmi(pl: Partitioned, P, Q, dP, g, bmat):
    """The state-feedback LMI (module docstring; eqs. 5.95-5.96) for numeric or cvxpy P, Q."""
    nw, npp = pl.B1.shape[1], pl.C1.shape[0]
    AP = pl.A @ P + pl.B2 @ Q
    F = pl.C1 @ P + pl.D12 @ Q
    return bmat([[AP + AP.T - dP, pl.B1, F.T],
                 [pl.B1.T, -g * np.eye(nw), pl.D11.T],
                 [F, pl.D11, -g * np.eye(npp)]])


def _output_feedback_lmi(pl: Partitioned, X, Y, Ah, Bh, Ch, Dh, dX, dY, g, bmat):
    """(LMI-OF) of the module docstring for numeric or cvxpy variables."""
    nw, npp = pl.B1.shape[1], pl.C1.shape[0]
    AY = pl.A @ Y + pl.B2 @ Ch
    XA = X @ pl.A + Bh @ pl.C2
    M21 = Ah + (pl.A + pl.B2 @ Dh @ pl.C2).T
    b1 = pl.B1 + pl.B2 @ Dh @ pl.D21
    b2 = X @ pl.B1 + Bh @ pl.D21
    c1 = pl.C1 @ Y + pl.D12 @ Ch
    c2 = pl.C1 + pl.D12 @ Dh @ pl.C2
    d = pl.D11 + pl.D12 @ Dh @ pl.D21
    return bmat([[AY + AY.T - dY, M21.T, b1, c1.T],
                 [M21, XA + XA.T + dX, b2, c2.T],
                 [b1.T, b2.T, -g * np.eye(nw), d.T],
                 [c1, c2, d, -g * np.eye(npp)]])


# ---------------------------------------------------------------------- bases on the grid
@dataclass
class GridBasis:
    """A user basis re-expressed as f~(rho) = f(rho) W, orthonormal (RMS 1) on the design grid:
    the same span, better conditioned coefficients. ``coefficients_in_user_basis`` maps back."""

    basis: Basis
    W: np.ndarray

    @classmethod
    def of(cls, basis: Basis, design_points: np.ndarray) -> GridBasis:
        V = basis.values(design_points)
        _, R = np.linalg.qr(V)
        return cls(basis=basis, W=np.linalg.inv(R) * np.sqrt(V.shape[0]))

    def values(self, rho) -> np.ndarray:
        return self.basis.values(rho)[0] @ self.W

    def derivatives(self, rho) -> np.ndarray:
        """(n_b, n_p): d f~_j / d rho_k."""
        return np.einsum("ik,ij->jk", self.basis.derivatives(rho)[0], self.W)

    def __len__(self) -> int:
        return len(self.basis)


def _combine(coeffs, c):
    return sum(ci * Mi for ci, Mi in zip(c, coeffs))


# ---------------------------------------------------------------------- the controller
@dataclass
class GriddedController:
    """The synthesised controller, evaluated at any rho (and rho' when it depends on it).

    ``at(rho, rho_dot)`` returns (A_K, B_K, C_K, D_K) of x_K' = A_K x_K + B_K y,
    u = C_K x_K + D_K y; for state feedback A_K, B_K, C_K are empty and D_K = K(rho) acts on
    the plant state (u = K x). ``rate_dependent``: A_K depends on rho' (output feedback with
    both X and Y parameter-dependent); ``rho_dot`` is then required.
    """

    kind: str
    certificate: Certificate
    plant: PlantFunction
    ncon: int
    nmeas: int
    T: np.ndarray

    @property
    def rate_dependent(self) -> bool:
        c = self.certificate
        return self.kind == "output" and len(c.bases["X"]) > 1 and len(c.bases["Y"]) > 1

    def at(self, rho, rho_dot=None) -> tuple:
        rho = np.asarray(rho, dtype=float).reshape(-1)
        c = self.certificate
        if rho.size != c.n_parameters:
            raise InputError(f"LPV controller: expected {c.n_parameters} parameter values, found {rho.size}")
        if rho_dot is None and self.rate_dependent:
            raise InputError("LPV controller: expected rho_dot (A_K depends on the rates when X and Y are "
                             "both parameter-dependent)")
        v = c.scaled_at(rho, rho_dot)
        if self.kind == "state":
            K = sla.solve(v["P"], v["Q"].T, assume_a="pos").T / self.T[None, :]
            n = self.T.size
            return np.zeros((0, 0)), np.zeros((0, n)), np.zeros((K.shape[0], 0)), K
        pl = Partitioned.of(self.plant, rho, ncon=self.ncon, nmeas=self.nmeas, T=self.T)
        X, Y = v["X"], v["Y"]
        n = X.shape[0]
        I = np.eye(n)
        if len(c.bases["X"]) == 1:                    # X constant: N = I, M^T = I - X Y
            N, MT, rate = I, I - X @ Y, np.zeros((n, n))
        else:                                          # M = I, N = I - X Y: rate term X Y'
            N, MT, rate = I - X @ Y, I, X @ v["dY"]
        Dk = v["D^"]
        Ck = sla.solve(MT.T, (v["C^"] - Dk @ pl.C2 @ Y).T).T
        Bk = sla.solve(N, v["B^"] - X @ pl.B2 @ Dk)
        inner = (v["A^"] + rate - X @ (pl.A + pl.B2 @ Dk @ pl.C2) @ Y - X @ pl.B2 @ Ck @ MT
                 - N @ Bk @ pl.C2 @ Y)
        Ak = sla.solve(MT.T, sla.solve(N, inner).T).T
        return Ak, Bk, Ck, Dk

    def ss(self, rho, rho_dot=None):
        """The frozen controller as a python-control ``StateSpace`` (inputs y, outputs u;
        state feedback: inputs x)."""
        import control
        return control.ss(*self.at(rho, rho_dot))

    def closed_loop(self, rho):
        """The frozen closed loop w -> p at rho (rho' = 0) as a ``StateSpace`` in the plant's
        own state coordinates (the plant's states first)."""
        import control
        A, B, C, D = self.plant.at(rho)
        nw = B.shape[1] - self.ncon
        npp = C.shape[0] - self.nmeas
        B1, B2, C1, D11, D12 = B[:, :nw], B[:, nw:], C[:npp], D[:npp, :nw], D[:npp, nw:]
        Ak, Bk, Ck, Dk = self.at(rho, np.zeros(self.certificate.n_parameters))
        if self.kind == "state":
            return control.ss(A + B2 @ Dk, B1, C1 + D12 @ Dk, D11)
        C2, D21 = C[npp:], D[npp:, :nw]
        Acl = np.block([[A + B2 @ Dk @ C2, B2 @ Ck], [Bk @ C2, Ak]])
        Bcl = np.vstack([B1 + B2 @ Dk @ D21, Bk @ D21])
        Ccl = np.hstack([C1 + D12 @ Dk @ C2, D12 @ Ck])
        return control.ss(Acl, Bcl, Ccl, D11 + D12 @ Dk @ D21)


@dataclass
class Certificate:
    """The parameter-dependent solution of the LMIs at gamma: coefficients (scaled states,
    orthonormalised bases) and the bases; :meth:`at` gives the matrices in the plant's own
    state coordinates (X -> T^-1 X T^-1, Y, P -> T Y T, A^ -> T^-1 A^ T, B^ -> T^-1 B^,
    C^, Q -> C^ T, the congruence of the LMIs by the state scaling)."""

    gamma: float
    kind: str
    bases: dict
    coefficients: dict
    T: np.ndarray
    n_parameters: int
    rate_bounds: np.ndarray

    def scaled_at(self, rho, rho_dot=None) -> dict:
        """M(rho) = sum_i f~_i(rho) M_i of every variable (scaled states), and dM/dt =
        sum_i (grad f~_i . rho') M_i of X, Y, P (rho' = 0 when not given); the basis values
        are evaluated once per basis (the gain variables share one)."""
        out, values = {}, {}
        for name, coeffs in self.coefficients.items():
            gb = self.bases[name]
            if id(gb) not in values:
                values[id(gb)] = gb.values(rho)
            out[name] = _combine(coeffs, values[id(gb)])
            if name in ("X", "Y", "P"):
                dv = gb.derivatives(rho) @ (np.zeros(self.n_parameters) if rho_dot is None
                                            else np.asarray(rho_dot, dtype=float).reshape(-1))
                out["d" + name] = _combine(coeffs, dv)
        return out

    def at(self, rho, rho_dot=None) -> dict:
        v = self.scaled_at(np.asarray(rho, dtype=float).reshape(-1), rho_dot)
        T, Ti = self.T, 1.0 / self.T
        conv = {"X": lambda M: Ti[:, None] * M * Ti[None, :], "dX": lambda M: Ti[:, None] * M * Ti[None, :],
                "Y": lambda M: T[:, None] * M * T[None, :], "dY": lambda M: T[:, None] * M * T[None, :],
                "P": lambda M: T[:, None] * M * T[None, :], "dP": lambda M: T[:, None] * M * T[None, :],
                "A^": lambda M: Ti[:, None] * M * T[None, :], "B^": lambda M: Ti[:, None] * M,
                "C^": lambda M: M * T[None, :], "Q": lambda M: M * T[None, :], "D^": lambda M: M}
        return {k: conv[k](M) for k, M in v.items()}

    def coefficients_in_user_basis(self) -> dict:
        """name -> list of M_i with M(rho) = sum_i f_i(rho) M_i for the user's basis functions f_i
        (scaled states)."""
        return {name: [sum(gb.W[i, j] * c[j] for j in range(len(c))) for i in range(len(c))]
                for name, c in self.coefficients.items() for gb in (self.bases[name],)}


@dataclass
class LPVSynthesis:
    """Result of :func:`lpvsyn`.

    Attributes
    ----------
    gamma : float
        The level certified for ``controller`` (gamma_b = (1 + backoff) gamma_min).
    gamma_min : float
        The minimised level of the gridded LMIs.
    controller : GriddedController
    certificate : Certificate
    verification : dict
        :func:`verify_design` records (``passed`` and the worst values with where they occur).
    info : dict
        Solver statuses and times, sizes, condition measures.
    design : LPVStateFeedback or None
        The EIGOPT route's controller in the form of eq. 5.99 (what the deployment of 8.4
        and ``tmfem control lpv --save`` use); None on the SDP route.
    """

    gamma: float
    gamma_min: float
    controller: GriddedController
    certificate: Certificate
    verification: dict
    info: dict = field(default_factory=dict)
    design: LPVStateFeedback | None = None


# ---------------------------------------------------------------------- the entry point
def _rate_box(rate_bounds, n_par: int) -> np.ndarray:
    if rate_bounds is None:
        raise InputError("LPV synthesis: expected rate_bounds (one [lower, upper] per parameter, a scalar "
                         "nu for [-nu, nu], 0 for frozen parameters, inf for arbitrarily fast), found none")
    rb = np.asarray(rate_bounds, dtype=float)
    if rb.ndim == 0:
        rb = np.tile([-abs(float(rb)), abs(float(rb))], (n_par, 1))
    elif rb.ndim == 1 and rb.size == n_par:
        rb = np.stack([-np.abs(rb), np.abs(rb)], axis=1)
    if rb.shape != (n_par, 2) or np.any(np.isnan(rb)) or np.any(rb[:, 0] > rb[:, 1]):
        raise InputError(f"LPV synthesis: expected rate_bounds of shape ({n_par}, 2) with lower <= upper "
                         f"(or one bound per parameter), found {np.asarray(rate_bounds).tolist()}")
    return rb


def _resolve_basis(basis, n_par: int, axes, what: str) -> Basis:
    if isinstance(basis, Basis):
        return basis
    if basis == "constant":
        return Basis.constant()
    if basis == "affine":
        lo = np.array([a[0] for a in axes])
        hi = np.array([a[-1] for a in axes])
        return Basis.affine(n_par, centre=(lo + hi) / 2, half_width=np.where(hi > lo, (hi - lo) / 2, 1.0),
                            parameters=[k for k in range(n_par) if hi[k] > lo[k]])
    raise InputError(f"{what}: expected a Basis, 'constant' or 'affine' (1 and each parameter with more "
                     f"than one grid value, eq. 5.99), found {basis!r}")


def refinement(factor) -> int:
    """The verification refinement ``factor`` as an int (an integer >= 1, also as a float)."""
    ok = (isinstance(factor, (int, float, np.integer, np.floating)) and not isinstance(factor, bool)
          and np.isfinite(factor) and int(factor) == factor and factor >= 1)
    if not ok:
        raise InputError(f"verification refinement: expected an integer >= 1, found {factor!r}")
    return int(factor)


def refined_axes(axes, factor: int) -> list:
    """Axes ``factor`` times finer, the design points kept."""
    factor = refinement(factor)
    return [a if a.size == 1 else np.concatenate(
        [np.linspace(a[i], a[i + 1], int(factor) + 1)[:-1] for i in range(a.size - 1)] + [a[-1:]])
        for a in axes]


def _points(axes) -> np.ndarray:
    return np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, len(axes))


def _vertices(rb: np.ndarray) -> np.ndarray:
    finite = np.where(np.isfinite(rb), rb, 0.0)       # unbounded rates: the basis ignores them
    return np.array(list(itertools.product(*[np.unique(r) for r in finite])), dtype=float)


def lpvsyn(P, nmeas: int, ncon: int, *, grid, rate_bounds, basis="constant", gain_basis=None,
           constant: str | None = "X", backoff: float = 0.01, budget: float = 10.0, gamma_max: float = 1e6,
           verify_refine: int = 4, solver: str = "CLARABEL", eps: float = 1e-7, scale: bool = True,
           interpolation: str = "multilinear", require_verified: bool = True, method: str = "auto",
           gamma: float | None = None, fixed_gamma: bool = False, gamma_rtol: float = GAMMA_RTOL,
           time_budget: float = TIME_BUDGET, start=None, max_iter: int | None = None,
           sample_time: float | None = None, bound=None, progress=None) -> LPVSynthesis:
    """Gridded LPV H-infinity synthesis (module docstring): minimise gamma, back off to a
    well-conditioned controller, verify off the grid.

    Two routes (``info["method"]``, the choice explained in ``info["route_reason"]``):
    ``"sdp"``, the interior-point SDP of the module docstring (any basis, state and output
    feedback), and ``"eigopt"``, the gamma bisection over eigenvalue-optimisation levels of
    :mod:`tmfem.control.lpv.eigopt_route` (state feedback with the affine basis of eq. 5.99,
    scalable to the 2-3 plant of ch. 8). ``method="auto"`` takes the SDP unless its memory
    estimate exceeds this machine's limit, then the EIGOPT route when the problem has its
    structure; otherwise it refuses (:class:`~tmfem.errors.ResourceLimit` with the estimate
    and the reason).

    Parameters
    ----------
    P : callable, StateSpace, tuple of arrays, GriddedLPV or GeneralizedLPV
        The generalised plant, inputs [w, u], outputs [p, y]
        (:func:`tmfem.control.lpv.gridded_plant.plant_function`).
    nmeas, ncon : int
        Number of measured outputs y (the last outputs) and of controls u (the last inputs).
        ``nmeas = 0``: state feedback u = K(rho) x (the controller reads the full state).
    grid : sequence of 1-D arrays, 1-D array or dict
        Design points of each parameter (a rectangular grid).
    rate_bounds : float, (n_p,) or (n_p, 2)
        Bounds of rho_k' (a scalar nu: [-nu, nu] for every parameter; 0: frozen; inf:
        arbitrarily fast, allowed only for parameters the Lyapunov basis does not depend on).
    basis : Basis, "constant" or "affine"
        Basis of the Lyapunov matrices (P for state feedback; X and Y for output feedback).
    gain_basis : Basis, "constant" or "affine", optional
        Basis of Q (state feedback) or of A^, B^, C^, D^ (output feedback); default ``basis``.
    constant : {"X", "Y", None}
        Output feedback: which of X, Y is taken constant (None: both parameter-dependent; the
        controller then depends on rho'). Refused for state feedback unless None or "X".
    backoff : float
        gamma_b = (1 + backoff) gamma_min for the conditioning re-solve (> 0).
    budget : float
        The re-solve bounds P, Q (X, Y) by ``budget`` times their largest norm at gamma_min.
    gamma_max : float
        Upper limit of gamma in the minimisation (a certificate of infeasibility below it
        instead of a solver that never stops raising gamma).
    verify_refine : int
        The verification grid is this many times finer than the design grid.
    solver : {"CLARABEL", "SCS"}
    eps : float
        Strictness margin of the LMIs in the scaled problem.
    require_verified : bool
        Raise :class:`InfeasibleController` when the off-grid verification fails (default);
        False returns the design with ``verification["passed"]`` false, to inspect it.
    method : {"auto", "sdp", "eigopt"}
        The route (above).
    gamma, fixed_gamma, gamma_rtol, time_budget, start, max_iter, sample_time, bound, progress
        EIGOPT route only (refused by the SDP route): the bisection's upper level (default
        twice the pointwise lower bound) or with ``fixed_gamma`` the one level solved, its
        relative bracket width and time budget [s], a starting design
        (:class:`~tmfem.control.lpv.state_feedback.LPVStateFeedback`), the L-BFGS iterations
        per level, the zero-order-hold step at which the sampled frozen loops must also be
        stable, the pointwise lower bound when already computed
        (:class:`~tmfem.control.lpv.bounds.PointwiseBound`), and ``progress(seconds)``
        called after each level
        (:func:`tmfem.control.lpv.eigopt_route.synthesize_eigopt`).

    Returns
    -------
    LPVSynthesis
        With the EIGOPT route ``gamma_min = gamma`` (no back-off: the lowest level where a
        point was found) and ``design`` the controller in the form of eq. 5.99.

    Raises
    ------
    InputError
        An unknown method or an option of the other route, the EIGOPT route asked for a
        problem without its structure, inconsistent shapes, a grid without the plant's design
        points, a basis that is not finite or smooth or is linearly dependent on the grid,
        options out of range.
    ResourceLimit
        An SDP whose interior-point memory or CPU-time estimate (:mod:`tmfem.control.lpv.cost`)
        exceeds this machine's memory limit or :data:`tmfem.resources.MAX_SYNTHESIS_S`,
        before anything is built, on a problem the EIGOPT route cannot
        carry (the message names why).
    InfeasibleController
        Infeasible or failed SDP, with the solver status and the likely cause; a design whose
        verification failed (with ``require_verified``).
    """
    t_start = time.perf_counter()
    axes = grid_axes(grid)
    n_par = len(axes)
    for nm, v in (("nmeas", nmeas), ("ncon", ncon)):
        if int(v) != v or v < 0:
            raise InputError(f"LPV synthesis: expected {nm} an integer >= 0, found {v!r}")
    if not (np.isfinite(backoff) and backoff > 0) or not (np.isfinite(budget) and budget >= 1):
        raise InputError(f"LPV synthesis: expected backoff > 0 and budget >= 1, found {backoff!r}, {budget!r}")
    if not (np.isfinite(gamma_max) and gamma_max > 0):
        raise InputError(f"LPV synthesis: expected gamma_max > 0, found {gamma_max!r}")
    if not (np.isfinite(eps) and eps > 0):
        raise InputError(f"LPV synthesis: expected eps > 0, found {eps!r}")
    kind = "state" if nmeas == 0 else "output"
    if method not in ("auto", "sdp", "eigopt"):
        raise InputError(f"LPV synthesis: expected method 'auto', 'sdp' or 'eigopt', found {method!r}")
    given = _given_options(locals())
    if constant not in ("X", "Y", None):
        raise InputError(f"LPV synthesis: expected constant in 'X', 'Y' or None, found {constant!r}")
    if kind == "state" and constant == "Y":
        raise InputError("LPV synthesis: constant='Y' applies to output feedback (nmeas > 0) only; state "
                         "feedback has one Lyapunov matrix P (its basis is `basis`)")
    plant = plant_function(P, axes=axes, interpolation=interpolation)
    m, p, n = plant.m, plant.p, plant.n
    if not (0 < ncon < m and nmeas < p):
        raise InputError(f"LPV synthesis: expected 0 < ncon < {m} inputs and 0 <= nmeas < {p} outputs (at "
                         f"least one w and one p), found ncon = {ncon}, nmeas = {nmeas}")
    rb = _rate_box(rate_bounds, n_par)
    f = refinement(verify_refine)
    # before any point is listed or evaluated: the grids' sizes are products of the axes'
    check_lpv_budget(design_points=int(np.prod([a.size for a in axes])),
                     verify_points=int(np.prod([(a.size - 1) * f + 1 for a in axes])),
                     vertices=len(_vertices(rb)), n=n, m=m, p=p)
    design = _points(axes)
    dense_axes = refined_axes(axes, f)
    dense = _points(dense_axes)
    lyap = _resolve_basis(basis, n_par, axes, "basis")
    gain = _resolve_basis(gain_basis if gain_basis is not None else basis, n_par, axes, "gain_basis")
    lyap.checked(design, dense, what="basis")
    gain.checked(design, dense, what="gain_basis")
    unbounded = [k for k in range(n_par) if not np.all(np.isfinite(rb[k]))]
    if unbounded:
        G = lyap.derivatives(dense)
        dep = [k for k in unbounded if np.abs(G[:, 1:, k] if len(lyap) > 1 else G[:, :, k]).max() > 1e-12]
        if dep:
            raise InputError(f"LPV synthesis: the rate of rho{dep[0]} is unbounded, expected a Lyapunov basis "
                             f"independent of it, found {list(lyap.names)} depending on it")
    gbL, gbG = GridBasis.of(lyap, design), GridBasis.of(gain, design)
    gbC = GridBasis.of(Basis.constant(), design)
    if kind == "state":
        bases = {"P": gbL, "Q": gbG}
    else:
        bases = {"X": gbC if constant == "X" else gbL, "Y": gbC if constant == "Y" else gbL,
                 "A^": gbG, "B^": gbG, "C^": gbG, "D^": gbG}
    cost = lpvsyn_cost(n=n, nw=m - ncon, np_=p - nmeas, nu=ncon, ny=nmeas, points=len(design),
                       vertices=len(_vertices(rb)), lyapunov_basis=len(lyap), gain_basis=len(gain), constant=constant)
    why_not = eigopt_route.unsupported(nmeas=nmeas, lyap=lyap, gain=gain, points=dense, rb=rb,
                                       affine=_resolve_basis("affine", n_par, axes, "basis"))
    log.info("lpvsyn: estimate of the interior-point SDP: %s", cost.text)
    method, reason = _route(method, cost=cost, why_not=why_not,
                            what=f"lpvsyn: {n} states, {len(design)} grid points x {len(_vertices(rb))} rate vertices")
    if method == "eigopt":
        if given["sdp"]:
            raise InputError(f"LPV synthesis: options {given['sdp']} belong to the SDP route, found them with the "
                             f"EIGOPT route ({reason})")
        gp = eigopt_route.generalized_on_grid(P, plant, axes=axes, rb=rb, ncon=ncon)
        t_syn = time.perf_counter()
        sf, record = eigopt_route.synthesize_eigopt(gp, gamma=gamma, fixed_gamma=fixed_gamma, rtol=gamma_rtol,
                                                    time_budget=time_budget, start=start, max_iter=max_iter,
                                                    sample_time=sample_time, bound=bound, progress=progress)
        T = eigopt_route.scaling(gp, scale=scale)
        cert = Certificate(gamma=sf.gamma, kind=kind, T=T, n_parameters=n_par, rate_bounds=rb,
                           bases={"P": GridBasis(basis=lyap, W=np.eye(len(lyap))),
                                  "Q": GridBasis(basis=gain, W=np.eye(len(gain)))},
                           coefficients={"P": [Pk / np.outer(T, T) for Pk in sf.P], "Q": [Qk / T for Qk in sf.Q]})
        ctrl = GriddedController(kind=kind, certificate=cert, plant=plant, ncon=ncon, nmeas=nmeas, T=T)
        info = {"kind": kind, "method": "eigopt", "route_reason": reason, "sizes": sf.sizes, "solver": sf.solver,
                "status": sf.status, "solve_time_s": sf.solve_time, "synthesis_time_s": time.perf_counter() - t_syn,
                "memory_estimate_sdp_gib": cost.memory_bytes / 2**30, "sample_time_s": sample_time,
                "plant_interpolated": plant.interpolated, **record}
        return _verified(ctrl, sf.gamma, info, design_axes=axes, check_axes=dense_axes, t_start=t_start,
                         require_verified=require_verified, design=sf)
    if given["eigopt"]:
        raise InputError(f"LPV synthesis: options {given['eigopt']} belong to the EIGOPT route, found them with the "
                         f"SDP route ({reason})")
    centre = tuple((a.size - 1) // 2 for a in axes)
    T = state_scaling(plant.at([a[i] for a, i in zip(axes, centre)])[0]) if scale else np.ones(n)
    verts = _vertices(rb)
    pts = [Partitioned.of(plant, r, ncon=ncon, nmeas=nmeas, T=T) for r in design]
    t_build = time.perf_counter()
    prob = _Problem(kind=kind, bases=bases, pts=pts, design=design, verts=verts, eps=eps, n=n,
                    nu=ncon, ny=nmeas)
    sizes = {"grid_points": len(design), "rate_vertices": len(verts), "lmis": len(design) * len(verts),
             "lmi_size": prob.lmi_size, "n_x": n, "basis": list(lyap.names), "gain_basis": list(gain.names),
             "decision_variables": prob.n_variables, "memory_estimate_gib": cost.memory_bytes / 2**30,
             "cpu_seconds_estimate": cost.seconds}
    log.info("lpvsyn: %s feedback, %s", kind, sizes)
    try:
        g_min, rep1 = prob.minimize_gamma(solver, gamma_max=gamma_max, budget=budget)
    except InfeasibleController as exc:
        raise InfeasibleController(f"LPV {kind}-feedback synthesis on {len(design)} grid points x "
                                   f"{len(verts)} rate vertices: {exc}; likely cause: "
                                   f"{_likely_cause(pts, design, kind, lyap, rb)}") from None
    g_b = (1 + backoff) * g_min
    try:
        rep2, cond = prob.condition(solver, g_b)
    except InfeasibleController as exc:
        raise InfeasibleController(f"LPV {kind}-feedback synthesis: gamma_min = {g_min:.6g} found, the "
                                   f"conditioning re-solve at {g_b:.6g} failed: {exc}; expected a strictly "
                                   "feasible point (try a larger backoff)") from None
    cert = Certificate(gamma=g_b, kind=kind, bases=bases, coefficients=prob.values(), T=T, n_parameters=n_par,
                       rate_bounds=rb)
    ctrl = GriddedController(kind=kind, certificate=cert, plant=plant, ncon=ncon, nmeas=nmeas, T=T)
    info = {"kind": kind, "method": "sdp", "route_reason": reason, "sizes": sizes, "solver": solver,
            "status_gamma": rep1.status, "status_backoff": rep2.status, "solve_time_gamma_s": rep1.solve_time_s,
            "solve_time_backoff_s": rep2.solve_time_s, "build_time_s": t_build - t_start,
            "condition": cond, "constant": constant if kind == "output" else None,
            "rate_dependent_controller": ctrl.rate_dependent, "plant_interpolated": plant.interpolated}
    return _verified(ctrl, g_min, info, design_axes=axes, check_axes=dense_axes, t_start=t_start,
                     require_verified=require_verified)


_ROUTE_OPTIONS = {"sdp": ("backoff", "budget", "gamma_max", "solver", "eps"),
                  "eigopt": ("gamma", "fixed_gamma", "gamma_rtol", "time_budget", "start", "max_iter", "sample_time",
                             "bound", "progress")}


def _given_options(values: dict) -> dict:
    """route -> the options of :func:`lpvsyn` that belong to that route only and were given a
    value other than their default (``values``: the call's arguments)."""
    import inspect
    defaults = inspect.signature(lpvsyn).parameters
    return {route: [k for k in names if values[k] is not defaults[k].default and values[k] != defaults[k].default]
            for route, names in _ROUTE_OPTIONS.items()}


def _route(method: str, *, cost, why_not: str, what: str) -> tuple:
    """The route of :func:`lpvsyn` and why: ``method`` as asked, or with "auto" the SDP when its
    memory and time estimates fit (:func:`~tmfem.control.lpv.cost.check_lpvsyn_cost`), else
    the EIGOPT route when ``why_not`` is empty; refused otherwise
    (:class:`ResourceLimit` with the estimate and ``why_not``)."""
    if method == "eigopt":
        if why_not:
            raise InputError(f"LPV synthesis: the EIGOPT route does not apply: {why_not}")
        return method, "asked for (method='eigopt')"
    try:
        check_lpvsyn_cost(cost, what=what)
    except ResourceLimit as exc:
        if method == "sdp" or why_not:
            raise ResourceLimit(f"{exc}; the EIGOPT route does not apply"
                                f"{': ' + why_not if why_not else ' (method=sdp asked for)'}") from None
        return "eigopt", f"the interior-point SDP is over this machine's limits ({cost.text})"
    return "sdp", ("asked for (method='sdp')" if method == "sdp" else f"the interior-point SDP fits ({cost.text})")


def _verified(ctrl: GriddedController, g_min: float, info: dict, *, design_axes, check_axes, t_start: float,
              require_verified: bool, design=None) -> LPVSynthesis:
    """The off-grid verification (:func:`verify_design`) of ``ctrl`` and the result of
    :func:`lpvsyn`; raises with ``require_verified`` when it fails."""
    cert = ctrl.certificate
    t_ver = time.perf_counter()
    ver = verify_design(ctrl, design_axes=design_axes, check_axes=check_axes)
    info.update(verify_time_s=time.perf_counter() - t_ver, total_time_s=time.perf_counter() - t_start)
    log.info("lpvsyn (%s): gamma_min = %.6g, gamma = %.6g, verification %s", info["method"], g_min, cert.gamma,
             "passed" if ver["passed"] else "FAILED")
    if require_verified and not ver["passed"]:
        raise InfeasibleController(f"LPV synthesis: gamma = {cert.gamma:.6g} but the off-grid verification failed "
                                   f"({ver['summary']}); expected a certificate that holds between grid "
                                   "points (refine the grid)")
    return LPVSynthesis(gamma=cert.gamma, gamma_min=g_min, controller=ctrl, certificate=cert, verification=ver,
                        info=info, design=design)


# ---------------------------------------------------------------------- the SDP
class _Problem:
    """The gridded LMIs as a cvxpy problem in one vector z of the coefficients' free entries.

    Each LMI is affine in z and gamma, so it is assembled numerically as vec(M) = m0 + G z +
    gamma h with a sparse G (columns: the LMI function of the module docstring at unit coefficients, then
    combined with the basis values and rate-weighted derivatives of each grid point and rate
    vertex); cvxpy then sees one matrix-vector product per LMI instead of the expression tree
    of the block products.
    """

    def __init__(self, *, kind, bases, pts, design, verts, eps, n, nu, ny):
        import cvxpy as cp
        self.cp, self.kind, self.bases, self.pts, self.design, self.verts = cp, kind, bases, pts, design, verts
        self.eps, self.n = eps, n
        self.shapes = ({"P": (n, n), "Q": (nu, n)} if kind == "state" else
                       {"X": (n, n), "Y": (n, n), "A^": (n, n), "B^": (n, ny), "C^": (nu, n), "D^": (nu, ny)})
        self.units = {k: self._units(k) for k in self.shapes}
        self.blocks, off = [], 0                 # (name, basis index, offset, size) in z
        for k in self.shapes:
            for i in range(len(bases[k])):
                self.blocks.append((k, i, off, len(self.units[k])))
                off += len(self.units[k])
        self.nz = off
        self.z = cp.Variable(off)
        pl = pts[0]
        self.lmi_size = (n + pl.B1.shape[1] + pl.C1.shape[0]) if kind == "state" else \
            (2 * n + pl.B1.shape[1] + pl.C1.shape[0])
        self.n_variables = off + 1

    def _units(self, k) -> list:
        r, c = self.shapes[k]
        if k in ("P", "X", "Y"):
            out = []
            for a, b in zip(*np.triu_indices(r)):
                E = np.zeros((r, c))
                E[a, b] = E[b, a] = 1.0
                out.append(E)
            return out
        return [np.eye(1, r * c, j).reshape(r, c) for j in range(r * c)]

    def _lmi(self, pl, slot):
        z = {k: slot.get(k, np.zeros(s)) for k, s in self.shapes.items()}
        g = slot.get("g", 0.0)
        if self.kind == "state":
            return _state_feedback_lmi(pl, z["P"], z["Q"], slot.get("dP", np.zeros(self.shapes["P"])), g, np.block)
        dn = np.zeros((self.n, self.n))
        return _output_feedback_lmi(pl, z["X"], z["Y"], z["A^"], z["B^"], z["C^"], z["D^"], slot.get("dX", dn),
                                    slot.get("dY", dn), g, np.block)

    def _point_maps(self, pl):
        """m0, the gamma column and, per slot (a matrix or its derivative), the columns of the
        LMI at unit entries."""
        m0 = self._lmi(pl, {}).ravel()
        H = {}
        for k in self.shapes:
            for slot in ((k, "d" + k) if k in ("P", "X", "Y") else (k,)):
                H[slot] = sp.csc_matrix(np.stack([self._lmi(pl, {slot: E}).ravel() - m0 for E in self.units[k]],
                                                 axis=1))
        return m0, self._lmi(pl, {"g": 1.0}).ravel() - m0, H

    def _G(self, H, rho, vert):
        cols = []
        for k, i, _, _ in self.blocks:
            gb = self.bases[k]
            col = gb.values(rho)[i] * H[k]
            if "d" + k in H:
                col = col + (gb.derivatives(rho)[i] @ vert) * H["d" + k]
            cols.append(col)
        return sp.hstack(cols, format="csr")

    def value(self, k, rho):
        """M_k(rho) as a cvxpy expression (sum_i f_i(rho) M_k,i)."""
        cp = self.cp
        f = self.bases[k].values(rho)
        r, c = self.shapes[k]
        S = np.zeros((r * c, self.nz))
        U = np.stack([E.ravel() for E in self.units[k]], axis=1)
        for kk, i, off, size in self.blocks:
            if kk == k:
                S[:, off:off + size] = f[i] * U
        return cp.reshape(S @ self.z, (r, c), order="C")

    def constraints(self, g, margin=0.0):
        """The LMIs at level ``g`` with LMI <= -(eps + margin) I (``margin`` a cvxpy variable in
        the re-solve), and P > 0 or [[Y, I], [I, X]] > 0 at the design points."""
        cp, n, eps = self.cp, self.n, self.eps
        cons, psd = [], []
        N = self.lmi_size
        for rho, pl in zip(self.design, self.pts):
            m0, hg, H = self._point_maps(pl)
            for v in self.verts:
                M = cp.reshape(m0 + self._G(H, rho, v) @ self.z + g * hg, (N, N), order="C")
                cons.append(sym(M) << -(eps + margin) * np.eye(N))
            if self.kind == "state":
                L = self.value("P", rho)
                psd.append(L)
                cons.append(sym(L) >> eps * np.eye(n))
            else:
                X, Y = self.value("X", rho), self.value("Y", rho)
                psd.append((X, Y))
                cons.append(sym(cp.bmat([[Y, np.eye(n)], [np.eye(n), X]])) >> eps * np.eye(2 * n))
        return cons, psd

    def minimize_gamma(self, solver, *, gamma_max, budget):
        cp = self.cp
        g = cp.Variable(nonneg=True)
        cons, _ = self.constraints(g)
        cons.append(g <= gamma_max)
        self._budget = budget
        prob = cp.Problem(cp.Minimize(g), cons)
        rep = _solve_relaxing(prob, solver=solver, what="gamma minimisation", lmi_size=self.lmi_size)
        self._bound = {k: self._budget * self._largest(k) for k in self.shapes if k in ("P", "Q", "X", "Y")}
        return float(g.value), rep

    def _at_design(self, rho) -> dict:
        return {k: _combine(c, self.bases[k].values(rho)) for k, c in self.values().items()}

    def _largest(self, name) -> float:
        """Largest 2-norm of the matrix ``name`` over the design points (its current value)."""
        return max(float(np.linalg.norm(self._at_design(r)[name], 2)) for r in self.design)

    def condition(self, solver, g_b):
        """The back-off re-solve (module docstring); returns (report, condition measures)."""
        cp, n = self.cp, self.n
        t = cp.Variable()
        cons, psd = self.constraints(g_b, t)
        for rho, L in zip(self.design, psd):
            if self.kind == "state":
                Q = self.value("Q", rho)
                nu = self.shapes["Q"][0]
                bq = self._bound["Q"]
                cons += [sym(L) >> t * np.eye(n), sym(L) << self._bound["P"] * np.eye(n),
                         sym(cp.bmat([[bq * np.eye(nu), Q], [Q.T, bq * np.eye(n)]])) >> 0]
            else:
                Xk, Yk = L
                cons += [sym(cp.bmat([[Yk - t * np.eye(n), np.eye(n)], [np.eye(n), Xk]])) >> 0,
                         sym(Xk) << self._bound["X"] * np.eye(n), sym(Yk) << self._bound["Y"] * np.eye(n)]
        prob = cp.Problem(cp.Maximize(t), cons)
        rep = _solve_relaxing(prob, solver=solver, what="conditioning re-solve", lmi_size=self.lmi_size)
        return rep, self._condition_measures()

    def _condition_measures(self) -> dict:
        vals = [self._at_design(r) for r in self.design]
        if self.kind == "state":
            K = [sla.solve(v["P"], v["Q"].T, assume_a="pos").T for v in vals]
            return {"max_gain_norm_scaled": float(max(np.linalg.norm(k, 2) for k in K)),
                    "max_cond_P": float(max(np.linalg.cond(v["P"]) for v in vals))}
        I = np.eye(self.n)
        return {"max_cond_I_minus_XY": float(max(np.linalg.cond(I - v["X"] @ v["Y"]) for v in vals)),
                "max_eig_X": float(max(np.linalg.eigvalsh(v["X"]).max() for v in vals)),
                "max_eig_Y": float(max(np.linalg.eigvalsh(v["Y"]).max() for v in vals))}

    def values(self) -> dict:
        """name -> coefficient matrices (orthonormalised basis, scaled states) at the solution."""
        z = np.asarray(self.z.value, dtype=float)
        out = {k: [] for k in self.shapes}
        for k, _, off, size in self.blocks:
            out[k].append(sum(zj * E for zj, E in zip(z[off:off + size], self.units[k])))
        return out


def _solve_relaxing(prob, *, solver, what, lmi_size, tols=(1e-7, 1e-5, 1e-3)):
    """:func:`tmfem.control.linear.lmi.solve` at the tolerances ``tols`` in turn: an interior-point
    solver that stalls short of a tight tolerance (a status other than infeasible) is given a
    looser one (the report's ``status`` names the tolerance used); the point it returns is
    checked by the verification in any case."""
    for k, tol in enumerate(tols):
        try:
            rep = solve(prob, solver=solver, what=what, lmi_sizes={"lmi": lmi_size}, tol=tol,
                        accept_inaccurate=True)
            rep.status = f"{rep.status} (tolerance {tol:g})"
            return rep
        except InfeasibleController as exc:
            if k == len(tols) - 1 or "'infeasible'" in str(exc):
                raise
            log.warning("%s: %s; retrying at tolerance %g", what, exc, tols[k + 1])


def _likely_cause(pts, design, kind, lyap: Basis, rb) -> str:
    """A frozen point that is not stabilisable (detectable), named with its mode; else the basis
    or the rate bounds."""
    for rho, pl in zip(design, pts):
        r = pbh(pl.A, pl.B2, pl.C2 if kind == "output" else np.eye(pl.A.shape[0]))
        lam = r.eigenvalues
        bad_c = (lam.real >= 0) & (r.controllability_margin <= r.tol)
        bad_o = (lam.real >= 0) & (r.observability_margin <= r.tol)
        for bad, what in ((bad_c, "not stabilisable by u"), (bad_o, "not detectable from y")):
            if bad.any():
                l0 = lam[np.argmax(bad)]
                return (f"the frozen plant at rho = {rho.tolist()} is {what} (mode {l0.real:.4g}"
                        f"{l0.imag:+.4g}j, PBH margin below {r.tol:g})")
    return (f"every frozen plant of the grid is stabilisable{' and detectable' if kind == 'output' else ''}; "
            f"the Lyapunov basis {list(lyap.names)} cannot certify the rate bounds {rb.tolist()} (try a richer "
            "basis or smaller rate bounds), or the plant is badly scaled")


# ---------------------------------------------------------------------- verification
def verify_design(ctrl: GriddedController, *, design_axes, check_axes, rtol: float = 1e-5) -> dict:
    """Off-grid verification of a design (module docstring): the certificate's LMIs with the
    basis derivatives at every rate vertex and point of ``check_axes``, and the frozen
    closed loops' poles and H-infinity norms there (python-control ``norm``).

    Returns a dict: ``passed``, ``certificate_passed``, ``frozen_passed``, ``max_lmi_eig``
    (largest eigenvalue of the LMI in the scaled problem, < 0 holds) with ``max_lmi_eig_at``,
    ``min_lyapunov_eig`` (of P or [[Y, I], [I, X]], > 0 holds), ``max_frozen_norm`` (<= gamma
    (1 + rtol) holds) with where, ``max_closed_loop_real`` (< 0 holds), ``summary``.
    """
    import control
    cert = ctrl.certificate
    g = cert.gamma
    pts = _points(check_axes)
    verts = _vertices(cert.rate_bounds)
    worst, worst_at, worst_text, minpos = -np.inf, None, "", np.inf
    fn, fn_at, re_max = 0.0, None, -np.inf
    n = ctrl.T.size
    for rho in pts:
        pl = Partitioned.of(ctrl.plant, rho, ncon=ctrl.ncon, nmeas=ctrl.nmeas, T=ctrl.T)
        for v in verts:
            a = cert.scaled_at(rho, v)
            if cert.kind == "state":
                M = _state_feedback_lmi(pl, a["P"], a["Q"], a["dP"], g, np.block)
            else:
                M = _output_feedback_lmi(pl, a["X"], a["Y"], a["A^"], a["B^"], a["C^"], a["D^"], a["dX"],
                                         a["dY"], g, np.block)
            e = float(np.linalg.eigvalsh((M + M.T) / 2).max())
            if e > worst:
                worst, worst_at = e, [rho.tolist(), v.tolist()]
                worst_text = ", ".join([ctrl.plant.point_text(rho)] + ([ctrl.plant.point_text(v, rates=True)]
                                                                      if len(v) else []))
        a = cert.scaled_at(rho)
        L = a["P"] if cert.kind == "state" else np.block([[a["Y"], np.eye(n)], [np.eye(n), a["X"]]])
        minpos = min(minpos, float(np.linalg.eigvalsh((L + L.T) / 2).min()))
        T = ctrl.closed_loop(rho)
        re = float(np.max(np.real(T.poles())))
        re_max = max(re_max, re)
        if re < 0:
            nrm = float(control.norm(T, p="inf"))
            if nrm > fn:
                fn, fn_at = nrm, rho.tolist()
        else:
            fn, fn_at = np.inf, rho.tolist()
    cert_ok = worst < 0 and minpos > 0
    frozen_ok = re_max < 0 and fn <= g * (1 + rtol)
    summary = (f"max LMI eigenvalue {worst:.3e} at {worst_text}, min Lyapunov eigenvalue "
               f"{minpos:.3e}, max frozen ||T_pw||_inf {fn:.6g} at {ctrl.plant.point_text(fn_at)} (gamma {g:.6g}), max "
               f"closed-loop Re {re_max:.4g}")
    log.info("lpvsyn verification on %s points: %s", len(pts), summary)
    return {"passed": bool(cert_ok and frozen_ok), "certificate_passed": bool(cert_ok),
            "frozen_passed": bool(frozen_ok), "grid": [a.size for a in check_axes],
            "design_grid": [a.size for a in design_axes], "max_lmi_eig": worst, "max_lmi_eig_at": worst_at,
            "min_lyapunov_eig": minpos, "max_frozen_norm": fn, "max_frozen_norm_at": fn_at,
            "max_closed_loop_real": re_max, "gamma": g, "summary": summary}
