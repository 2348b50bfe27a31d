"""Pinched cylinder with rigid diaphragms in the large-deflection range (Sze, Liu & Lo 2004,
test 3.6)."""
from __future__ import annotations

import numpy as np

NAME = "shell-pinched-cylinder-nonlinear"
HELP = ("pinched cylinder with rigid end diaphragms (R = 100, L = 200, h = 1, E = 3e4, nu = 0.3) under two "
        "opposite point loads up to P_max = 12000, octant 40 x 40 MITC4, displacement control at the load "
        "point, -W_A and U_B against Sze, Liu & Lo, Finite Elem. Anal. Des. 40 (2004) 1551, test 3.6")
COLUMNS = {"P_ratio": "1", "W_A": "1", "W_A_ref": "1", "U_B": "1", "U_B_ref": "1"}

R, LENGTH, H, E_MOD, NU, P_MAX = 100.0, 200.0, 1.0, 3.0e4, 0.3, 12000.0
#: P/P_max, the inward deflection -W_A under the load and the outward radial displacement U_B
#: of the side point of the mid-length section, Sze, Liu & Lo (2004), 40 x 40 octant (the
#: table as given in MBDyn's tests/plates/sze2004/sze36/sze36_ref.dat)
REFERENCE = np.array([
    [0.000, 0.000, 0.000], [0.050, 9.561, -0.233], [0.075, 15.648, -0.922], [0.100, 23.164, -2.391],
    [0.125, 29.375, -3.872], [0.150, 36.208, -2.154], [0.175, 51.499, 6.792], [0.200, 56.373, 10.448],
    [0.250, 61.877, 14.905], [0.300, 65.498, 17.979], [0.350, 68.229, 20.365], [0.400, 70.424, 22.321],
    [0.450, 72.204, 23.916], [0.500, 73.790, 25.381], [0.550, 75.139, 26.631], [0.600, 76.331, 27.735],
    [0.650, 77.472, 28.843], [0.700, 78.451, 29.772], [0.750, 79.339, 30.604], [0.800, 80.218, 31.471],
    [0.850, 81.045, 32.299], [0.900, 81.766, 32.989], [0.950, 82.435, 33.619], [1.000, 83.102, 34.272]])
SOURCE = ("K.Y. Sze, X.H. Liu, S.H. Lo, Popular benchmark problems for geometric nonlinear analysis of "
          "shells, Finite Elem. Anal. Des. 40 (2004) 1551-1569, test 3.6 (table via MBDyn "
          "tests/plates/sze2004/sze36/sze36_ref.dat)")


def model(*, n: int = 40):
    """Octant x in [0, L/2] (x along the axis, x = 0 the mid-length section), theta in
    [0, 90 deg] from the top, n x n MITC4, directors outward: symmetry planes x = 0, y = 0 and
    z = 0, the diaphragm at x = L/2 (u_y = u_z = 0, axial sliding free), P_max / 4 at
    A = (0, 0, R) along -z. Returns (structure, A, B) with B = (0, R, 0)."""
    from skfem import MeshQuad
    from tmfem.fem.mitc4 import ShellSection
    from tmfem.fem.structure import Structure
    m = MeshQuad.init_tensor(np.linspace(0.0, LENGTH / 2, n + 1), np.linspace(0.0, np.pi / 2, n + 1))
    x, th = m.p
    s = Structure.shell((np.vstack([x, R * np.sin(th), R * np.cos(th)]), m.t),
                        section=ShellSection(E=E_MOD, nu=NU, thickness=H),
                        normals=np.vstack([0 * x, np.sin(th), np.cos(th)]),
                        orient=lambda x, y, z: np.vstack([0 * x, y, z]))
    for axis in ("x", "y", "z"):
        k = "xyz".index(axis)
        s.symmetry(s.nodes_where(lambda *p: np.isclose(p[k], 0.0, atol=1e-9 * R)), normal=axis)
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, LENGTH / 2)), ["uy", "uz"])
    A = s.nodes_where(lambda x, y, z: np.isclose(x, 0.0) & np.isclose(y, 0.0, atol=1e-9 * R))
    B = s.nodes_where(lambda x, y, z: np.isclose(x, 0.0) & np.isclose(z, 0.0, atol=1e-9 * R))
    s.point_load(A, force=(0.0, 0.0, -P_MAX / 4))
    return s, int(A[0]), int(B[0])


def trace(s, A, B, *, increment: float = 2.0):
    """Displacement control of W_A in steps of ``increment`` until the load reaches P_max;
    returns the path, P/P_max, -W_A, U_B."""
    from tmfem.errors import ConvergenceError
    path = s.solve_displacement_control(node=A, dof="uz", increment=-increment, target=-0.95 * R, max_steps=400,
                                        stop=lambda st, lam: lam >= 1.0)
    if path.reason != "stopped":
        raise ConvergenceError(f"pinched cylinder: expected to reach P_max, stopped ({path.reason}): {path.message}")
    d = np.array([s.displacements(st)[:, [A, B]] for st in path])
    return path, path.lam, -d[:, 2, 0], d[:, 1, 1]


def curve_distance(P_fe, D_fe, P_ref, D_ref, *, d_scale: float) -> np.ndarray:
    """Distance of each reference point (P_ref, D_ref) to the polyline (P_fe, D_fe) in the
    plane (P / P_max, D / d_scale): a measure of two load paths that stays meaningful where
    the load is nearly flat (there, a small load difference moves the displacement at a
    given load far)."""
    a = np.stack([P_fe, np.asarray(D_fe) / d_scale], axis=1)            # (n, 2)
    p = np.stack([P_ref, np.asarray(D_ref) / d_scale], axis=1)          # (m, 2)
    s0, s1 = a[:-1], a[1:]
    seg = s1 - s0
    t = np.einsum("mni,ni->mn", p[:, None] - s0[None], seg) / np.maximum(np.einsum("ni,ni->n", seg, seg), 1e-300)
    near = s0[None] + np.clip(t, 0.0, 1.0)[..., None] * seg[None]
    return np.linalg.norm(p[:, None] - near, axis=-1).min(axis=1)


def at_first_crossing(lam, P, values) -> np.ndarray:
    """``values`` (along the path) where the load factor ``lam`` first reaches each of ``P``
    (linear between the path points around the crossing); NaN for a load never reached."""
    lam = np.asarray(lam, dtype=float)
    top = np.maximum.accumulate(lam)
    i = np.searchsorted(top, P, side="left")                  # first index with lam >= P
    out = np.full(np.shape(P), np.nan)
    ok = (i > 0) & (i < lam.size)
    j = i[ok]
    t = (np.asarray(P)[ok] - lam[j - 1]) / (lam[j] - lam[j - 1])
    out[ok] = np.asarray(values)[j - 1] + t * (np.asarray(values)[j] - np.asarray(values)[j - 1])
    out[np.asarray(P) == lam[0]] = np.asarray(values)[0]
    return out


def run(*, reduced: bool = False) -> dict:
    """The path on the 40 x 40 octant (``reduced``: 32 x 32) and -W_A, U_B at the tabulated
    loads where the path first reaches them (what load control reaches), interpolated
    linearly between the two path points around that crossing.

    Errors: ``max_error_W_A_over_path`` max over the tabulated loads of |FE - ref| / ref;
    ``max_error_U_B_over_path`` (U_B crosses zero) of |FE - ref| / the largest |U_B|;
    ``max_curve_distance`` the largest distance of a reference point to the FE path in the
    plane (P / P_max, displacement / its largest reference value), both curves."""
    import time
    s, A, B = model(n=32 if reduced else 40)
    t0 = time.perf_counter()
    path, lam, W, U = trace(s, A, B)
    seconds = time.perf_counter() - t0
    P, W_ref, U_ref = REFERENCE.T
    Wi, Ui = at_first_crossing(lam, P, W), at_first_crossing(lam, P, U)
    rows = [{"P_ratio": float(p), "W_A": float(w), "W_A_ref": float(wr), "U_B": float(u), "U_B_ref": float(ur)}
            for p, w, wr, u, ur in zip(P, Wi, W_ref, Ui, U_ref)]
    on = P > 0
    err_W = np.abs(Wi - W_ref)[on] / W_ref[on]
    err_U = np.abs(Ui - U_ref) / np.abs(U_ref).max()
    dist = max(curve_distance(lam, W, P, W_ref, d_scale=W_ref.max()).max(),
               curve_distance(lam, U, P, U_ref, d_scale=np.abs(U_ref).max()).max())
    return {"rows": rows, "source": SOURCE, "max_error_W_A_over_path": float(err_W.max()),
            "max_error_U_B_over_path": float(err_U.max()),
            "load_of_max_error_W_A": float(P[on][np.argmax(err_W)]),
            "max_curve_distance": float(dist),
            "error_measure": "-W_A: max over the tabulated loads of |FE - reference| / reference; U_B (crosses "
                             "zero): max of |FE - reference| / the largest reference |U_B|; curve distance: "
                             "largest distance of a reference point to the FE path in (P/P_max, "
                             "displacement / its largest reference value)",
            "steps": len(path) - 1, "seconds": seconds,
            "path": {"P_ratio": [float(v) for v in lam], "W_A": [float(v) for v in W], "U_B": [float(v) for v in U]}}


def plot(result: dict, png):
    """Load against -W_A and U_B: the displacement-controlled path and the reference."""
    from tmfem.post.plots import plot_xy
    p = result["path"]
    return plot_xy(png, {"-W_A MITC4": (p["W_A"], p["P_ratio"]), "U_B MITC4": (p["U_B"], p["P_ratio"]),
                         "-W_A Sze et al. 2004": (REFERENCE[:, 1], REFERENCE[:, 0]),
                         "U_B Sze et al. 2004": (REFERENCE[:, 2], REFERENCE[:, 0])},
                   xlabel="displacement", ylabel="P / P_max", title="pinched cylinder with diaphragms (Sze 3.6)")
