"""Cantilever strip rolled up by an end moment (dissertation 4.5.2), 16 x 1 MITC4 shells."""
from __future__ import annotations

import math

import numpy as np

NAME = "shell-cantilever-moment"
HELP = ("cantilever strip (E = 1.2e6, nu = 0, L = 12, b = 1, h = 0.1) under an end moment up to "
        "M = 2 pi EI/L, 16 x 1 MITC4, against the elastica (benchmarks.json "
        "elastica_end_moment_closed_form, sze32_cantilever_end_moment)")
COLUMNS = {"lambda": "1", "u_tip": "m", "w_tip": "m", "u_elastica": "m", "w_elastica": "m",
           "u_discrete": "m", "w_discrete": "m", "newton_iterations": "1"}


def elastica(lam, L: float):
    """Tip displacements (u along, w across the initial axis) of the inextensible elastica
    under the end moment M = lam 2 pi EI / L: theta = 2 pi lam, u = -L (1 - sin theta / theta),
    w = L (1 - cos theta) / theta."""
    th = 2 * np.pi * np.asarray(lam, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where(th > 0, -L * (1 - np.sin(th) / np.where(th > 0, th, 1)), 0.0)
        w = np.where(th > 0, L * (1 - np.cos(th)) / np.where(th > 0, th, 1), 0.0)
    return u, w


def discrete_closed_form(lam, L: float, n: int):
    """Tip of the uniform-curvature solution of n MITC4 elements of length l = L/n: with the
    directors interpolated linearly between nodes the bending strain of an element goes with
    the chord 2 sin(dtheta/2) of the director rotation dtheta, so its moment is
    M = (EI/l) sin(dtheta) (not (EI/l) dtheta); the chords, normal to the mean director
    (MITC shear zero at the element midpoints), turn by dtheta from element to element:
    x_tip + i z_tip = l sum_k exp(i (k - 1/2) dtheta)."""
    lam = np.atleast_1d(np.asarray(lam, float))
    l = L / n
    s = np.clip(2 * np.pi * lam * l / L, -1.0, 1.0)
    dth = np.arcsin(s)
    k = np.arange(1, n + 1)
    z = l * np.exp(1j * np.outer(dth, k - 0.5)).sum(axis=1)
    return z.real - L, z.imag


def model(*, n: int = 16, L: float = 12.0, b: float = 1.0, h: float = 0.1, E: float = 1.2e6):
    """The clamped strip as a :class:`tmfem.fem.structure.Structure` with the moment 2 pi EI/L
    at load factor 1 (split over the two tip nodes, about -y: the strip curls up)."""
    from skfem import MeshQuad
    from tmfem.fem.mitc4 import ShellSection
    from tmfem.fem.structure import Structure
    s = Structure.shell(MeshQuad.init_tensor(np.linspace(0, L, n + 1), np.linspace(0, b, 2)),
                        section=ShellSection(E=E, nu=0.0, thickness=h))
    EI = E * b * h**3 / 12
    tip = s.nodes_where(lambda x, y, z: np.isclose(x, L))
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0.0)))
    s.point_load(tip, moment=(0.0, -2 * math.pi * EI / L / tip.size, 0.0))
    return s, tip


def run(*, reduced: bool = False) -> dict:
    """The dissertation's 16 x 1 mesh, 10 equal moment increments to the full circle
    (``reduced`` changes nothing: the benchmark is small)."""
    return roll_up(n=16, steps=10)


def roll_up(*, n: int = 16, steps: int = 10, L: float = 12.0) -> dict:
    """Load stepping in ``steps`` equal increments of the moment to the full circle on an
    n x 1 mesh; rows against the elastica and the discrete closed form."""
    s, tip = model(n=n, L=L)
    path = s.solve(steps=steps).check()
    rows = []
    for st in path:
        u = s.displacements(st)[:, tip].mean(axis=1)
        ue, we = elastica(st.lam, L)
        ud, wd = discrete_closed_form(st.lam, L, n)
        rows.append({"lambda": float(st.lam), "u_tip": float(u[0]), "w_tip": float(u[2]),
                     "u_elastica": float(ue), "w_elastica": float(we), "u_discrete": float(ud[0]),
                     "w_discrete": float(wd[0]), "newton_iterations": int(st.iterations)})
    err = max(max(abs(r["u_tip"] - r["u_elastica"]), abs(r["w_tip"] - r["w_elastica"])) for r in rows) / L
    return {"rows": rows, "load_steps": steps, "mesh": f"{n}x1",
            "max_error_over_L_vs_elastica": err,
            "source": "elastica (benchmarks.json elastica_end_moment_closed_form); discrete closed form "
                      "of the linearly interpolated directors (docs/guides/shells.md)"}


def plot(result: dict, png):
    """Tip displacements against the load factor, FE and elastica."""
    from tmfem.post.plots import plot_xy
    r = result["rows"]
    lam = [x["lambda"] for x in r]
    lf = np.linspace(0, 1, 101)
    ue, we = elastica(lf, 12.0)
    return plot_xy(png, {"-u_tip MITC4": (lam, [-x["u_tip"] for x in r]),
                         "w_tip MITC4": (lam, [x["w_tip"] for x in r]),
                         "-u elastica": (lf, -ue), "w elastica": (lf, we)},
                   xlabel="lambda = M L / (2 pi EI)", ylabel="tip displacement [m]",
                   title="cantilever under end moment (4.5.2), 16x1 MITC4")
