"""The partitioned (generalised) plant of eq. 5.62 with named signals::

    x' = A x + B1 w + B2 u,   p = C1 x + D11 w + D12 u,   y = C2 x + D21 w + D22 u

w exogenous inputs, u control inputs, p performance outputs, y measured outputs (the
ordering of python-control's ``hinfsyn``: inputs [w, u], outputs [p, y]).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError


@dataclass
class GeneralizedPlant:
    """Partitioned plant of eq. 5.62 with named signals. The synthesis routes assume D22 = 0
    (7.3); :func:`tmfem.control.linear.hinf_synthesis.hinfsyn` removes a D22 != 0 by loop shifting."""

    A: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    C1: np.ndarray
    C2: np.ndarray
    D11: np.ndarray
    D12: np.ndarray
    D21: np.ndarray
    D22: np.ndarray
    state_names: list
    w_names: list
    u_names: list
    p_names: list
    y_names: list

    def __post_init__(self):
        for k in ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22"):
            M = np.asarray(getattr(self, k))
            if np.iscomplexobj(M):
                raise InputError(f"generalised plant: expected real matrices, found complex {k}")
            if not (np.issubdtype(M.dtype, np.number) or M.dtype == bool):
                raise InputError(f"generalised plant: expected numeric matrices, found {k} of "
                                 f"dtype {M.dtype}")
            setattr(self, k, np.atleast_2d(M.astype(float)))
        n = self.A.shape[0]
        nw, nu, np_, ny = self.B1.shape[1], self.B2.shape[1], self.C1.shape[0], self.C2.shape[0]
        want = {"A": (n, n), "B1": (n, nw), "B2": (n, nu), "C1": (np_, n), "C2": (ny, n),
                "D11": (np_, nw), "D12": (np_, nu), "D21": (ny, nw), "D22": (ny, nu)}
        for k, shp in want.items():
            if getattr(self, k).shape != shp:
                raise InputError(f"generalised plant: expected {k} of shape {shp}, found "
                                 f"{getattr(self, k).shape}")
        for k, m in (("state_names", n), ("w_names", nw), ("u_names", nu), ("p_names", np_),
                     ("y_names", ny)):
            if len(getattr(self, k)) != m:
                raise InputError(f"generalised plant: expected {m} {k}, found {len(getattr(self, k))}")
        if not np.all(np.isfinite(np.concatenate([getattr(self, k).ravel() for k in want]))):
            raise InputError("generalised plant: expected finite matrices, found NaN or inf")

    @property
    def sizes(self) -> dict:
        return {"n": self.A.shape[0], "nw": self.B1.shape[1], "nu": self.B2.shape[1],
                "np": self.C1.shape[0], "ny": self.C2.shape[0]}

    def to_ss(self, name: str = "P"):
        """python-control ``StateSpace``: inputs [w, u], outputs [p, y] (hinfsyn's order)."""
        import control
        B = np.hstack([self.B1, self.B2])
        C = np.vstack([self.C1, self.C2])
        D = np.block([[self.D11, self.D12], [self.D21, self.D22]])
        return control.ss(self.A, B, C, D, states=list(self.state_names),
                          inputs=list(self.w_names) + list(self.u_names),
                          outputs=list(self.p_names) + list(self.y_names), name=name)

    @classmethod
    def from_ss(cls, sys, *, nw: int, ny: int) -> "GeneralizedPlant":
        """Split a ``StateSpace`` with inputs [w, u] and outputs [p, y]."""
        A, B, C, D = (np.asarray(M, dtype=float) for M in (sys.A, sys.B, sys.C, sys.D))
        np_ = C.shape[0] - ny
        if not (0 < nw < B.shape[1] and 0 < ny < C.shape[0]):
            raise InputError(f"generalised plant: expected 0 < nw < {B.shape[1]} and 0 < ny < "
                             f"{C.shape[0]}, found nw = {nw}, ny = {ny}")
        names = lambda lab: list(lab)  # noqa: E731
        return cls(A=A, B1=B[:, :nw], B2=B[:, nw:], C1=C[:np_], C2=C[np_:], D11=D[:np_, :nw],
                   D12=D[:np_, nw:], D21=D[np_:, :nw], D22=D[np_:, nw:],
                   state_names=names(sys.state_labels), w_names=names(sys.input_labels[:nw]),
                   u_names=names(sys.input_labels[nw:]), p_names=names(sys.output_labels[:np_]),
                   y_names=names(sys.output_labels[np_:]))

    def scaled(self) -> tuple["GeneralizedPlant", np.ndarray]:
        """Plant in balanced state coordinates x = T x_b, T diagonal (LAPACK gebal via
        ``scipy.linalg.matrix_balance`` on [[A, B], [C, 0]] restricted to the states).
        The input-output map, and hence any controller, is unchanged."""
        import scipy.linalg as sla
        n = self.A.shape[0]
        B = np.hstack([self.B1, self.B2])
        C = np.vstack([self.C1, self.C2])
        big = np.zeros((n + C.shape[0], n + B.shape[1]))
        big[:n, :n], big[:n, n:], big[n:, :n] = self.A, B, C
        sq = max(big.shape)
        Z = np.zeros((sq, sq))
        Z[: big.shape[0], : big.shape[1]] = big
        _, (s, _) = sla.matrix_balance(Z, permute=False, separate=True)
        t = s[:n] / np.exp2(np.round(np.mean(np.log2(s[:n]))))
        Ti = 1.0 / t
        sp = GeneralizedPlant(A=Ti[:, None] * self.A * t[None, :], B1=Ti[:, None] * self.B1,
                              B2=Ti[:, None] * self.B2, C1=self.C1 * t[None, :],
                              C2=self.C2 * t[None, :], D11=self.D11, D12=self.D12, D21=self.D21,
                              D22=self.D22, state_names=self.state_names, w_names=self.w_names,
                              u_names=self.u_names, p_names=self.p_names, y_names=self.y_names)
        return sp, t

    def reachable_part(self, *, tol: float = 1e-8) -> "GeneralizedPlant":
        """The plant without the states that no input reaches: the controllable part of
        (A, [B1 B2]) by SLICOT TB01PD (job "C", an orthogonal staircase transformation, no
        balancing), with C1, C2 in the new coordinates. The transfer functions from [w; u] to
        [p; y] are unchanged, so is any controller's closed loop from w to p; the removed
        modes keep their own dynamics, which no input excites. ``tol``: TB01PD's rank
        tolerance. The states are renamed ``x_1`` .. ``x_nr`` (mixtures of the original ones).
        """
        from slycot import tb01pd
        n, nw, nu = self.A.shape[0], self.B1.shape[1], self.B2.shape[1]
        npo, ny = self.C1.shape[0], self.C2.shape[0]
        m, p = nw + nu, npo + ny
        B = np.zeros((n, max(m, p)))
        B[:, :m] = np.hstack([self.B1, self.B2])
        C = np.zeros((max(1, m, p), n))
        C[:p] = np.vstack([self.C1, self.C2])
        Ar, Br, Cr, nr = tb01pd(n, m, p, self.A, B, C, job="C", equil="N", tol=tol)
        Ar, Br, Cr = (np.ascontiguousarray(M) for M in (Ar[:nr, :nr], Br[:nr, :m], Cr[:p, :nr]))
        return GeneralizedPlant(A=Ar, B1=Br[:, :nw], B2=Br[:, nw:], C1=Cr[:npo], C2=Cr[npo:],
                                D11=self.D11, D12=self.D12, D21=self.D21, D22=self.D22,
                                state_names=[f"x_{i + 1}" for i in range(nr)], w_names=self.w_names,
                                u_names=self.u_names, p_names=self.p_names, y_names=self.y_names)

    def shifted(self, alpha: float) -> "GeneralizedPlant":
        """The plant with A + alpha I (the alpha-shift of 7.3: a controller whose closed loop
        with the shifted plant is stable has closed-loop poles left of -alpha with the
        original plant once its own A_k is shifted back by -alpha I)."""
        return GeneralizedPlant(**{**self.__dict__, "A": self.A + alpha * np.eye(self.A.shape[0])})

    @classmethod
    def from_system(cls, sys, *, nmeas: int, ncon: int) -> "GeneralizedPlant":
        """The partitioned plant of a python-control ``StateSpace`` or ``TransferFunction``
        with inputs [w, u] and outputs [p, y] (python-control ``hinfsyn``'s convention:
        the last ``ncon`` inputs are u, the last ``nmeas`` outputs are y).

        Raises
        ------
        InputError
            Not an LTI system, a discrete-time system, complex or non-finite data, or sizes
            that leave no w or no p.
        """
        import control
        if isinstance(sys, control.TransferFunction):
            sys = control.ss(sys)
        if not isinstance(sys, control.StateSpace):
            raise InputError(f"plant: expected a python-control StateSpace or TransferFunction, "
                             f"found {type(sys).__name__}")
        if sys.isdtime(strict=True):
            raise InputError(f"plant: expected a continuous-time system (dt = 0), found dt = "
                             f"{sys.dt}: discretize the design or convert the plant (d2c) first")
        for k in ("A", "B", "C", "D"):
            M = np.asarray(getattr(sys, k))
            if np.iscomplexobj(M) and np.any(np.imag(M) != 0):
                raise InputError(f"plant: expected real matrices, found complex {k}")
            if not np.all(np.isfinite(M)):
                raise InputError(f"plant: expected finite matrices, found NaN or inf in {k}")
        for name, v in (("nmeas", nmeas), ("ncon", ncon)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise InputError(f"{name}: expected an integer >= 1, found {v!r}")
        if not (ncon < sys.ninputs and nmeas < sys.noutputs):
            raise InputError(f"plant: expected ncon < {sys.ninputs} inputs and nmeas < "
                             f"{sys.noutputs} outputs (at least one w and one p), found ncon = "
                             f"{ncon}, nmeas = {nmeas}")
        real = control.ss(np.real(sys.A), np.real(sys.B), np.real(sys.C), np.real(sys.D),
                          states=list(sys.state_labels), inputs=list(sys.input_labels),
                          outputs=list(sys.output_labels))
        return cls.from_ss(real, nw=sys.ninputs - ncon, ny=nmeas)
