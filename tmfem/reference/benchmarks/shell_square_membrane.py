"""Square membrane under corner forces (dissertation 4.5.4): MITC4 shells against the
membrane element, 51 um on 2 m (h/a = 2.55e-5)."""
from __future__ import annotations

import numpy as np

NAME = "shell-square-membrane"
HELP = ("square membrane (a = 2 m, h = 51 um, E = 1.65e8, nu = 0.34) under corner forces F = 2.749 N, "
        "Fw = 0.1 N (4.5.4): deflections along y = 0.4, 1.0, 1.6 m, MITC4 shells against the "
        "total-Lagrangian membrane element (an independent formulation)")
COLUMNS = {"y": "m", "x": "m", "w_membrane": "m", "w_shell": "m"}


def shell_square_membrane(*, n: int = 10, a: float = 2.0, F: float = 2.749, Fw: float = 0.1,
                          steps: int = 4, thickness: float = 51e-6):
    """The 4.5.4 problem with MITC4 shells on the membrane's mesh (4 n x n quads), the same
    supports and loads as :func:`tmfem.reference.element_benchmarks.square_membrane`
    ("diagonal" corner forces): stage 1 the in-plane corner forces (frozen as a base load,
    :meth:`Structure.freeze_loads`), stage 2 Fw at B in ``steps`` load steps.
    Returns (structure, final state, stage-1 state, path of stage 2, mesh)."""
    from tmfem.fem.mitc4 import ShellSection
    from tmfem.fem.structure import Structure
    from tmfem.mesh.polygon import polygon_quad_mesh
    mesh = polygon_quad_mesh(np.array([[0, a, a, 0], [0, 0, a, a]], float), n)
    s = Structure.shell((mesh.p, mesh.t), section=ShellSection(E=1.65e8, nu=0.34, thickness=thickness,
                                                                  rho=1400.0))
    O, A, B, C = mesh.corners
    s.fix([O], ["ux", "uy", "uz"])
    s.fix([A], ["uy", "uz"])
    s.fix([C], ["ux", "uz"])
    c = F / np.sqrt(2)
    s.point_load([A], force=(c, 0, 0))
    s.point_load([B], force=(c, c, 0))
    s.point_load([C], force=(0, c, 0))
    stage1 = s.solve(steps=1).check()[-1]
    s.freeze_loads()
    s.point_load([B], force=(0, 0, Fw))
    path = s.solve(steps=steps, start=type(stage1)(state=stage1.state, lam=0.0)).check()
    return s, path[-1], stage1, path, mesh


def run(*, reduced: bool = False) -> dict:
    """The 20 x 20 mesh of 4.5.4 (``reduced``: 10 x 10) with both elements."""
    from tmfem.reference.element_benchmarks import square_membrane
    n = 5 if reduced else 10
    mem = square_membrane(n=n)
    s, st, _, path, mesh = shell_square_membrane(n=n)
    w_shell = s.displacements(st)[2]
    rows = []
    for y, (x, w_m) in mem.lines.items():
        sel = np.flatnonzero(np.isclose(mesh.p[1], y, atol=1e-9))
        sel = sel[np.argsort(mesh.p[0, sel])]
        for xi, wm, ws in zip(x, w_m, w_shell[sel]):
            rows.append({"y": float(y), "x": float(xi), "w_membrane": float(wm), "w_shell": float(ws)})
    wm = np.array([r["w_membrane"] for r in rows])
    ws = np.array([r["w_shell"] for r in rows])
    return {"rows": rows, "mesh": f"{2 * n}x{2 * n}",
            "max_difference_over_max_w": float(np.max(np.abs(ws - wm)) / np.max(np.abs(wm))),
            "newton_iterations_stage2": [p.iterations for p in path[1:]],
            "source": "membrane element (tmfem.fem.membrane, 4.4.1) on the same mesh and loads"}


def plot(result: dict, png):
    """Deflection along the three lines, both elements."""
    from tmfem.post.plots import plot_xy
    series = {}
    for y in sorted({r["y"] for r in result["rows"]}):
        rr = [r for r in result["rows"] if r["y"] == y]
        series[f"membrane y = {y} m"] = ([r["x"] for r in rr], [1e3 * r["w_membrane"] for r in rr])
        series[f"MITC4 y = {y} m"] = ([r["x"] for r in rr], [1e3 * r["w_shell"] for r in rr])
    return plot_xy(png, series, xlabel="x [m]", ylabel="deflection w [mm]",
                   title="square membrane under corner forces (4.5.4)")
