"""The second coordinate set of the control-oriented model: K membrane relative deflections
at chosen points instead of the modal coordinates eta (eqs. 5.17-5.18)."""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError

_COMPONENTS = {"u": 0, "v": 1, "w": 2}


def point_coordinates(membrane, points) -> tuple[list, np.ndarray, float]:
    """The map v = T_v_eta eta (eq. 5.17) from the modal coordinates to K relative
    deflections v at membrane points, so that eta = T_v_eta^-1 v (eq. 5.18).

    Parameters
    ----------
    membrane : MembraneBasis
    points : list of (component, x_f, y_f)
        K points in O_f; component ``"u"``, ``"v"`` or ``"w"``.

    Returns
    -------
    points : list of (str, float, float)
    T_veta : ndarray (K, K)
    cond : float
        Condition number of T_v_eta (< 1e8, else :class:`InputError`).
    """
    pts = list(points)
    if len(pts) != membrane.K:
        raise InputError(f"membrane point coordinates: expected K = {membrane.K} points "
                         f"(eq. 5.17: k1 + k2 + k3 = K), found {len(pts)}")
    rows = []
    for p in pts:
        if len(p) != 3 or p[0] not in _COMPONENTS:
            raise InputError(f"membrane point coordinate: expected (component in u/v/w, x_f, y_f), found {p!r}")
        Pm = membrane.point_matrix(np.array([[p[1]], [p[2]]]), _COMPONENTS[p[0]])
        rows.append(Pm[0, 1 + membrane.n_delta:])
    Tve = np.array(rows)                                                # eq. 5.17
    cond = np.linalg.cond(Tve)
    if not np.isfinite(cond) or cond > 1e8:
        raise InputError(f"membrane point coordinates (eq. 5.17): T_v_eta must be invertible; "
                         f"its condition number is {cond:.3e} (expected < 1e8): choose other "
                         "points or components")
    return [(p[0], float(p[1]), float(p[2])) for p in pts], Tve, float(cond)
