"""``tmfem study``: a complete equilibrium study of a system, written to a directory.

The main job of the README (``make demo``). For the system (preset or file) it runs the
equilibrium design (ch. 3, :func:`tmfem.equilibrium.design.design_equilibrium`) and writes

* ``equilibrium.csv``: the design table (quantity, unit, ours, printed, relative difference,
  source), written row by row;
* ``tendons.csv``: every tendon (length, force, force density, rest length, stress, and the
  strain / force the given rest lengths imply, if any);
* ``equilibrium.md``: the table beside the dissertation's printed values, and the checks;
* ``configuration.png`` (matplotlib), ``membrane_stress.png`` (von Mises over the mesh);
* ``configuration.vtu`` for ParaView (bars, tendons with forces, membrane with stresses) and
  ``render.png`` (pyvista, off screen);
* for symmetric systems with M >= 2 and 1-N(D) systems: ``equilibrium_map.png`` / ``.json``,
  the region of symmetric equilibria over (theta, psi) of eq. 5.97.

Progress goes to stderr.
"""
from __future__ import annotations

import json
import textwrap
from pathlib import Path

import numpy as np

from tmfem.cli import json_default
from tmfem.cli.common import (Progress, add_attachment_args, add_membrane_law_arg, add_system_args,
                              check_attachment_options, check_mesh_budget, output_dir, positive_int,
                              say, system_from_args)
from tmfem.errors import InputError
from tmfem.io.atomic import write_text
from tmfem.io.units import with_units
from tmfem.reference.report import explanations
from tmfem.reference.study import (plot_configuration, plot_membrane_stress, text_table,
                                   write_tables)

NAME = "study"
HELP = "equilibrium study of a system: table beside the printed values, plots, VTK file"


def configure(parser) -> None:
    add_system_args(parser)
    parser.add_argument("--out", required=True, help="output directory (created; checked "
                                                      "writable before the study starts)")
    parser.add_argument("--mesh", type=positive_int, default=10, metavar="n",
                        help="membrane mesh n x n per quadrilateral patch (default 10, as in 6.2)")
    parser.add_argument("--allow-infeasible", action="store_true",
                        help="write the study even when an equilibrium condition is violated")
    parser.add_argument("--map-grid", type=int, default=13, metavar="k",
                        help="k x k grid of the (theta, psi) equilibrium map for M >= 2 "
                             f"and 1-N(D) systems (default 13; 0 = no map; 2 <= k <= {MAX_MAP_GRID})")
    parser.add_argument("--no-render", action="store_true", help="skip the pyvista render")
    add_attachment_args(parser)
    add_membrane_law_arg(parser)


MAX_MAP_GRID = 60      # 13 x 13 takes ~6 s (2-3): 60 x 60 about two minutes


def run(args) -> dict:
    if args.map_grid != 0 and not 2 <= args.map_grid <= MAX_MAP_GRID:
        raise InputError(f"--map-grid: expected 0 (no map) or 2 <= k <= {MAX_MAP_GRID} (a map "
                         f"needs two points per axis), found {args.map_grid}")
    system = system_from_args(args)
    check_mesh_budget(N=system.N, n=args.mesh, dofs_per_node=2)
    check_attachment_options(system, attachment=args.attachment, patch=args.patch)
    out = output_dir(args.out, option="--out")
    with Progress(total=6, desc=f"study {system.name}") as bar:
        result = _study(args, system, out, bar)
    say("study", f"done: {out}")     # also when the bar is off (no tty)
    return result


def _study(args, system, out: Path, bar: Progress) -> dict:
    from tmfem.cli.equilibrium import design_result

    bar.note(f"equilibrium design (membrane mesh {args.mesh}x{args.mesh})")
    result, d = design_result(system, mesh_n=args.mesh, strict=not args.allow_infeasible,
                              attachment=args.attachment, patch=args.patch,
                              membrane_law=args.membrane_law)
    files = {}
    bar.step("tables")
    notes = explanations(system, "design")
    tables = write_tables(out, d, system, notes=notes)
    for f in ("equilibrium.csv", "tendons.csv", "equilibrium.md"):
        files[f] = str(out / f)
    write_text(out / "design.json", json.dumps(with_units(result), default=json_default))
    files["design.json"] = str(out / "design.json")
    bar.step("plots")
    files["configuration.png"] = str(plot_configuration(out / "configuration.png", d, system))
    files["membrane_stress.png"] = str(plot_membrane_stress(out / "membrane_stress.png", d))
    bar.step("VTK file")
    from tmfem.io.writer import write_configuration
    from tmfem.post.fields import placed_membrane_field
    membrane = placed_membrane_field(system, d.membrane_model, d.membrane)
    files["configuration.vtu"] = str(write_configuration(
        out / "configuration.vtu", system, tendon_forces=d.tendon_forces,
        rest_lengths=d.rest_lengths if np.all(np.isfinite(d.rest_lengths)) else None,
        membrane=membrane, bar_forces=-d.bar_loads.ravel()))
    if not args.no_render:
        bar.step("render")
        from tmfem.post.render import render_configuration
        files["render.png"] = str(render_configuration(out / "render.png", system,
                                                       tendon_forces=d.tendon_forces,
                                                       membrane=membrane, title=system.name))
    if system.symmetric is not None and (system.M >= 2 or system.deployable) \
            and args.map_grid > 0:
        from tmfem.equilibrium.symmetric_map import equilibrium_map
        from tmfem.post.equilibrium_map import plot_equilibrium_map
        k = args.map_grid
        c = system.symmetric
        bar.step(f"equilibrium map {k}x{k} (eq. 5.97)")
        th = np.radians(np.linspace(30, 85, k))
        ps = np.radians(np.linspace(-60, 60, k))
        emap = equilibrium_map(system, theta=th, psi=ps, progress=bar.callback("map rows"))
        write_text(out / "equilibrium_map.json", json.dumps(with_units(emap.to_dict())))
        files["equilibrium_map.json"] = str(out / "equilibrium_map.json")
        design = (c.theta[0], c.psi[0] - c.sigma[0])
        # a finer map +-10 deg around the design resolves a thin feasible region
        bar.step(f"equilibrium map {2 * k - 1}x{2 * k - 1} around the design")
        detail = equilibrium_map(system, theta=design[0] + np.radians(np.linspace(-10, 10, 2 * k - 1)),
                                 psi=design[1] + np.radians(np.linspace(-10, 10, 2 * k - 1)),
                                 progress=bar.callback("map rows"))
        files["equilibrium_map.png"] = str(plot_equilibrium_map(
            out / "equilibrium_map.png", emap, mark=design, detail=detail))
        result["map_feasible_points"] = int(emap.feasible.sum())
    bar.step("done")
    return {"system": system.name, "ok": d.ok, "out": str(out), "files": files,
            "failed_checks": [c.name for c in d.failed], "table": tables["rows"], "notes": notes}


def format_text(r: dict) -> str:
    lines = [text_table(r["table"]), ""]
    notes = r.get("notes", [])
    if notes:
        lines += ["notes of the system file:"]
        lines += [textwrap.fill(n, width=96, initial_indent="- ", subsequent_indent="  ")
                  for n in notes] + [""]
    lines.append("checks: " + ("all passed" if r["ok"] else "FAILED: " + ", ".join(r["failed_checks"])))
    lines.append(f"written to {r['out']}/: " + ", ".join(Path(f).name for f in r["files"].values()))
    return "\n".join(lines)
