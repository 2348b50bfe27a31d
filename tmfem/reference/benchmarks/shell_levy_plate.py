"""Simply supported square plate with immovable edges under pressure (dissertation 4.5.1)."""
from __future__ import annotations

import numpy as np

NAME = "shell-levy-plate"
HELP = ("simply supported square plate, immovable edges, uniform pressure (E = 1e7, nu = 0.316, "
        "h = 0.12, a = 24), 10 x 10 MITC4, centre deflection up to q a^4/(E h^4) = 400 against "
        "Levy and the von Karman curve (benchmarks.json levy_ss_square_plate_immovable_*)")
COLUMNS = {"P": "1", "w_over_h": "1", "w_over_h_von_karman": "1", "newton_iterations": "1"}

E, NU, H, A = 1e7, 0.316, 0.12, 24.0


#: Levy (1942, NACA TN 846) for the simply supported square plate with immovable edges
#: (benchmarks.json ``levy_ss_square_plate_immovable_point``): (q a^4/(E h^4), w_centre/h)
LEVY_POINT = (278.5, 1.83)

#: von Karman centre deflection, Ritz solution with u = v = 0 on all edges (benchmarks.json
#: ``levy_ss_square_plate_immovable_derived``, column "w_c/h ('all')"): (P, w_centre/h)
VON_KARMAN = np.array([
    [1.0, 0.0438], [12.5, 0.4318], [25.0, 0.664], [50.0, 0.9374], [75.0, 1.1173],
    [100.0, 1.2553], [125.0, 1.369], [150.0, 1.4667], [200.0, 1.6306], [250.0, 1.7667],
    [278.5, 1.8356], [300.0, 1.8844], [350.0, 1.9888], [400.0, 2.0832]])


def model(*, n: int = 10, P_max: float = 400.0):
    """The full plate on an n x n mesh: w = 0 and u = v = 0 on the edges (rotations free),
    dead pressure q = P_max E h^4 / a^4 at load factor 1. Returns (structure, centre node)."""
    from skfem import MeshQuad
    from tmfem.fem.mitc4 import ShellSection
    from tmfem.fem.structure import Structure
    xs = np.linspace(0.0, A, n + 1)
    s = Structure.shell(MeshQuad.init_tensor(xs, xs), section=ShellSection(E=E, nu=NU, thickness=H))
    edge = s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(x, A) | np.isclose(y, 0) | np.isclose(y, A))
    s.fix(edge, ["ux", "uy", "uz"])
    s.pressure(P_max * E * H**4 / A**4, follower=False)
    centre = s.nodes_where(lambda x, y, z: np.isclose(x, A / 2) & np.isclose(y, A / 2))
    return s, int(centre[0])


def run(*, reduced: bool = False, n: int = 10, steps: int = 16) -> dict:
    """Load stepping to P = 400 in ``steps`` equal increments (``reduced``: 8)."""
    P_max = 400.0
    s, c = model(n=n, P_max=P_max)
    path = s.solve(steps=8 if reduced else steps).check()
    levy, vk = LEVY_POINT, VON_KARMAN
    rows = []
    for st in path[1:]:
        P = st.lam * P_max
        # deflection along the centre director (the side the pressure pushes to)
        w = float(s.displacements(st)[:, c] @ s.frames[c][:, 2]) / H
        rows.append({"P": float(P), "w_over_h": w,
                     "w_over_h_von_karman": float(np.interp(P, vk[:, 0], vk[:, 1])),
                     "newton_iterations": int(st.iterations)})
    err = max(abs(r["w_over_h"] / r["w_over_h_von_karman"] - 1) for r in rows)
    return {"rows": rows, "mesh": f"{n}x{n}", "levy_point": {"P": levy[0], "w_over_h": levy[1]},
            "max_relative_error_vs_von_karman": err,
            "source": "von Karman Ritz table and Levy's point, benchmarks.json"}


def plot(result: dict, png):
    """Centre deflection against load, MITC4 and von Karman, with Levy's point."""
    from tmfem.post.plots import plot_xy
    vk = VON_KARMAN
    r = result["rows"]
    lp = result["levy_point"]
    return plot_xy(png, {"MITC4 10x10": ([x["P"] for x in r], [x["w_over_h"] for x in r]),
                         "von Karman (Ritz)": (vk[:, 0], vk[:, 1]),
                         "Levy (1942)": ([lp["P"]], [lp["w_over_h"]])},
                   xlabel="P = q a^4 / (E h^4)", ylabel="w_centre / h",
                   title="simply supported plate, immovable edges (4.5.1)")
