"""Cantilever strip under an end shear force, large deflection (Sze, Liu & Lo 2004, test 3.1)."""
from __future__ import annotations

import numpy as np

NAME = "shell-cantilever-shear"
HELP = ("cantilever strip (E = 1.2e6, nu = 0, L = 10, b = 1, h = 0.1) under an end shear force up to "
        "P = 4 EI/L^2 as a line load on its free edge, 16 x 1 MITC4, load control, against Sze, Liu & Lo, "
        "Finite Elem. Anal. Des. 40 (2004) 1551, test 3.1")
COLUMNS = {"P_ratio": "1", "u_tip": "1", "w_tip": "1", "u_ref": "1", "w_ref": "1"}

E_MOD, LENGTH, WIDTH, H, P_MAX = 1.2e6, 10.0, 1.0, 0.1, 4.0
#: P/P_max, -u_tip, w_tip of Sze, Liu & Lo (2004), 16 x 1 mesh (the table as given in MBDyn's
#: tests/plates/sze2004/sze31/sze31_ref.dat)
REFERENCE = np.array([
    [0.00, 0.000, 0.000], [0.05, 0.026, 0.663], [0.10, 0.103, 1.309], [0.15, 0.224, 1.922],
    [0.20, 0.381, 2.493], [0.25, 0.563, 3.015], [0.30, 0.763, 3.488], [0.35, 0.971, 3.912],
    [0.40, 1.184, 4.292], [0.45, 1.396, 4.631], [0.50, 1.604, 4.933], [0.55, 1.807, 5.202],
    [0.60, 2.002, 5.444], [0.65, 2.190, 5.660], [0.70, 2.370, 5.855], [0.75, 2.541, 6.031],
    [0.80, 2.705, 6.190], [0.85, 2.861, 6.335], [0.90, 3.010, 6.467], [0.95, 3.151, 6.588],
    [1.00, 3.286, 6.698]])
SOURCE = ("K.Y. Sze, X.H. Liu, S.H. Lo, Popular benchmark problems for geometric nonlinear analysis of "
          "shells, Finite Elem. Anal. Des. 40 (2004) 1551-1569, test 3.1 (table via MBDyn "
          "tests/plates/sze2004/sze31/sze31_ref.dat)")


def model(*, n: int = 16):
    """The strip clamped at x = 0 with the end shear P_max as a line load P_max / b along z on
    the edge x = L; returns (structure, tip node set name)."""
    from skfem import MeshQuad
    from tmfem.fem.mitc4 import ShellSection
    from tmfem.fem.structure import Structure
    m = MeshQuad.init_tensor(np.linspace(0.0, LENGTH, n + 1), np.linspace(0.0, WIDTH, 2))
    s = Structure.shell(m, section=ShellSection(E=E_MOD, nu=0.0, thickness=H), orient=(0, 0, 1))
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0.0)))
    s.node_set("tip", s.nodes_where(lambda x, y, z: np.isclose(x, LENGTH)))
    s.line_load("tip", (0.0, 0.0, P_MAX / WIDTH))
    return s, "tip"


def run(*, reduced: bool = False) -> dict:
    """Load control in 20 steps of P_max / 20 (``reduced``: the 8 x 1 mesh)."""
    s, tip = model(n=8 if reduced else 16)
    path = s.solve(steps=20).check()
    nodes = s.node_sets[tip]
    rows = []
    for st, ref in zip(path, REFERENCE):
        d = s.displacements(st)[:, nodes].mean(axis=1)
        rows.append({"P_ratio": float(st.lam), "u_tip": float(-d[0]), "w_tip": float(d[2]),
                     "u_ref": float(ref[1]), "w_ref": float(ref[2])})
    err_u = max(abs(r["u_tip"] - r["u_ref"]) for r in rows) / REFERENCE[-1, 1]
    err_w = max(abs(r["w_tip"] - r["w_ref"]) for r in rows) / REFERENCE[-1, 2]
    return {"rows": rows, "source": SOURCE, "max_error_u_over_path": float(err_u),
            "max_error_w_over_path": float(err_w),
            "error_measure": "max over the path of |FE - reference| / reference at P_max",
            "newton_iterations": [int(i) for i in path.iterations[1:]]}


def plot(result: dict, png):
    """Tip displacements against the load, FE and reference."""
    from tmfem.post.plots import plot_xy
    r = result["rows"]
    P = [x["P_ratio"] for x in r]
    return plot_xy(png, {"-u_tip MITC4": ([x["u_tip"] for x in r], P),
                         "w_tip MITC4": ([x["w_tip"] for x in r], P),
                         "-u_tip Sze 2004": ([x["u_ref"] for x in r], P),
                         "w_tip Sze 2004": ([x["w_ref"] for x in r], P)},
                   xlabel="tip displacement", ylabel="P / P_max", title="cantilever under end shear (Sze 3.1)")
