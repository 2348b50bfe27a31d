"""Scordelis-Lo roof under self weight, linear (Belytschko et al. 1985 shell obstacle course)."""
from __future__ import annotations

import numpy as np

NAME = "shell-scordelis-lo"
HELP = ("Scordelis-Lo roof (R = 25, L = 50, t = 0.25, 40 deg, E = 4.32e8, nu = 0, 90 per unit area), "
        "quarter model, linear, MITC4 n x n meshes against 0.3024 (benchmarks.json scordelis_lo_roof)")
COLUMNS = {"n": "1", "dofs": "1", "w_B": "ft", "w_B_ratio": "1"}

#: vertical displacement at the mid-point of the free edge [ft] (benchmarks.json
#: ``scordelis_lo_roof``: the classical 0.3024; FinEtools' converged soft-diaphragm 0.30203)
W_REF = 0.3024
R, LENGTH, T, PHI, E_MOD, WEIGHT = 25.0, 50.0, 0.25, np.deg2rad(40.0), 4.32e8, 90.0


def model(*, n: int):
    """Quarter roof (x in [0, L/2], phi in [0, 40 deg] from the crown), n x n MITC4: diaphragm
    at x = 0 (u_y = u_z = 0), symmetry planes x = L/2 and y = 0, exact radial directors.
    Returns (structure, node B at the middle of the free edge)."""
    from skfem import MeshQuad
    from tmfem.fem.mitc4 import ShellSection
    from tmfem.fem.structure import Structure
    m = MeshQuad.init_tensor(np.linspace(0.0, LENGTH / 2, n + 1), np.linspace(0.0, PHI, n + 1))
    x, phi = m.p
    p, t = np.vstack([x, R * np.sin(phi), R * np.cos(phi)]), m.t
    radial = np.vstack([np.zeros_like(x), np.sin(phi), np.cos(phi)])
    s = Structure.shell((p, t), section=ShellSection(E=E_MOD, nu=0.0, thickness=T), normals=radial)
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0.0)), ["uy", "uz"])
    s.symmetry(s.nodes_where(lambda x, y, z: np.isclose(x, LENGTH / 2)), normal="x")
    s.symmetry(s.nodes_where(lambda x, y, z: np.isclose(y, 0.0)), normal="y")
    s.surface_load((0.0, 0.0, -WEIGHT))
    B = s.nodes_where(lambda x, y, z: np.isclose(x, LENGTH / 2) & np.isclose(y, R * np.sin(PHI)))
    return s, int(B[0])


def run(*, reduced: bool = False) -> dict:
    """Linear solutions on n x n quarter meshes, n = 4 ... 32 (``reduced``: up to 16)."""
    rows = []
    for n in (4, 8, 16) if reduced else (4, 8, 16, 32):
        s, B = model(n=n)
        st = s.solve_linear()
        w = -float(s.displacements(st)[2, B])
        rows.append({"n": n, "dofs": int(s.constraints.free.sum()), "w_B": w, "w_B_ratio": w / W_REF})
    return {"rows": rows, "reference": W_REF,
            "source": "benchmarks.json scordelis_lo_roof (Belytschko et al., CMAME 51 (1985))"}


def plot(result: dict, png):
    """Normalised displacement against mesh size."""
    from tmfem.post.plots import plot_xy
    r = result["rows"]
    n = [x["n"] for x in r]
    return plot_xy(png, {"MITC4": (n, [x["w_B_ratio"] for x in r]), "reference 0.3024": (n, [1.0] * len(n))},
                   xlabel="elements per side of the quarter roof", ylabel="w_B / 0.3024",
                   title="Scordelis-Lo roof, linear")
