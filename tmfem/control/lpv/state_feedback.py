"""The gridded LPV state feedback K(rho) = Q(rho) P(rho)^-1 of eq. 5.99: its coefficients,
its evaluation at a parameter value and its file format."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from tmfem.io.npz import read_npz
from tmfem.errors import InputError


@dataclass
class LPVStateFeedback:
    """Result of :func:`synthesize_state_feedback`: K(rho) = Q(rho) P(rho)^-1 (eq. 5.99).

    ``P[k]``, ``Q[k]`` (k = 0..n_p) are the coefficients in the normalised parameters
    rho_n = (rho - center) / half_width (k = 0 the constant term); :meth:`P_of`, :meth:`Q_of`
    and :meth:`gain` evaluate them at a parameter value in the original units.
    """

    gamma: float
    P: list
    Q: list
    center: np.ndarray
    half_width: np.ndarray
    varying: list
    axes: list
    parameter_names: list
    rate_bounds: np.ndarray
    state_names: list
    solver: str
    status: str
    solve_time: float
    build_time: float
    sizes: dict
    max_lmi_eig: float
    min_P_eig: float

    def _basis(self, rho) -> np.ndarray:
        rho = np.asarray(rho, dtype=float).reshape(-1)
        if rho.size != len(self.center):
            raise InputError(f"LPV controller: expected {len(self.center)} parameter values, found {rho.size}")
        return np.concatenate([[1.0], ((rho - self.center) / self.half_width)[self.varying]])

    def P_of(self, rho) -> np.ndarray:
        """P(rho) (eq. 5.99)."""
        return sum(c * Pk for c, Pk in zip(self._basis(rho), self.P))

    def Q_of(self, rho) -> np.ndarray:
        """Q(rho) (eq. 5.99)."""
        return sum(c * Qk for c, Qk in zip(self._basis(rho), self.Q))

    def gain(self, rho) -> np.ndarray:
        """K(rho) = Q(rho) P(rho)^-1 (8.3)."""
        return sla.solve(self.P_of(rho), self.Q_of(rho).T, assume_a="pos").T

    def summary(self) -> dict:
        return {"gamma": self.gamma, "solver": self.solver, "status": self.status,
                "solve_time_s": self.solve_time, "build_time_s": self.build_time,
                "sizes": self.sizes, "max_lmi_eig": self.max_lmi_eig, "min_P_eig": self.min_P_eig}

    def arrays(self) -> dict:
        """The coefficients, gamma and grid as arrays (the contents of :meth:`save`)."""
        return dict(gamma=self.gamma, P=np.array(self.P), Q=np.array(self.Q), centre=self.center,
                    half_width=self.half_width, varying=np.isin(np.arange(len(self.center)), self.varying),
                    rate_bounds=self.rate_bounds, parameter_names=np.array(self.parameter_names),
                    state_names=np.array(self.state_names),
                    **{f"axis_{k}": a for k, a in enumerate(self.axes)})

    def save(self, path) -> None:
        """Write the coefficients, gamma and grid to an ``.npz`` file."""
        np.savez(path, **self.arrays())

    @classmethod
    def load(cls, path) -> "LPVStateFeedback":
        """The coefficients, gamma and grid written by :meth:`save` (sizes and residuals are
        re-computed by whoever uses it: :func:`tmfem.control.lpv.verify.verify`).

        Raises
        ------
        InputError
            Not a file written by :meth:`save`.
        """
        d = read_npz(path, expected="an .npz LPV controller written by `tmfem control lpv "
                                    "--save`")
        try:
            keys = ("gamma", "P", "Q", "centre", "half_width", "varying", "rate_bounds",
                    "parameter_names", "state_names")
            f = {k: d[k] for k in keys}
        except (OSError, KeyError, ValueError) as exc:
            raise InputError(f"LPV controller file {str(path)!r}: expected an .npz written by "
                             f"`tmfem control lpv --save` (keys gamma, P, Q, ...), found {exc}") from None
        axes = [d[f"axis_{k}"] for k in range(len(f["parameter_names"]))]
        P, Q = list(f["P"]), list(f["Q"])
        varying = [k for k, a in enumerate(axes) if a.size > 1]      # as in the synthesis
        if len(P) != 1 + len(varying) or len(Q) != len(P):
            raise InputError(f"LPV controller file {str(path)!r}: expected {1 + len(varying)} coefficients "
                             f"P_k, Q_k (eq. 5.99 on its grid), found {len(P)} and {len(Q)}")
        return cls(gamma=float(f["gamma"]), P=P, Q=Q, center=f["centre"], half_width=f["half_width"],
                   varying=varying, axes=axes,
                   parameter_names=[str(v) for v in f["parameter_names"]], rate_bounds=f["rate_bounds"],
                   state_names=[str(v) for v in f["state_names"]], solver="loaded", status=f"from {path}",
                   solve_time=0.0, build_time=0.0, sizes={"n_x": P[0].shape[0], "coefficients": len(P)},
                   max_lmi_eig=float("nan"), min_P_eig=float("nan"))
