"""The equilibrium study of a system (ch. 3): its design table beside the dissertation's
printed values, the tendon table, and two matplotlib figures. Used by ``tmfem study`` and
by the report of :mod:`tmfem.reference.report`."""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from tabulate import tabulate

from tmfem.io.atomic import atomic_open, write_text
from tmfem.post.plots import new_figure, save_figure


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
        if has_printed(system=system):
            add("r_1 of eq. 3.33 (printed column: input r_1)", "m", d.closed_form["r1_equilibrium"], c.r[0],
                "eq. 3.33")
        else:
            add("r_1 of eq. 3.33", "m", d.closed_form["r1_equilibrium"], None,
                f"eq. 3.33 (input r_1 = {c.r[0]:.6g} m)")
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


def has_printed(rows_of=None, *, system=None) -> bool:
    """Whether a design table has a printed column: some row of ``rows_of`` carries a printed
    value, or ``system`` carries printed values (a file's ``[printed]`` table beyond its
    ``source``). A system without printed values gets no printed and no rel. diff columns."""
    if system is not None:
        return any(k != "source" for k in dict(system.printed))
    return any(r["printed"] is not None for r in rows_of)


def fmt(v, nd=6):
    """Number for the tables; ``n/a`` where there is none (a tendon that would push has no
    rest length, eqs. 3.8-3.9)."""
    if v is None:
        return ""
    return f"{v:.{nd}g}" if np.isfinite(v) else "n/a"


def markdown_table(rows) -> str:
    """The design table (rows of :func:`table_rows`) as a compact GitHub Markdown table
    (unpadded cells, so that a row reads ``| rest length S1 | m | ...`` in the source too;
    tabulate's Markdown formats pad every cell)."""
    if not has_printed(rows):
        md = ["| quantity | unit | value | source |", "|---|---|---|---|"]
        md += [f"| {r['quantity']} | {r['unit']} | {fmt(r['ours'])} | {r['source']} |" for r in rows]
        return "\n".join(md)
    md = ["| quantity | unit | ours | printed | rel. diff | source |", "|---|---|---|---|---|---|"]
    for r in rows:
        rd = "" if r["rel_diff"] is None else f"{100 * r['rel_diff']:+.2f} %"
        md.append(f"| {r['quantity']} | {r['unit']} | {fmt(r['ours'])} | {fmt(r['printed'])} | "
                  f"{rd} | {r['source']} |")
    return "\n".join(md)


def text_table(rows) -> str:
    """The design table as plain text (tabulate), for the terminal."""
    if not has_printed(rows):
        return tabulate([[r["quantity"], r["unit"], fmt(r["ours"])] for r in rows],
                        headers=["quantity", "unit", "value"], tablefmt="simple", disable_numparse=True,
                        colalign=("left", "right", "right"))
    body = [[r["quantity"], r["unit"], fmt(r["ours"]), fmt(r["printed"]),
             "" if r["rel_diff"] is None else f"{100 * r['rel_diff']:+.2f}%"] for r in rows]
    return tabulate(body, headers=["quantity", "unit", "ours", "printed", "rel. diff"],
                    tablefmt="simple", disable_numparse=True, colalign=("left", "right", "right",
                                                                         "right", "right"))


def write_tables(out: Path, d, system, *, notes=()) -> dict:
    """Write ``equilibrium.csv`` (one row per quantity with its unit column), ``tendons.csv``
    (units in the headers) and ``equilibrium.md`` (the table, ``notes`` explaining it, the
    checks) into ``out``; CSV line endings are ``\n``."""
    rows = table_rows(d, system)
    columns = (["quantity", "unit", "ours", "printed", "rel_diff", "source"] if has_printed(rows)
               else ["quantity", "unit", "ours", "source"])
    with atomic_open(out / "equilibrium.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns, lineterminator="\n", extrasaction="ignore")
        w.writeheader()
        for row in rows:
            w.writerow({k: (fmt(v, 8) if isinstance(v, float) else v) for k, v in row.items()})
            f.flush()
    given = d.given_rest_lengths
    with atomic_open(out / "tendons.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        head = ["tendon", "group", "length_m", "force_N", "force_density_N_per_m", "rest_length_m",
                "stress_MPa"]
        if given is not None:
            head += ["given_rest_length_m", "given_strain", "given_force_N", "given_slack"]
        w.writerow(head)
        for k, t in enumerate(system.tendons):
            row = [t.name, t.group, fmt(d.tendon_lengths[k], 8), fmt(d.tendon_forces[k], 8),
                   fmt(d.force_densities[k], 8), fmt(d.rest_lengths[k], 8),
                   fmt(d.tendon_stress[k] / 1e6, 8)]
            if given is not None:
                row += [fmt(given["rest_lengths"][k], 8), fmt(given["strain"][k], 6),
                        fmt(given["forces"][k], 6), bool(given["slack"][k])]
            w.writerow(row)
    md = [f"# Equilibrium study: {system.name}", "", system.description, "",
          f"Membrane mesh {d.membrane_model.mesh.n} x {d.membrane_model.mesh.n} per patch "
          f"({d.membrane_model.mesh.t.shape[1]} quads), "
          + (f"distributed corners (patch radius {d.membrane_model.patch:.4g} m). "
             if d.membrane_model.attachment == "distributed" else "point corners. ")
          + (f"Printed values: {system.printed.get('source', 'none')}." if has_printed(rows)
             else "The system carries no printed values."), "", markdown_table(rows)]
    if notes:
        md += ["", "## Why ours and the printed values differ", ""] + [f"- {n}" for n in notes]
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
    write_text(out / "equilibrium.md", "\n".join(md) + "\n")
    return {"rows": rows}


def plot_configuration(png: Path, d, system) -> Path:
    """3-D line plot: bars black, tendons coloured by force, membrane polygon."""
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D

    X = d.nodes
    fig = new_figure(figsize=(7.5, 6))
    ax = fig.add_subplot(projection="3d")
    for a, b in system.bar_connectivity.T:
        ax.plot(*X[:, [a, b]], color="k", lw=3)
    T = d.tendon_forces
    cmap = colormaps["viridis"]
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
    sm = ScalarMappable(cmap=cmap, norm=Normalize(0, tmax))
    fig.colorbar(sm, ax=ax, shrink=0.6, label="tendon force [N] (red: slack)")
    # the legend shows the colours drawn: the tendons' median force, and red where one is slack
    handles = [Line2D([], [], color="k", lw=3, label="bar"),
               Line2D([], [], color=cmap(float(np.median(np.clip(T, 0, None))) / tmax), lw=1.2,
                      label="tendon (colour: force)")]
    if np.any(T <= 0):
        handles.append(Line2D([], [], color="r", lw=1.2, label="tendon (slack)"))
    handles.append(Line2D([], [], color="orange", alpha=0.5, lw=6, label="membrane"))
    ax.legend(handles=handles, loc="upper left", fontsize=8)
    ax.set_title(f"{system.name}: design configuration")
    return save_figure(fig, png)


def plot_membrane_stress(png: Path, d) -> Path:
    """von Mises stress (element maximum, eq. 5.30) over the membrane mesh in O_f."""
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import LogNorm

    mesh = d.membrane_model.mesh
    vm = d.membrane.von_mises().max(axis=1) / 1e6
    verts = np.moveaxis(mesh.p[:, mesh.t], 0, -1).transpose(1, 0, 2)   # (ne, 4, 2)
    fig = new_figure(figsize=(6.4, 5.2))
    ax = fig.subplots()
    norm = LogNorm(vm.min(), vm.max()) if vm.min() > 0 and vm.max() > 10 * vm.min() else None
    pc = PolyCollection(verts, array=vm, cmap="magma", edgecolors="face", norm=norm)
    ax.add_collection(pc)
    ax.autoscale()
    ax.set_aspect("equal")
    fig.colorbar(pc, ax=ax, label="von Mises stress [MPa] (element max)")
    ax.set_xlabel("x_f [m]"), ax.set_ylabel("y_f [m]")
    ax.set_title("membrane stress in the floating frame O_f (linear plane stress)", fontsize=10)
    return save_figure(fig, png)


