"""A shell structure of your own with the Structure API: a simply supported square plate.

``tmfem.fem.structure.Structure`` assembles any mesh of MITC4 shells (and beams, trusses) with
supports, loads, linear and nonlinear statics, modes and ParaView output. This script builds a
steel plate, a x a x h, simply supported on its four edges, and checks it against the closed
forms of plate theory (Timoshenko & Woinowsky-Krieger, Navier series):

* uniform pressure q: centre deflection w = 0.00406 q a^4 / D, D = E h^3 / (12 (1 - nu^2));
* lowest natural frequency f_11 = (pi / a^2) sqrt(D / (rho h)).

It then loads the plate a hundred times harder with a following pressure, where membrane action
stiffens it (geometrically nonlinear statics), and writes both states for ParaView.

    .venv/bin/python examples/shell_structure.py [--n 16] [--out out/plate]
"""
import argparse
from pathlib import Path

import numpy as np
from skfem import MeshQuad

from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure


def plate(n, a, section):
    """The plate on an n x n mesh with its edges simply supported (w = 0, rotations free) and
    its in-plane rigid motions held at two corners."""
    m = MeshQuad.init_tensor(np.linspace(0, a, n + 1), np.linspace(0, a, n + 1))
    p = np.vstack([m.p, np.zeros(m.p.shape[1])])
    s = Structure.shell((p, m.t), section=section)
    edges = s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(x, a)
                          | np.isclose(y, 0) | np.isclose(y, a))
    s.fix(edges, "uz")
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) & np.isclose(y, 0)), ["ux", "uy"])
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, a) & np.isclose(y, 0)), "uy")
    centre = s.nodes_where(lambda x, y, z: np.isclose(x, a / 2) & np.isclose(y, a / 2))
    return s, centre


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=16, help="elements per edge (even)")
    ap.add_argument("--out", type=Path, default=Path("out/plate"))
    args = ap.parse_args(argv)
    a, h, q = 1.0, 0.01, 1.0e3                                  # m, m, Pa
    section = ShellSection(E=200e9, nu=0.3, thickness=h, rho=7800.0)
    D = section.E * h**3 / (12 * (1 - section.nu**2))

    s, centre = plate(args.n, a, section)
    s.surface_load((0.0, 0.0, -q))
    linear = s.solve_linear()
    w = -s.displacements(linear)[2, centre][0]
    w_ref = 0.00406 * q * a**4 / D
    print(f"linear centre deflection {w * 1e3:.4f} mm, plate theory {w_ref * 1e3:.4f} mm "
          f"({w / w_ref - 1:+.2%})")

    f1 = s.modes(k=1).freq_hz[0]
    f_ref = np.pi / a**2 * np.sqrt(D / (section.rho * h))
    print(f"lowest frequency {f1:.3f} Hz, plate theory {f_ref:.3f} Hz ({f1 / f_ref - 1:+.2%})")

    # A hundred times the load as a following pressure, in load steps (solve returns the
    # path): the deflection of twice the thickness is no longer proportional to the load, the
    # mid-surface stretches and carries part of it.
    s2, centre2 = plate(args.n, a, section)
    s2.pressure(100 * q)
    big = s2.solve(steps=10)[-1]
    w2 = np.abs(s2.displacements(big)[2, centre2][0])
    print(f"100 x the pressure: centre deflection {w2 * 1e3:.3f} mm = {w2 / w:.1f} x the linear one")

    args.out.mkdir(parents=True, exist_ok=True)
    s.to_meshio(linear).write(args.out / "plate_linear.vtu")
    s2.to_meshio(big).write(args.out / "plate_pressure.vtu")
    print("wrote", args.out / "plate_linear.vtu", "and", args.out / "plate_pressure.vtu")
    return w / w_ref, f1 / f_ref, w2 / w


if __name__ == "__main__":
    main()
