"""Hinged cylindrical roof under a central point load, snap-through traced by arc length
(Sze, Liu & Lo 2004, test 3.8, isotropic roof h = 12.7)."""
from __future__ import annotations

import numpy as np

NAME = "shell-hinged-roof"
HELP = ("hinged cylindrical roof (R = 2540, half length 254, half angle 0.1 rad, h = 12.7, E = 3102.75, "
        "nu = 0.3) under a central point load up to P_max = 3000, quarter model 16 x 16 MITC4, arc length "
        "through both limit points, against Sze, Liu & Lo, Finite Elem. Anal. Des. 40 "
        "(2004) 1551, test 3.8")
COLUMNS = {"W_C": "1", "P_ratio": "1", "P_ratio_ref": "1"}

R, HALF_LENGTH, HALF_ANGLE, E_MOD, NU, P_MAX = 2540.0, 254.0, 0.1, 3102.75, 0.3, 3000.0
#: P/P_max and the central deflection -W_C of Sze, Liu & Lo (2004), isotropic roof h = 12.7
#: (table as given in MBDyn's tests/plates/sze2004/sze38/sze38_ref_a.dat)
REFERENCE = np.array([
    [0.0000, 0.000], [0.0877, 0.693], [0.1980, 1.638], [0.3473, 3.087], [0.4686, 4.477],
    [0.5647, 5.802], [0.6381, 7.057], [0.6908, 8.237], [0.7246, 9.339], [0.7412, 10.358],
    [0.7421, 11.293], [0.7286, 12.141], [0.7023, 12.903], [0.6649, 13.583], [0.6182, 14.188],
    [0.5643, 14.728], [0.5055, 15.217], [0.4442, 15.676], [0.3830, 16.125], [0.3245, 16.590],
    [0.2717, 17.094], [0.2272, 17.657], [0.1940, 18.299], [0.1750, 19.028], [0.1729, 19.852],
    [0.1905, 20.771], [0.2303, 21.780], [0.2950, 22.875], [0.3871, 24.049], [0.4443, 24.663],
    [0.5093, 25.293], [0.5826, 25.940], [0.6644, 26.601], [0.7551, 27.276], [0.8549, 27.964],
    [0.9643, 28.663], [1.0835, 29.374]])
SOURCE = ("K.Y. Sze, X.H. Liu, S.H. Lo, Popular benchmark problems for geometric nonlinear analysis of "
          "shells, Finite Elem. Anal. Des. 40 (2004) 1551-1569, test 3.8 (table via MBDyn "
          "tests/plates/sze2004/sze38/sze38_ref_a.dat)")


def model(*, n: int = 16, h: float = 12.7):
    """Quarter roof (theta in [0, 0.1], y in [0, 254]) with the axis along y, n x n MITC4,
    directors outward: symmetry planes x = 0 and y = 0 (the loaded centre is on both), the
    straight edge theta = 0.1 hinged (translations fixed), the curved edge free, P_max / 4 at
    the centre along -z. Returns (structure, centre node)."""
    from skfem import MeshQuad
    from tmfem.fem.mitc4 import ShellSection
    from tmfem.fem.structure import Structure
    m = MeshQuad.init_tensor(np.linspace(0.0, HALF_ANGLE, n + 1), np.linspace(0.0, HALF_LENGTH, n + 1))
    th, y = m.p
    radial = np.vstack([np.sin(th), 0 * th, np.cos(th)])
    s = Structure.shell((np.vstack([R * np.sin(th), y, R * np.cos(th)]), m.t),
                        section=ShellSection(E=E_MOD, nu=NU, thickness=h), normals=radial,
                        orient=lambda x, y, z: np.vstack([x, 0 * x, z]))
    s.symmetry(s.nodes_where(lambda x, y, z: np.isclose(x, 0.0)), normal="x")
    s.symmetry(s.nodes_where(lambda x, y, z: np.isclose(y, 0.0)), normal="y")
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, R * np.sin(HALF_ANGLE))), ["ux", "uy", "uz"])
    c = s.nodes_where(lambda x, y, z: np.isclose(x, 0.0) & np.isclose(y, 0.0))
    s.point_load(c, force=(0.0, 0.0, -P_MAX / 4))
    return s, int(c[0])


def trace(s, c, *, dl: float, w_end: float):
    """Arc-length path (P/P_max, W_C) from the reference state until W_C exceeds ``w_end``."""
    path = s.solve_arc_length(dl=dl, dl_max=2 * dl, max_steps=500,
                              stop=lambda st, lam: -(st.x[2, c] - s.X[2, c]) > w_end)
    if path.reason != "stopped":
        from tmfem.errors import ConvergenceError
        raise ConvergenceError(f"hinged roof: expected to pass W_C = {w_end}, stopped ({path.reason}): {path.message}")
    W = np.array([-(st.x[2, c] - s.X[2, c]) for st in path])
    return path, W


def run(*, reduced: bool = False) -> dict:
    """The path on the 16 x 16 quarter (``reduced``: 8 x 8, 3.5 % off at the end of the path)
    and P/P_max at the reference deflections by a cubic spline through the path (W_C grows
    monotonically along it)."""
    import time
    from scipy.interpolate import CubicSpline
    s, c = model(n=8 if reduced else 16)
    t0 = time.perf_counter()
    path, W = trace(s, c, dl=1.0, w_end=REFERENCE[-1, 1])
    seconds = time.perf_counter() - t0
    if np.any(np.diff(W) <= 0):
        from tmfem.errors import ConvergenceError
        raise ConvergenceError("hinged roof: expected W_C to grow along the path, found it turning back")
    P = CubicSpline(W, path.lam)(REFERENCE[:, 1])
    rows = [{"W_C": float(w), "P_ratio": float(p), "P_ratio_ref": float(r)}
            for w, p, r in zip(REFERENCE[:, 1], P, REFERENCE[:, 0])]
    limit_ref = REFERENCE[REFERENCE[:, 1] < 12.0, 0].max()
    err = float(np.max(np.abs(P - REFERENCE[:, 0])) / limit_ref)
    return {"rows": rows, "source": SOURCE, "max_error_over_path": err,
            "error_measure": "max over the reference points of |P_FE - P_ref| at the same W_C / the reference "
                             "limit load 0.7421 P_max",
            "limit_load_ratio": float(path.lam[:np.argmax(W > 12.0)].max()), "limit_load_ratio_ref": float(limit_ref),
            "steps": len(path) - 1, "events": [e for _, e in path.events], "seconds": seconds,
            "path": {"P_ratio": [float(v) for v in path.lam], "W_C": [float(v) for v in W]}}


def plot(result: dict, png):
    """Load against the central deflection: the arc-length path and the reference."""
    from tmfem.post.plots import plot_xy
    return plot_xy(png, {"MITC4 16 x 16 quarter, arc length": (result["path"]["W_C"], result["path"]["P_ratio"]),
                         "Sze et al. 2004": (REFERENCE[:, 1], REFERENCE[:, 0])},
                   xlabel="central deflection -W_C", ylabel="P / P_max", title="hinged cylindrical roof, h = 12.7")
