"""Your own system, from a TOML file to its modes and ParaView files.

The system of ``examples/pentagon.toml`` is not one of the dissertation's: one stage of five
bars carrying a pentagonal membrane. This script designs its prestress (dissertation ch. 3),
solves the nonlinear statics of the membrane-truss-cable finite-element model from the flat
membrane, computes its modes, and writes the mode shapes for ParaView. The tutorial
(docs/tutorial.md) walks through the same steps.

    .venv/bin/python examples/own_system.py [--out out/pentagon] [--mesh 10]
"""
import argparse
from pathlib import Path

import numpy as np

from tmfem.equilibrium import design_equilibrium
from tmfem.io.codes import kind_cell_data
from tmfem.io.writer import write_modes
from tmfem.models.mtc.model import MTCModel
from tmfem.post.mtc import model_cells
from tmfem.system import load_system

HERE = Path(__file__).resolve().parent


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("out/pentagon"))
    ap.add_argument("--mesh", type=int, default=10, help="membrane elements per patch edge")
    args = ap.parse_args(argv)

    # 1. The system: topology, configuration, membrane and materials from the file.
    system = load_system(HERE / "pentagon.toml")

    # 2. The equilibrium design: tendon forces and the rest lengths that give them, with every
    #    check (membrane stretched, tendons taut, yield, bar buckling). A failed check raises
    #    an error that names it and its numbers.
    design = design_equilibrium(system, mesh_n=args.mesh)
    print(f"design: Delta = {design.Delta * 1e3:.3f} mm, F_Delta = {design.F_Delta:.3f} N, "
          f"rest lengths {design.group_values(design.rest_lengths)}")

    # 3. The MTC model takes the designed rest lengths; its statics start from the flat,
    #    unstretched membrane, and the modes are those of the prestressed equilibrium.
    mtc = MTCModel(system, mesh_n=args.mesh, tendon_elements=3)
    static = mtc.equilibrium()
    modes = mtc.modes(k=12, at=static)
    print("MTC frequencies [Hz]:", np.round(modes.freq_hz, 4))

    # 4. The mode shapes for ParaView: point data mode_1 .. mode_12 (Warp By Vector).
    args.out.mkdir(parents=True, exist_ok=True)
    cells = model_cells(mtc)
    path = write_modes(args.out / "modes.vtu", static.state, cells, mtc.topology.T @ modes.shapes,
                       modes.freq_hz, cell_data=kind_cell_data(cells))
    print("wrote", path)
    return modes.freq_hz


if __name__ == "__main__":
    main()
