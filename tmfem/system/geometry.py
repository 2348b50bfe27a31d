"""Geometry of symmetric systems and the generalised coordinates q (eqs. 3.1-3.3, 3.19-3.22).

Conventions (dissertation 2.2, 3.2): the inertial frame has its origin at A_1N and its x
axis through A_11, so the base polygon runs counter-clockwise A_11, ..., A_1N. Seen from
the centre of a regular N-gon, vertex j lies at the angle beta_j of eq. 3.21,

    beta_j = -(N + 2) pi / (2N) + 2 j pi / N,

which is also the direction of membrane corner j from the membrane centre. A bar with
declination theta (from Oz) and azimuth psi (from Ox) points along
``(sin theta cos psi, sin theta sin psi, cos theta)``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError
from tmfem.system.coordinates import join_q


def beta(N: int) -> np.ndarray:
    """Polar angles beta_j (j = 1..N) of the polygon vertices about the centre (eq. 3.21)."""
    j = np.arange(1, N + 1)
    return -(N + 2) * np.pi / (2 * N) + 2 * j * np.pi / N


def wrap_angle(a):
    """Map angles to (-pi, pi], the range of the azimuths psi_ij (3.2)."""
    return np.pi - np.mod(np.pi - np.asarray(a, dtype=float), 2 * np.pi)


def bar_direction(theta, psi) -> np.ndarray:
    """Unit vector of a bar with declination theta and azimuth psi, shape (3, ...)."""
    theta = np.asarray(theta, dtype=float)
    psi = np.asarray(psi, dtype=float)
    return np.array([np.sin(theta) * np.cos(psi), np.sin(theta) * np.sin(psi), np.cos(theta)])


def base_centre(N: int, r1: float) -> np.ndarray:
    """Centre of the stage-1 base polygon in the inertial frame: (r_1 sin(pi/N), r_1 cos(pi/N), 0)."""
    return np.array([r1 * np.sin(np.pi / N), r1 * np.cos(np.pi / N), 0.0])


def regular_polygon(N: int, radius, centre, rotation=0.0) -> np.ndarray:
    """Vertices of horizontal regular N-gons at the angles beta_j + rotation about their centres,

        X_j = centre + radius (cos(beta_j + rotation), sin(beta_j + rotation), 0),

    shape (3, N) for one polygon, or (3, K, N) for K polygons (``radius`` and ``rotation`` of
    shape (K,), ``centre`` of shape (3, K))."""
    b = beta(N) + np.asarray(rotation, dtype=float)[..., None]
    c = np.asarray(centre, dtype=float)[..., None]
    radius = np.asarray(radius, dtype=float)[..., None]
    return c + radius * np.array([np.cos(b), np.sin(b), np.zeros_like(b)])


def membrane_corners_regular(N: int, r_mb: float) -> np.ndarray:
    """Undeformed corners (2, N) of the regular membrane in the floating frame O_f (3.2).

    O_f is at corner N and x_f runs from corner N through corner 1.
    """
    xy = regular_polygon(N, r_mb, (0.0, 0.0, 0.0))[:2]
    return xy - xy[:, [-1]]


def cross3(a, b) -> np.ndarray:
    """The cross product a x b = (a_y b_z - a_z b_y, a_z b_x - a_x b_z, a_x b_y - a_y b_x) of two
    3-vectors: the products and differences of ``np.cross`` without its set-up for stacks of
    vectors, which costs ten times as much for one pair."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def floating_frame(corners_3d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Origin and axes of the floating frame O_f-x_f y_f z_f (3.2) from the corners B_Mj.

    O_f = B_MN; x_f goes through B_M1; the plane x_f y_f is the plane of B_MN, B_M1 and
    B_M,N-1, with y_f on the side of B_M,N-1 (so the undeformed corners P_i of a
    counter-clockwise membrane have y_f >= 0, as eq. 3.5 assumes); z_f = x_f x y_f (right-hand
    rule). The columns of R are the O_f axes in the inertial frame, R = R^ef of eq. 3.3.

    Parameters
    ----------
    corners_3d : ndarray (3, N)
        Positions of B_M1, ..., B_MN in the inertial frame, N >= 3.

    Returns
    -------
    origin : ndarray (3,)
        B_MN.
    R : ndarray (3, 3)
        Rotation O_f -> O-xyz (columns e_xf, e_yf, e_zf).

    Raises
    ------
    InputError
        if the array is not (3, N >= 3) or B_MN, B_M1, B_M,N-1 are collinear (the frame of
        3.2 is then undefined).
    """
    c = np.asarray(corners_3d, dtype=float)
    if c.ndim != 2 or c.shape[0] != 3 or c.shape[1] < 3:
        raise InputError(f"floating frame: expected corners of shape (3, N >= 3), found {c.shape}")
    o = c[:, -1]
    x1, v = c[:, 0] - o, c[:, -2] - o
    n1, nv = np.linalg.norm(x1), np.linalg.norm(v)
    ex = x1 / n1 if n1 > 0 else x1
    ez = cross3(ex, v)
    nz = np.linalg.norm(ez)
    if n1 == 0 or nz == 0 or nz < 1e-12 * nv:
        raise InputError("corners B_MN, B_M1, B_M,N-1 are collinear: the floating frame O_f "
                         f"of 3.2 is undefined (|B_M1 - B_MN| = {n1:.3g} m, "
                         f"|B_M,N-1 - B_MN| = {nv:.3g} m, sine of their angle {nz / max(nv, 1e-300):.3g})")
    ez = ez / nz
    return o, np.column_stack([ex, cross3(ez, ex), ez])


def free_corner_components(N: int) -> list[tuple[int, int]]:
    """The 3N-6 free corner displacements of eq. 3.5 in the order of eqs. 3.4 and 5.14.

    Delta_u1; Delta_ui, Delta_vi, Delta_wi (2 <= i <= N-2); Delta_u,N-1, Delta_v,N-1 (corner
    N is O_f, corner 1 lies on x_f and corner N-1 in the plane x_f y_f).

    Returns
    -------
    list of (corner index 0..N-1, component 0=u 1=v 2=w)
    """
    out = [(0, 0)]
    for i in range(1, N - 2):
        out += [(i, 0), (i, 1), (i, 2)]
    out += [(N - 2, 0), (N - 2, 1)]
    return out


def rotation_ef(gamma) -> np.ndarray:
    """Rotation matrix R^ef of the 3-2-1 Euler angles (gamma_1, gamma_2, gamma_3), eq. 3.3.

    R^ef = Rz(gamma_1) Ry(gamma_2) Rx(gamma_3); its columns are the O_f axes in O-xyz. The
    casadi version for automatic differentiation is
    :func:`tmfem.models.com.kinematics.rotation_ef_sx`.

    Parameters
    ----------
    gamma : array_like (3,)

    Returns
    -------
    ndarray (3, 3)
    """
    g1, g2, g3 = gamma
    c1, s1, c2, s2, c3, s3 = np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2), np.cos(g3), np.sin(g3)
    return np.array([[c1 * c2, c1 * s2 * s3 - c3 * s1, c1 * c3 * s2 + s1 * s3],
                     [c2 * s1, c1 * c3 + s1 * s2 * s3, c3 * s1 * s2 - c1 * s3],
                     [-s2, c2 * s3, c2 * c3]])


def euler_angles_321(R: np.ndarray) -> np.ndarray:
    """3-2-1 Euler angles (gamma_1, gamma_2, gamma_3) of a rotation R^ef (inverse of eq. 3.3).

    Parameters
    ----------
    R : ndarray (3, 3)

    Returns
    -------
    ndarray (3,)
        gamma_1, gamma_3 in (-pi, pi], gamma_2 in [-pi/2, pi/2] (unique for |gamma_2| < pi/2).
    """
    return np.array([np.arctan2(R[1, 0], R[0, 0]), -np.arcsin(np.clip(R[2, 0], -1.0, 1.0)),
                     np.arctan2(R[2, 1], R[2, 2])])


@dataclass(frozen=True)
class SymmetricConfig:
    """Symmetric parametrisation of an M-N or 1-N(D) configuration (3.3.1, eqs. 3.19-3.20).

    All arrays have length M; angles are in radians. ``psi[i]`` is the absolute azimuth of
    bar b_iN, so bar b_ij has azimuth psi_i + 2 j pi / N (eq. 3.20); ``sigma[i]`` is the
    rotation of the base of stage i about the vertical axis and ``z[i]`` its height
    (sigma_1 = z_1 = 0); ``r[i]`` is the circumradius of the base of stage i and ``l[i]``
    the bar length.
    """

    theta: np.ndarray
    psi: np.ndarray
    sigma: np.ndarray
    z: np.ndarray
    r: np.ndarray
    l: np.ndarray

    def __post_init__(self):
        arrays = {k: np.atleast_1d(np.asarray(getattr(self, k), dtype=float))
                  for k in ("theta", "psi", "sigma", "z", "r", "l")}
        M = len(arrays["theta"])
        for k, v in arrays.items():
            if v.shape != (M,):
                raise InputError(f"symmetric configuration: expected {k} of length M={M}, "
                                 f"found shape {v.shape}")
            if not np.isfinite(v).all():
                raise InputError(f"symmetric configuration: {k} has non-finite entries {v}")
            object.__setattr__(self, k, v)
        for k in ("r", "l"):
            if (arrays[k] <= 0).any():
                raise InputError(f"symmetric configuration: expected {k} > 0, found {arrays[k]}")
        th = arrays["theta"]
        if ((th <= 0) | (th >= np.pi / 2)).any():
            raise InputError("symmetric configuration: expected 0 < theta < 90 deg, found "
                             f"{np.degrees(th)} deg")
        if arrays["sigma"][0] != 0 or arrays["z"][0] != 0:
            raise InputError("symmetric configuration: stage 1 has sigma_1 = z_1 = 0, found "
                             f"sigma_1={arrays['sigma'][0]}, z_1={arrays['z'][0]}")

    @property
    def M(self) -> int:
        return len(self.theta)

    def base_nodes(self, N: int) -> np.ndarray:
        """Lower bar ends A_ij, shape (3, M, N)."""
        c = np.repeat(base_centre(N, self.r[0])[:, None], self.M, axis=1)
        c[2] += self.z
        return regular_polygon(N, self.r, c, self.sigma)

    def angles(self, N: int) -> tuple[np.ndarray, np.ndarray]:
        """theta_ij and psi_ij, each (M, N), from eqs. 3.19-3.20."""
        j = np.arange(1, N + 1)
        theta = np.repeat(self.theta[:, None], N, axis=1)
        psi = wrap_angle(self.psi[:, None] + 2 * np.pi * j[None, :] / N)
        return theta, psi

    def to_q(self, N: int) -> np.ndarray:
        """Generalised coordinates q of eqs. 3.1-3.2."""
        theta, psi = self.angles(N)
        return join_q(self.base_nodes(N), theta, psi)

    def system_arrays(self, N: int) -> dict:
        """The :class:`tmfem.system.System` fields this configuration fixes: ``q`` (eqs.
        3.1-3.2), ``base`` A_1j (3, N) and the bar lengths ``l`` (M, N)."""
        A = self.base_nodes(N)
        return {"q": join_q(A, *self.angles(N)), "base": A[:, 0, :],
                "l": np.repeat(self.l[:, None], N, axis=1)}

    def membrane_delta(self, N: int, r_mb: float) -> float:
        """Radial membrane corner displacement Delta of eq. 3.22 (:func:`membrane_delta`)."""
        return float(membrane_delta(l_M=self.l[-1], theta_M=self.theta[-1], psi_M=self.psi[-1],
                                    sigma_M=self.sigma[-1], r_M=self.r[-1], r_mb=r_mb, N=N))


def membrane_delta(*, l_M, theta_M, psi_M, sigma_M, r_M, r_mb, N):
    """Radial membrane corner displacement Delta of a symmetric system (eq. 3.22).

    Parameters are those of the top stage M (radians). Delta > 0 means a stretched
    membrane.
    """
    L = l_M * np.sin(theta_M)
    return -r_mb + np.sqrt(L**2 + r_M**2 - 2 * r_M * L * np.sin(psi_M - sigma_M + np.pi / N))
