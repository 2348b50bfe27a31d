"""``tmfem export``: a system's configuration for ParaView (VTK) and as a PNG render.

Bars and tendons are written as lines with their data (length, rest length, strain and,
when the equilibrium design is available, axial force, force density, stress, slack
flag); the membrane as the quadrilateral mesh of 6.2 placed on the bar tops with the
linear plane-stress state (displacement, principal and von Mises stress) that the corner
positions impose, or as the polygon B_M1..B_MN with ``--mesh 0``.
"""
from __future__ import annotations


import numpy as np

from tmfem.cli.common import add_system_args, check_mesh_budget, output_file, system_from_args, warn
from tmfem.errors import InfeasibleDesign, InputError

NAME = "export"
HELP = "write a system's configuration for ParaView (.vtu/.xdmf) and a PNG render"


def configure(parser) -> None:
    add_system_args(parser)
    parser.add_argument("out", help="output file: .vtu (ParaView), .xdmf or .vtk")
    parser.add_argument("--png", help="also render the configuration to this PNG file")
    parser.add_argument("--mesh", type=int, default=10, metavar="n",
                        help="membrane mesh n x n per quadrilateral patch (default 10); "
                             "0 writes the membrane polygon only")
    parser.add_argument("--no-equilibrium", action="store_true",
                        help="geometry and rest lengths only, no equilibrium design")


def design_forces(d) -> dict:
    """Tendon forces, rest lengths and bar forces of an equilibrium design ``d``
    (:func:`tmfem.equilibrium.design.design_equilibrium`, 3.2, eqs. 3.8-3.9, 3.16). Bar
    forces are axial forces, negative in compression, in stage-major order."""
    return {"tendon_forces": np.asarray(d.tendon_forces, dtype=float),
            "rest_lengths": np.asarray(d.rest_lengths, dtype=float),
            "bar_forces": -np.asarray(d.bar_loads, dtype=float).ravel()}


def run(args) -> dict:
    from tmfem.equilibrium.design import design_equilibrium
    from tmfem.io import write_configuration
    from tmfem.post.fields import (corner_radial_displacements, membrane_design_field,
                                   placed_membrane_field)

    system = system_from_args(args)
    if args.mesh < 0:
        raise InputError(f"--mesh: expected n >= 0, found {args.mesh}")
    check_mesh_budget(N=system.N, n=max(args.mesh, 1), dofs_per_node=2)
    output_file(args.out, option="out", suffixes=(".vtu", ".xdmf", ".vtk"))
    output_file(args.png, option="--png", suffixes=(".png",))
    warnings = []
    d = None
    if not args.no_equilibrium:
        try:
            d = design_equilibrium(system, mesh_n=args.mesh if args.mesh > 0 else 10)
        except InfeasibleDesign as exc:
            # the configuration is still worth looking at: write it without forces, say why
            warnings.append(f"no equilibrium design ({type(exc).__name__}: {exc}); "
                            "writing geometry and rest lengths only")
    forces = {} if d is None else design_forces(d)
    source = "design_equilibrium" if d is not None else "none"
    radial = corner_radial_displacements(system)
    if np.any(radial <= 0):
        warnings.append("membrane not stretched (eq. 3.36): radial corner displacements "
                        f"{np.array2string(radial, precision=4)} m; its linear plane-stress "
                        "field is compressive and only shows the misfit")
    for w in warnings:
        warn(NAME, w)
    if args.mesh == 0:
        membrane = None
    elif d is not None:     # the design solved this membrane already (same mesh, same q)
        membrane = placed_membrane_field(system, d.membrane_model, d.membrane)
    else:
        membrane = membrane_design_field(system, n=args.mesh)
    path = write_configuration(args.out, system, membrane=membrane,
                               tendon_forces=forces.get("tendon_forces"),
                               rest_lengths=forces.get("rest_lengths"),
                               bar_forces=forces.get("bar_forces"))
    result = {"system": system.name, "file": str(path), "nodes": len(system.node_labels),
              "bars": system.M * system.N, "tendons": len(system.tendons),
              "membrane_elements": 0 if membrane is None else int(membrane.mesh.t.shape[1]),
              "forces_from": source, "corner_radial_displacement": radial.tolist(),
              "warnings": warnings}
    if "tendon_forces" in forces:
        result["tendon_forces"] = dict(zip(system.tendon_names(), forces["tendon_forces"].tolist()))
    rest = forces.get("rest_lengths", system.rest_lengths)
    if rest is not None:
        result["rest_lengths"] = dict(zip(system.tendon_names(), np.asarray(rest).tolist()))
    if membrane is not None:
        result["membrane_max_von_mises"] = float(membrane.cell_data["von_mises"].max())
        result["membrane_max_sigma_p1"] = float(membrane.cell_data["sigma_p1"].max())
    if args.png:
        from tmfem.post.render import render_configuration
        title = f"{system.name}" + (" (as printed)" if args.as_printed else "")
        result["png"] = str(render_configuration(args.png, system, membrane=membrane,
                                                 tendon_forces=forces.get("tendon_forces"),
                                                 title=title))
    return result


def format_text(r: dict) -> str:
    lines = [f"{r['file']}: system {r['system']}, {r['nodes']} nodes, {r['bars']} bars, "
             f"{r['tendons']} tendons, {r['membrane_elements'] or 'polygon'} membrane "
             f"element(s); forces from: {r['forces_from']}"]
    if "membrane_max_von_mises" in r:
        lines.append(f"membrane (linear plane stress): max von Mises "
                     f"{r['membrane_max_von_mises'] / 1e6:.3f} MPa, max sigma_p1 "
                     f"{r['membrane_max_sigma_p1'] / 1e6:.3f} MPa")
    if "png" in r:
        lines.append(f"render: {r['png']}")
    return "\n".join(lines)
