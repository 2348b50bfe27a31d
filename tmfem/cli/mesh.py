"""``tmfem mesh``: the membrane mesh of a system (gmsh, N quadrilaterals of n x n, 6.2)."""
from __future__ import annotations

from tmfem.cli.common import add_system_args, check_mesh_budget, system_from_args
from tmfem.errors import InputError

NAME = "mesh"
HELP = "write the membrane mesh of a system (N quadrilaterals of n x n elements) as .msh/.vtu"


def configure(parser) -> None:
    add_system_args(parser)
    parser.add_argument("out", help="output mesh file (.msh gmsh 2.2 ASCII, .vtu or .xdmf)")
    parser.add_argument("--mesh", "--n", dest="n", type=int, default=10, metavar="n",
                        help="elements per side of each quadrilateral patch (default 10, as in 6.2)")
    parser.add_argument("--polygon", type=int, metavar="N",
                        help="a regular N-gon instead of a system's membrane (needs --r-mb)")
    parser.add_argument("--r-mb", type=float, help="circumradius of the --polygon membrane [m]")


def membrane_corners_from_args(args):
    """Corners (2, N) in O_f from --polygon/--r-mb, or from the system."""
    from tmfem.system import membrane_corners_regular

    if args.polygon is not None:
        if args.spec is not None or args.preset is not None:
            raise InputError("expected either --polygon N --r-mb R or a system, found both")
        if args.polygon < 3:
            raise InputError(f"--polygon: expected N >= 3 corners, found {args.polygon}")
        if args.r_mb is None or not args.r_mb > 0:
            raise InputError(f"--polygon needs --r-mb > 0, found {args.r_mb}")
        return membrane_corners_regular(args.polygon, args.r_mb), f"{args.polygon}-gon"
    if args.r_mb is not None:
        raise InputError("--r-mb applies to --polygon only")
    s = system_from_args(args)
    return s.membrane_corners, s.name


def run(args) -> dict:
    from tmfem.io.msh import write_membrane_mesh
    from tmfem.mesh import polygon_quad_mesh

    corners, name = membrane_corners_from_args(args)
    if args.n < 1:
        raise InputError(f"--mesh: expected n >= 1, found {args.n}")
    check_mesh_budget(N=corners.shape[1], n=args.n, option="--mesh", dofs_per_node=1)
    mesh = polygon_quad_mesh(corners, args.n)
    path = write_membrane_mesh(args.out, mesh)
    return {"file": str(path), "membrane": name, "N": int(corners.shape[1]), "n": args.n,
            "nodes": int(mesh.p.shape[1]), "elements": int(mesh.t.shape[1]),
            "corner_nodes": mesh.corners.tolist()}


def format_text(r: dict) -> str:
    return (f"{r['file']}: {r['membrane']} membrane, {r['N']} x {r['n']} x {r['n']} = "
            f"{r['elements']} quadrilaterals, {r['nodes']} nodes")
