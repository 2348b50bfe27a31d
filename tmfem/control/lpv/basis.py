"""Basis functions of the parameter dependence of LPV Lyapunov matrices and gains.

A parameter-dependent matrix is written M(rho) = sum_i f_i(rho) M_i with scalar basis
functions f_i of the scheduling parameters rho (a vector of ``n_p`` entries) and constant
coefficients M_i; its derivative along a trajectory is

    dM/dt = sum_i (grad f_i(rho) . rho') M_i,

which is affine in the rate rho', so a rate-bounded LMI holds for every rate in a box iff it
holds at the box's vertices. The basis is the designer's choice: {1, rho_1, ..., rho_np}
(affine, eq. 5.99 of the dissertation), {1, cos rho, sin rho} for a rotating parameter, any
smooth functions. :meth:`Basis.checked` refuses values or gradients that are not finite, a
function with a kink (left and right difference quotients that disagree), a gradient that
does not match its function, and functions that are linearly dependent on the design grid.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError


@dataclass(frozen=True)
class Basis:
    """Scalar basis functions f_i(rho) with their gradients.

    Attributes
    ----------
    functions : tuple of callables
        f_i(rho) -> float, rho an (n_p,) array.
    gradients : tuple of callables or None
        grad f_i(rho) -> (n_p,) array; None: central difference quotients.
    names : tuple of str
    """

    functions: tuple
    gradients: tuple | None
    names: tuple

    def __post_init__(self):
        if not self.functions or not all(callable(f) for f in self.functions):
            raise InputError(f"basis: expected a non-empty sequence of callables f(rho), found "
                             f"{self.functions!r}")
        if self.gradients is not None and (len(self.gradients) != len(self.functions)
                                           or not all(callable(g) for g in self.gradients)):
            raise InputError(f"basis: expected one gradient callable per function ({len(self.functions)}), "
                             f"found {self.gradients!r}")
        if len(self.names) != len(self.functions):
            raise InputError(f"basis: expected {len(self.functions)} names, found {len(self.names)}")

    def __len__(self) -> int:
        return len(self.functions)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def constant(cls) -> Basis:
        """{1}: a parameter-independent matrix (quadratic stability for a Lyapunov matrix)."""
        return cls(functions=(lambda r: 1.0,), gradients=(lambda r: np.zeros(np.size(r)),), names=("1",))

    @classmethod
    def affine(cls, n_parameters: int, *, centre=None, half_width=None, parameters=None) -> Basis:
        """{1, rho_nk for k in ``parameters`` (default all)} with rho_nk = (rho_k - centre_k) /
        half_width_k (eq. 5.99: the same span as {1, rho_k}, better conditioned)."""
        if int(n_parameters) != n_parameters or n_parameters < 1:
            raise InputError(f"affine basis: expected n_parameters >= 1, found {n_parameters!r}")
        n = int(n_parameters)
        c = np.zeros(n) if centre is None else np.asarray(centre, dtype=float).reshape(n)
        h = np.ones(n) if half_width is None else np.asarray(half_width, dtype=float).reshape(n)
        if not (np.all(np.isfinite(c)) and np.all(np.isfinite(h)) and np.all(h > 0)):
            raise InputError(f"affine basis: expected finite centre and half widths > 0, found {c}, {h}")

        def f(k):
            return lambda r: (np.asarray(r, dtype=float)[k] - c[k]) / h[k]

        def g(k):
            return lambda r: np.eye(np.size(r))[k] / h[k]
        ks = range(n) if parameters is None else [int(k) for k in parameters]
        if any(not 0 <= k < n for k in ks):
            raise InputError(f"affine basis: expected parameter indices in [0, {n}), found {list(ks)}")
        return cls(functions=(lambda r: 1.0,) + tuple(f(k) for k in ks),
                   gradients=(lambda r: np.zeros(np.size(r)),) + tuple(g(k) for k in ks),
                   names=("1",) + tuple(f"rho{k}" for k in ks))

    @classmethod
    def trigonometric(cls, *, parameter: int = 0, harmonics: int = 1) -> Basis:
        """{1, cos(h rho_p), sin(h rho_p), h = 1..harmonics} of one parameter (index ``parameter``):
        the dependence of a plant on a rotating angle."""
        if int(harmonics) != harmonics or harmonics < 1 or int(parameter) != parameter or parameter < 0:
            raise InputError(f"trigonometric basis: expected harmonics >= 1 and a parameter index >= 0, "
                             f"found harmonics = {harmonics!r}, parameter = {parameter!r}")
        p = int(parameter)
        funcs, grads, names = [lambda r: 1.0], [lambda r: np.zeros(np.size(r))], ["1"]
        for h in range(1, int(harmonics) + 1):
            funcs += [lambda r, h=h: np.cos(h * np.asarray(r, dtype=float)[p]),
                      lambda r, h=h: np.sin(h * np.asarray(r, dtype=float)[p])]
            grads += [lambda r, h=h: -h * np.sin(h * np.asarray(r, dtype=float)[p]) * np.eye(np.size(r))[p],
                      lambda r, h=h: h * np.cos(h * np.asarray(r, dtype=float)[p]) * np.eye(np.size(r))[p]]
            m = "" if h == 1 else f"{h} "
            names += [f"cos({m}rho{p})", f"sin({m}rho{p})"]
        return cls(functions=tuple(funcs), gradients=tuple(grads), names=tuple(names))

    @classmethod
    def from_functions(cls, functions, *, gradients=None, names=None) -> Basis:
        """Any smooth functions f_i(rho) (gradients optional: central differences otherwise)."""
        functions = tuple(functions)
        names = tuple(names) if names is not None else tuple(f"f{i}" for i in range(len(functions)))
        return cls(functions=functions, gradients=None if gradients is None else tuple(gradients),
                   names=names)

    # ------------------------------------------------------------------ evaluation
    def values(self, points) -> np.ndarray:
        """(m, n_b) values f_i at the rows of ``points`` (m, n_p)."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        with np.errstate(all="ignore"):        # a non-finite value is refused by :meth:`checked`
            return np.array([[float(f(r)) for f in self.functions] for r in pts])

    def derivatives(self, points) -> np.ndarray:
        """(m, n_b, n_p) gradients at the rows of ``points``."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        if self.gradients is not None:
            return np.array([[np.asarray(g(r), dtype=float).reshape(pts.shape[1]) for g in self.gradients]
                             for r in pts])
        return self._difference_quotients(pts, central=True)

    def _difference_quotients(self, pts, *, central, step=None):
        """Central, or (right, left) one-sided, difference quotients along each parameter."""
        h = (1e-6 if central else 1e-4) * np.maximum(1.0, np.abs(pts)) if step is None else step
        out = []
        for k in range(pts.shape[1]):
            e = np.zeros(pts.shape)
            e[:, k] = h[:, k]
            f0, fp, fm = self.values(pts), self.values(pts + e), self.values(pts - e)
            out.append((fp - fm) / (2 * h[:, k:k + 1]) if central else
                       ((fp - f0) / h[:, k:k + 1], (f0 - fm) / h[:, k:k + 1]))
        if central:
            return np.stack(out, axis=-1)
        return np.stack([o[0] for o in out], -1), np.stack([o[1] for o in out], -1)

    def checked(self, design_points, check_points, *, what: str) -> None:
        """Refuse a basis that cannot parametrise a smooth matrix function on this grid.

        Raises
        ------
        InputError
            Values or gradients not finite at a point of ``check_points``; left and right
            difference quotients that differ (a kink); given gradients that differ from the
            central difference quotients; functions linearly dependent at ``design_points``.
        """
        pts = np.atleast_2d(np.asarray(check_points, dtype=float))
        try:
            V, G = self.values(pts), self.derivatives(pts)
        except (TypeError, ValueError, IndexError) as exc:
            raise InputError(f"{what}: expected basis functions f(rho) of {pts.shape[1]} parameter(s) "
                             f"returning a number (gradients an array of {pts.shape[1]}), found: {exc}") from None
        for arr, kind in ((V, "value"), (G, "gradient")):
            bad = ~np.all(np.isfinite(arr.reshape(arr.shape[0], len(self), -1)), axis=2)
            if bad.any():
                j, i = np.argwhere(bad)[0]
                raise InputError(f"{what}: expected finite basis functions, found {kind} of "
                                 f"{self.names[i]!r} = {arr[j, i]} at rho = {pts[j].tolist()}")
        right, left = self._difference_quotients(pts, central=False)
        scale = 1.0 + np.abs(G)
        kink = np.abs(right - left) / scale
        if kink.max() > 1e-2:
            j, i, k = np.unravel_index(np.argmax(kink), kink.shape)
            raise InputError(f"{what}: expected smooth basis functions, found {self.names[i]!r} with a kink "
                             f"at rho = {pts[j].tolist()} (slopes {left[j, i, k]:.6g} from the left, "
                             f"{right[j, i, k]:.6g} from the right in rho{k})")
        if self.gradients is not None:
            mism = np.abs(G - self._difference_quotients(pts, central=True)) / scale
            if mism.max() > 1e-4:
                j, i, k = np.unravel_index(np.argmax(mism), mism.shape)
                raise InputError(f"{what}: expected the gradient of {self.names[i]!r} to match the function, "
                                 f"found d/drho{k} = {G[j, i, k]:.6g} against the difference quotient "
                                 f"{(left[j, i, k] + right[j, i, k]) / 2:.6g} at rho = {pts[j].tolist()}")
        Vd = self.values(design_points)
        s = np.linalg.svd(Vd, compute_uv=False)
        if Vd.shape[0] < len(self) or s[-1] <= 1e-9 * s[0]:
            raise InputError(f"{what}: expected basis functions {list(self.names)} linearly independent on "
                             f"the {Vd.shape[0]} design points, found singular values of their values "
                             f"{np.array2string(s, precision=3)}")
