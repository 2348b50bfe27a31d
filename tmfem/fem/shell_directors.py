"""The director field of a degenerated shell element at its integration and tying points.

Nodal directors d_k = (a/2) V_n^k (a: thickness) are interpolated with the element's shape
functions, D = sum h_k d_k, D_alpha = sum h_k,alpha d_k, and the director used in the
geometry x = sum h_k x_k + r_3 a_d is either

* ``"linear"``: a_d = D, the director of eq. 4.12 read literally; between two nodal directors
  at an angle dtheta its length shrinks to cos(dtheta/2) and its rate of turn is the chord
  2 sin(dtheta/2) per element, not dtheta; or
* ``"normalized"``: a_d = (a/2) D/|D| (a unit normal times a/2 at every point: the director
  of the degenerated continuum is inextensible). At the 2-point Gauss abscissae of an element
  its rate of turn is 2 tan(dtheta/2)/(1 + tan^2(dtheta/2)/3) = dtheta (1 + O(dtheta^4)), so a
  uniformly bent strip has the curvature of its nodal rotations (docs/shells.md, 4.5.2).

With rho = |D|, n = D/rho, P = I - n n^T and s = (a/2)/rho the normalized field is

    a_d = s D,   a_d,alpha = s P D_alpha,

its variations delta a_d = s P delta D and
delta a_d,alpha = s P delta D_alpha - (s/rho) M(D_alpha) delta D with the symmetric

    M(v) = v n^T + n v^T + (n.v) (I - 3 n n^T),

the Hessian of v.a_d in D is -(s/rho) M(v), and that of v.a_d,alpha in (D, D_alpha) has the
blocks -(s/rho) M(v) (mixed) and (:meth:`DirectorField.hess_DD`)

    (s/rho^2) [(3 b c - A) I + (3 A - 15 b c) n n^T - (v D_a^T + D_a v^T)
               + 3 c (v n^T + n v^T) + 3 b (D_a n^T + n D_a^T)],   A = v.D_a, b = v.n, c = n.D_a.

All arrays carry the points as leading axes (elements, points); methods broadcast over any
extra axes of the vectors they act on.
"""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError

DIRECTOR_INTERPOLATIONS = ("normalized", "linear")


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


class DirectorField:
    """Director a_d (..., 3) and its derivatives a_d,alpha (..., 2, 3) at points, with their
    changes from the reference computed without cancellation.

    Parameters
    ----------
    D0, Da0 : reference D (..., 3) and D_alpha (..., 2, 3) at the points
    W, Wa : their changes (current minus reference), same shapes
    half : a / 2 [m]
    interpolation : ``"normalized"`` or ``"linear"`` (module docstring)
    """

    def __init__(self, D0, Da0, W, Wa, *, half: float, interpolation: str = "normalized"):
        if interpolation not in DIRECTOR_INTERPOLATIONS:
            raise InputError(f"shell directors: expected interpolation in {DIRECTOR_INTERPOLATIONS}, "
                             f"found {interpolation!r}")
        self.normalized = interpolation == "normalized"
        W = np.broadcast_to(np.asarray(W, dtype=float), np.shape(D0))
        Wa = np.broadcast_to(np.asarray(Wa, dtype=float), np.shape(Da0))
        D, Da = D0 + W, Da0 + Wa
        self.Da = Da
        if not self.normalized:
            self.a, self.aa, self.da, self.daa = D, Da, W, Wa
            return
        rho0, rho = np.linalg.norm(D0, axis=-1), np.linalg.norm(D, axis=-1)
        if np.any(rho <= 1e-12 * half):
            raise InputError("shell directors: expected interpolated directors of non-zero length, found "
                             "opposite nodal directors in an element")
        s0, s = half / rho0, half / rho
        self.rho, self.s, self.n = rho, s, D / rho[..., None]
        # rho^2 - rho0^2 = W.(D + D0): the differences below carry no cancellation
        dr2 = _dot(W, D + D0)
        drho = dr2 / (rho + rho0)
        ds = -half * drho / (rho * rho0)
        q0, q = s0 / rho0**2, s / rho**2
        dq = -half * drho * (rho**2 + rho * rho0 + rho0**2) / (rho * rho0) ** 3
        C0 = np.einsum("...i,...ai->...a", D0, Da0)
        dC = np.einsum("...i,...ai->...a", W, Da) + np.einsum("...i,...ai->...a", D0, Wa)
        self.a = s[..., None] * D
        self.da = s[..., None] * W + ds[..., None] * D0
        # a_d,alpha = s D_alpha - q (D.D_alpha) D
        self.aa = s[..., None, None] * Da - (q[..., None] * (C0 + dC))[..., None] * D[..., None, :]
        self.daa = (s[..., None, None] * Wa + ds[..., None, None] * Da0
                    - (dq[..., None] * (C0 + dC))[..., None] * D[..., None, :]
                    - (q0[..., None] * dC)[..., None] * D[..., None, :]
                    - (q0[..., None] * C0)[..., None] * W[..., None, :])

    def _b(self, v):
        """Broadcast the point arrays against a vector v (..., extra, 3) whose extra axes
        follow the point axes."""
        extra = v.ndim - self.n.ndim
        sh = self.n.shape[:-1] + (1,) * extra
        return self.s.reshape(sh), self.rho.reshape(sh), self.n.reshape(sh + (3,))

    def sP(self, v):
        """s P v (d a_d / d D, transposed, applied to v; v for the linear field)."""
        if not self.normalized:
            return v
        s, _, n = self._b(v)
        return s[..., None] * (v - _dot(n, v)[..., None] * n)

    def m(self, v, w):
        """(s/rho) M(v) w (symmetric in v, w; zero for the linear field)."""
        if not self.normalized:
            return np.zeros(np.broadcast_shapes(v.shape, w.shape))
        s, rho, n = self._b(v if v.ndim >= w.ndim else w)
        nv, nw = _dot(n, v), _dot(n, w)
        return (s / rho)[..., None] * (v * nw[..., None] + n * _dot(v, w)[..., None] + nv[..., None] * w
                                       - 3 * (nv * nw)[..., None] * n)

    def sP_matrix(self):
        """s P (..., 3, 3) (the identity for the linear field)."""
        if not self.normalized:
            return np.broadcast_to(np.eye(3), self.a.shape + (3,))
        return self.s[..., None, None] * (np.eye(3) - self.n[..., :, None] * self.n[..., None, :])

    def M_matrix(self, v):
        """(s/rho) M(v) (..., 3, 3) for vectors v (..., extra, 3) at the points."""
        if not self.normalized:
            return np.zeros(v.shape + (3,))
        s, rho, n = self._b(v)
        nv = _dot(n, v)
        outer = v[..., :, None] * n[..., None, :]
        M = outer + np.swapaxes(outer, -1, -2) + nv[..., None, None] * (np.eye(3) - 3 * n[..., :, None] * n[..., None, :])
        return (s / rho)[..., None, None] * M

    def hess_DD(self, v, alpha: int):
        """Hessian (..., 3, 3) of v . a_d,alpha in D (v (..., 3) at the points; module docstring)."""
        if not self.normalized:
            return np.zeros(v.shape + (3,))
        n, Da = self.n, self.Da[..., alpha, :]
        A, b, c = _dot(v, Da), _dot(v, n), _dot(n, Da)

        def sym(x, y):
            o = x[..., :, None] * y[..., None, :]
            return o + np.swapaxes(o, -1, -2)
        H = ((3 * b * c - A)[..., None, None] * np.eye(3)
             + (3 * A - 15 * b * c)[..., None, None] * n[..., :, None] * n[..., None, :]
             - sym(v, Da) + 3 * c[..., None, None] * sym(v, n) + 3 * b[..., None, None] * sym(Da, n))
        return (self.s / self.rho**2)[..., None, None] * H
