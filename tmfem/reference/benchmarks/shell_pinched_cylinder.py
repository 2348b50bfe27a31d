"""Pinched cylinder with rigid diaphragms, linear (MacNeal & Harder 1985; Belytschko et al. 1985)."""
from __future__ import annotations

import numpy as np

NAME = "shell-pinched-cylinder"
HELP = ("pinched cylinder with rigid diaphragms (R = 300, L = 600, t = 3, E = 3e6, nu = 0.3, P = 1), octant "
        "with the loaded node on two symmetry planes, linear, MITC4 n x n against w = 1.8248e-5 (MacNeal & "
        "Harder, Finite Elem. Anal. Des. 1 (1985); Belytschko et al., CMAME 51 (1985))")
COLUMNS = {"n": "1", "dofs": "1", "w_A": "1", "w_A_ratio": "1"}

W_REF = 1.8248e-5
R, LENGTH, T, E_MOD, NU = 300.0, 600.0, 3.0, 3e6, 0.3
SOURCE = ("MacNeal & Harder, Finite Elem. Anal. Des. 1 (1985) 3-20; Belytschko et al., CMAME 51 (1985) 221-258: "
          "radial displacement 1.8248e-5 under the load")


def model(*, n: int, how: str = "symmetry", order=("x", "y")):
    """Octant x in [0, L/2], theta in [0, 90 deg] from the top, x along the axis: the load P/4
    at (0, 0, R) on the planes x = 0 and y = 0 (``how="by hand"``: that node's translations
    and both rotations fixed explicitly instead of by the two planes, in the given plane
    ``order`` otherwise), the plane z = 0, the diaphragm (u_y = u_z = 0) at x = L/2.
    Returns (structure, load node)."""
    from skfem import MeshQuad
    from tmfem.fem.mitc4 import ShellSection
    from tmfem.fem.structure import Structure
    m = MeshQuad.init_tensor(np.linspace(0, LENGTH / 2, n + 1), np.linspace(0, np.pi / 2, n + 1))
    x, th = m.p
    s = Structure.shell((np.vstack([x, R * np.sin(th), R * np.cos(th)]), m.t),
                        section=ShellSection(E=E_MOD, nu=NU, thickness=T),
                        normals=np.vstack([0 * x, np.sin(th), np.cos(th)]))
    on = {"x": lambda x, y, z: np.isclose(x, 0), "y": lambda x, y, z: np.isclose(y, 0, atol=1e-9)}
    A = s.nodes_where(lambda x, y, z: on["x"](x, y, z) & on["y"](x, y, z))
    for plane in order:
        nodes = s.nodes_where(on[plane])
        s.symmetry(np.setdiff1d(nodes, A) if how == "by hand" else nodes, normal=plane)
    if how == "by hand":
        s.fix(A, ["ux", "uy", "r1", "r2"])
    s.symmetry(s.nodes_where(lambda x, y, z: np.isclose(z, 0, atol=1e-9)), normal="z")
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, LENGTH / 2)), ["uy", "uz"])
    s.point_load(A, force=(0, 0, -0.25))
    return s, int(A[0])


def run(*, reduced: bool = False) -> dict:
    """Linear solutions on n x n octants, n = 8 ... 32 (``reduced``: up to 16)."""
    rows = []
    for n in (8, 16) if reduced else (8, 16, 24, 32):
        s, A = model(n=n)
        w = -float(s.displacements(s.solve_linear())[2, A])
        rows.append({"n": n, "dofs": int(s.constraints.free.sum()), "w_A": w, "w_A_ratio": w / W_REF})
    return {"rows": rows, "reference": W_REF, "source": SOURCE}


def plot(result: dict, png):
    """Normalised displacement against mesh size."""
    from tmfem.post.plots import plot_xy
    r = result["rows"]
    n = [x["n"] for x in r]
    return plot_xy(png, {"MITC4": (n, [x["w_A_ratio"] for x in r]), "reference 1.8248e-5": (n, [1.0] * len(n))},
                   xlabel="elements per side of the octant", ylabel="w_A / 1.8248e-5",
                   title="pinched cylinder, linear")
