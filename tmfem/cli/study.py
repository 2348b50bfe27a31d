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

import csv
import json
import sys
from pathlib import Path

import numpy as np

from tmfem.cli import _json_default
from tmfem.cli.common import (add_attachment_args, add_membrane_law_arg, add_system_args,
                              system_from_args)
from tmfem.errors import InputError

NAME = "study"
HELP = "equilibrium study of a system: table beside the printed values, plots, VTK file"


def configure(parser) -> None:
    add_system_args(parser)
    parser.add_argument("--out", required=True, help="output directory (created)")
    parser.add_argument("--mesh", type=int, default=10, metavar="n",
                        help="membrane mesh n x n per quadrilateral patch (default 10, as in 6.2)")
    parser.add_argument("--allow-infeasible", action="store_true",
                        help="write the study even when an equilibrium condition is violated")
    parser.add_argument("--map-grid", type=int, default=13, metavar="k",
                        help="k x k grid of the (theta, psi) equilibrium map for M >= 2 "
                             "and 1-N(D) systems "
                             "(default 13; 0 = no map)")
    parser.add_argument("--no-render", action="store_true", help="skip the pyvista render")
    add_attachment_args(parser)
    add_membrane_law_arg(parser)


def _progress(msg: str) -> None:
    print(f"tmfem study: {msg}", file=sys.stderr, flush=True)


def table_rows(d, system) -> list[dict]:
    """Rows (quantity, unit, ours, printed, rel_diff, source) of the design table."""
    from tmfem.reference.tables import relative_difference

    p = dict(system.printed)
    prest = p.get("rest_lengths", {}) or {}
    rows = []

    def add(q, unit, ours, printed=None, source=""):
        rows.append({"quantity": q, "unit": unit, "ours": None if ours is None else float(ours),
                     "printed": None if printed is None else float(printed),
                     "rel_diff": relative_difference(ours, printed), "source": source})

    c = system.symmetric
    if c is not None:
        for i in range(system.M):
            add(f"theta_{i + 1}", "deg", np.degrees(c.theta[i]), None, "input (eq. 3.19)")
            add(f"psi_{i + 1}", "deg", np.degrees(c.psi[i]), None, "input (eq. 3.20)")
            add(f"l_{i + 1}", "m", c.l[i], None, "input")
            add(f"r_{i + 1}", "m", c.r[i], None, "input")
            if i > 0:
                add(f"sigma_{i + 1}", "deg", np.degrees(c.sigma[i]), None, "input")
                add(f"z_{i + 1}", "m", c.z[i], None, "input")
        add("r_mb", "m", system.r_mb, None, "input")
    if d.closed_form is not None and "r1_equilibrium" in d.closed_form:
        add("r_1 of eq. 3.33 (printed column: input r_1)", "m", d.closed_form["r1_equilibrium"], c.r[0],
            "eq. 3.33")
    if d.Delta is not None:
        add("Delta", "mm", d.Delta * 1e3, None, "eq. 3.22")
    add("F_Delta", "N", d.F_Delta, None, "plane-stress FE (3.2)")
    add("equilibrium residual", "-", d.residual, None, "eq. 3.16")
    groups = dict.fromkeys(t.group for t in system.tendons)
    L, T = d.group_values(d.tendon_lengths), d.group_values(d.tendon_forces)
    fd, r = d.group_values(d.force_densities), d.group_values(d.rest_lengths)
    for g in groups:
        add(f"length {g}", "m", L[g], None, "geometry")
        add(f"force {g}", "N", T[g], None, "null vector of A(q) scaled to F (3.16)")
        add(f"force density {g}", "N/m", fd[g], None, "eq. 3.30")
        add(f"rest length {g}", "m", r[g], prest.get(g), "eqs. 3.8-3.9")
    add("max tendon stress", "MPa", d.tendon_stress.max() / 1e6,
        p.get("tendon_max_stress", None) and p["tendon_max_stress"] / 1e6, "T/A")
    add("membrane max sigma_p1", "MPa", d.membrane_max_principal / 1e6,
        p.get("membrane_max_sigma_p1", None) and p["membrane_max_sigma_p1"] / 1e6, "eq. 5.29")
    add("membrane max von Mises", "MPa", d.membrane_max_von_mises / 1e6,
        p.get("membrane_max_von_mises", None) and p["membrane_max_von_mises"] / 1e6, "eq. 5.30")
    for i in range(system.M):
        key = "bar_load" if system.M == 1 else f"bar_load_stage{i + 1}"
        add(f"bar load stage {i + 1} (compression)", "N", d.bar_loads[i].max(), p.get(key),
            "bar equilibrium")
    for i in range(system.M):
        add(f"bar Euler load stage {i + 1}", "N", d.bar_critical[i].min(),
            p.get("bar_critical_load"), "eq. 5.31, K = 1")
    return rows


def _fmt(v, nd=6):
    """Number for the tables; ``n/a`` where there is none (a tendon that would push has no
    rest length, eqs. 3.8-3.9)."""
    if v is None:
        return ""
    return f"{v:.{nd}g}" if np.isfinite(v) else "n/a"


def write_tables(out: Path, d, system) -> dict:
    rows = table_rows(d, system)
    with open(out / "equilibrium.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["quantity", "unit", "ours", "printed", "rel_diff", "source"])
        w.writeheader()
        for row in rows:
            w.writerow({k: (_fmt(v, 8) if isinstance(v, float) else v) for k, v in row.items()})
            f.flush()
    given = d.given_rest_lengths
    with open(out / "tendons.csv", "w", newline="") as f:
        w = csv.writer(f)
        head = ["tendon", "group", "length_m", "force_N", "force_density_N_per_m", "rest_length_m",
                "stress_MPa"]
        if given is not None:
            head += ["given_rest_length_m", "given_strain", "given_force_N", "given_slack"]
        w.writerow(head)
        for k, t in enumerate(system.tendons):
            row = [t.name, t.group, _fmt(d.tendon_lengths[k], 8), _fmt(d.tendon_forces[k], 8),
                   _fmt(d.force_densities[k], 8), _fmt(d.rest_lengths[k], 8),
                   _fmt(d.tendon_stress[k] / 1e6, 8)]
            if given is not None:
                row += [_fmt(given["rest_lengths"][k], 8), _fmt(given["strain"][k], 6),
                        _fmt(given["forces"][k], 6), bool(given["slack"][k])]
            w.writerow(row)
    md = [f"# Equilibrium study: {system.name}", "", system.description, "",
          f"Membrane mesh {d.membrane_model.mesh.n} x {d.membrane_model.mesh.n} per patch "
          f"({d.membrane_model.mesh.t.shape[1]} quads), "
          + (f"distributed corners (patch radius {d.membrane_model.patch:.4g} m). "
             if d.membrane_model.attachment == "distributed" else "point corners. ")
          + f"Printed values: "
          f"{system.printed.get('source', 'none')}.", "",
          "| quantity | unit | ours | printed | rel. diff | source |",
          "|---|---|---|---|---|---|"]
    for row in rows:
        rd = "" if row["rel_diff"] is None else f"{100 * row['rel_diff']:+.2f} %"
        md.append(f"| {row['quantity']} | {row['unit']} | {_fmt(row['ours'])} | "
                  f"{_fmt(row['printed'])} | {rd} | {row['source']} |")
    md += ["", "## Checks", ""]
    for c in d.checks:
        md.append(f"- [{'ok' if c.ok else 'FAIL'}] **{c.name}** ({c.equation}): {c.message}")
    if given is not None:
        md += ["", "## Given rest lengths at the design geometry", "",
               f"Equilibrium residual of eq. 3.16 with their forces: {given['residual']:.3g}.", "",
               "| tendon | rest length [m] | strain | force [N] |", "|---|---|---|---|"]
        for k, t in enumerate(system.tendons):
            md.append(f"| {t.name} | {given['rest_lengths'][k]:.5g} | {given['strain'][k]:+.4%} | "
                      f"{given['forces'][k]:.4g}{' (slack)' if given['slack'][k] else ''} |")
    if system.notes:
        md += ["", "## Notes on the system", ""] + [f"- {n}" for n in system.notes]
    (out / "equilibrium.md").write_text("\n".join(md) + "\n")
    return {"rows": rows}


def plot_configuration(png: Path, d, system) -> Path:
    """3-D line plot: bars black, tendons coloured by force, membrane polygon."""
    from tmfem.post.plots import _plt, _save

    plt = _plt()
    X = d.nodes
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    for a, b in system.bar_connectivity.T:
        ax.plot(*X[:, [a, b]], color="k", lw=3)
    T = d.tendon_forces
    cmap = plt.get_cmap("viridis")
    tmax = max(np.abs(T).max(), 1e-12)
    for k, (a, b) in enumerate(system.tendon_connectivity.T):
        col = "r" if T[k] <= 0 else cmap(T[k] / tmax)
        ax.plot(*X[:, [a, b]], color=col, lw=1.2)
    B = system.membrane_corners_inertial(d.q)
    P = np.concatenate([B, B[:, :1]], axis=1)
    ax.plot(*P, color="0.5", lw=1)
    ax.plot_trisurf(B[0], B[1], B[2], color="orange", alpha=0.3) if system.N >= 3 else None
    ax.set_xlabel("x [m]"), ax.set_ylabel("y [m]"), ax.set_zlabel("z [m]")
    span = (X.max(axis=1) - X.min(axis=1)).max() / 2
    mid = (X.max(axis=1) + X.min(axis=1)) / 2
    ax.set_xlim(mid[0] - span, mid[0] + span)
    ax.set_ylim(mid[1] - span, mid[1] + span)
    ax.set_zlim(mid[2] - span, mid[2] + span)
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, tmax))
    fig.colorbar(sm, ax=ax, shrink=0.6, label="tendon force [N] (red: slack)")
    ax.set_title(f"{system.name}: design configuration")
    return _save(fig, png)


def plot_membrane_stress(png: Path, d) -> Path:
    """von Mises stress (element maximum, eq. 5.30) over the membrane mesh in O_f."""
    from matplotlib.collections import PolyCollection

    from tmfem.post.plots import _plt, _save

    plt = _plt()
    mesh = d.membrane_model.mesh
    vm = d.membrane.von_mises().max(axis=1) / 1e6
    verts = np.moveaxis(mesh.p[:, mesh.t], 0, -1).transpose(1, 0, 2)   # (ne, 4, 2)
    fig, ax = plt.subplots(figsize=(6.4, 5.2))
    from matplotlib.colors import LogNorm
    norm = LogNorm(vm.min(), vm.max()) if vm.min() > 0 and vm.max() > 10 * vm.min() else None
    pc = PolyCollection(verts, array=vm, cmap="magma", edgecolors="face", norm=norm)
    ax.add_collection(pc)
    ax.autoscale()
    ax.set_aspect("equal")
    fig.colorbar(pc, ax=ax, label="von Mises stress [MPa] (element max)")
    ax.set_xlabel("x_f [m]"), ax.set_ylabel("y_f [m]")
    ax.set_title("membrane stress in the floating frame O_f (linear plane stress)", fontsize=10)
    return _save(fig, png)


def run(args) -> dict:
    from tmfem.cli.equilibrium import design_result

    system = system_from_args(args)
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"--out: cannot create directory {out}: {exc}") from None
    _progress(f"equilibrium design of {system.name} (membrane mesh {args.mesh}x{args.mesh})")
    result, d = design_result(system, mesh_n=args.mesh, strict=not args.allow_infeasible,
                              attachment=args.attachment, patch=args.patch,
                              membrane_law=args.membrane_law)
    files = {}
    _progress("tables")
    tables = write_tables(out, d, system)
    for f in ("equilibrium.csv", "tendons.csv", "equilibrium.md"):
        files[f] = str(out / f)
    (out / "design.json").write_text(json.dumps(result, default=_json_default))
    files["design.json"] = str(out / "design.json")
    _progress("plots")
    files["configuration.png"] = str(plot_configuration(out / "configuration.png", d, system))
    files["membrane_stress.png"] = str(plot_membrane_stress(out / "membrane_stress.png", d))
    _progress("VTK file")
    from tmfem.io.vtk import write_configuration
    from tmfem.post.fields import placed_membrane_field
    membrane = placed_membrane_field(system, d.membrane_model, d.membrane)
    files["configuration.vtu"] = str(write_configuration(
        out / "configuration.vtu", system, tendon_forces=d.tendon_forces,
        rest_lengths=d.rest_lengths if np.all(np.isfinite(d.rest_lengths)) else None,
        membrane=membrane, bar_forces=-d.bar_loads.ravel()))
    if not args.no_render:
        _progress("render")
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
        _progress(f"equilibrium map {k}x{k} over (theta, psi) (eq. 5.97)")
        th = np.radians(np.linspace(30, 85, k))
        ps = np.radians(np.linspace(-60, 60, k))
        emap = equilibrium_map(system, theta=th, psi=ps, progress=True)
        (out / "equilibrium_map.json").write_text(json.dumps(emap.to_dict()))
        files["equilibrium_map.json"] = str(out / "equilibrium_map.json")
        files["equilibrium_map.png"] = str(plot_equilibrium_map(
            out / "equilibrium_map.png", emap, mark=(c.theta[0], c.psi[0] - c.sigma[0])))
        result["map_feasible_points"] = int(emap.feasible.sum())
    _progress(f"done: {out}")
    return {"system": system.name, "ok": d.ok, "out": str(out), "files": files,
            "failed_checks": [c.name for c in d.failed], "table": tables["rows"]}


def format_text(r: dict) -> str:
    w = max(len("quantity"), *(len(row["quantity"]) for row in r["table"])) + 2
    lines = [f"{'quantity':<{w}}{'unit':>6}{'ours':>14}{'printed':>14}{'rel. diff':>11}"]
    for row in r["table"]:
        rd = "" if row["rel_diff"] is None else f"{100 * row['rel_diff']:+.2f}%"
        lines.append(f"{row['quantity']:<{w}}{row['unit']:>6}{_fmt(row['ours']):>14}"
                     f"{_fmt(row['printed']):>14}{rd:>11}")
    lines.append("")
    lines.append("checks: " + ("all passed" if r["ok"] else "FAILED: " + ", ".join(r["failed_checks"])))
    lines.append(f"written to {r['out']}/: " + ", ".join(Path(f).name for f in r["files"].values()))
    return "\n".join(lines)
