"""Gaussian radial-basis-function network with a projection-based adaptation law
(dissertation eqs. 5.44, 5.51-5.52).

Basis (eq. 5.44): Phi_i(v) = exp(-|v - c_i|^2 / (2 sigma^2)), v = [q; q'].

Projection (eqs. 5.51-5.52), applied column by column to W (m x n_q): for a column w with
bound w_bar and tolerance eps > 0 the convex function

    f(w) = ((1 + eps) |w|^2 - w_bar^2) / (eps w_bar^2)

is <= 0 inside the ball |w| <= w_bar / sqrt(1 + eps) and = 1 on |w| = w_bar. The operator

    Proj(w, y) = y - grad f (grad f^T y) f(w) / |grad f|^2   if f(w) > 0 and y^T grad f > 0,
               = y                                           otherwise,

keeps f(w(t)) <= 1 (|w| <= w_bar) along w' = Proj(w, y) and satisfies
(w - w*)^T (Proj(w, y) - y) <= 0 for every w* with f(w*) <= 0, i.e.
Tr(Delta W^T (Y - Proj(W, Y))) <= 0 with Delta W = W* - W (the property used in eq. 5.53).
The sampled controller integrates the law by explicit Euler over dt; a column that the step
would carry outside |w| <= w_bar is scaled back onto it (:func:`euler_step`), so the bound
holds at every sample too.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError


class GaussianRBF:
    """m Gaussian functions (eq. 5.44) with centres C (m, n_v) and one width sigma."""

    def __init__(self, *, centers, sigma: float):
        self.centers = np.atleast_2d(np.asarray(centers, dtype=float))
        if not (np.isfinite(sigma) and sigma > 0):
            raise InputError(f"RBF width sigma_q: expected > 0, found {sigma!r}")
        self.sigma = float(sigma)

    @property
    def m(self) -> int:
        return self.centers.shape[0]

    def __call__(self, v) -> np.ndarray:
        """Phi(v), shape (m,) (eq. 5.44)."""
        d = self.centers - np.asarray(v, dtype=float)[None, :]
        return np.exp(-np.einsum("ij,ij->i", d, d) / (2 * self.sigma**2))


def projection(W, Y, *, bound: float, eps: float = 0.1) -> np.ndarray:
    """Column-wise projection operator Proj(W, Y) (eqs. 5.51-5.52, module docstring)."""
    W = np.asarray(W, dtype=float)
    Y = np.asarray(Y, dtype=float)
    if not (bound > 0 and eps > 0):
        raise InputError(f"projection: expected bound > 0 and eps > 0, found {bound!r}, {eps!r}")
    n2 = np.sum(W**2, axis=0)
    f = ((1 + eps) * n2 - bound**2) / (eps * bound**2)
    g = 2 * (1 + eps) * W / (eps * bound**2)                         # grad f, column-wise
    gy = np.sum(g * Y, axis=0)
    gg = np.sum(g * g, axis=0)
    active = (f > 0) & (gy > 0)
    corr = np.zeros_like(f)
    corr[active] = gy[active] * f[active] / gg[active]
    return Y - g * corr[None, :]


def euler_step(W, Y, *, dt: float, bound: float, eps: float = 0.1) -> np.ndarray:
    """W + dt Proj(W, Y), each column then kept in |w| <= bound (module docstring)."""
    Wn = np.asarray(W, dtype=float) + dt * projection(W, Y, bound=bound, eps=eps)
    n = np.linalg.norm(Wn, axis=0)
    over = n > bound
    Wn[:, over] *= bound / n[over]
    return Wn
