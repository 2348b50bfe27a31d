"""``tmfem converge``: mesh and tendon-subdivision convergence of the MTC or SBC model (6.3)."""
from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np

from tmfem.cli.common import (add_attachment_args, add_membrane_law_arg, add_system_args,
                              check_attachment_options, check_model_budget, check_outputs,
                              system_from_args)
from tmfem.errors import InputError, shorten
from tmfem.io.run import partial_name
from tmfem.io.units import unit_of
from tmfem.models.fe.rest_lengths import describe_rule
from tmfem.models.fe.rest_lengths import apply_rest_lengths
from tmfem.models.registry import get_spec, models_with
from tmfem.post.convergence import plot_convergence_study
from tmfem.solvers.backends import AUTO_CROSSOVER_DOFS, backend_names

NAME = "converge"
HELP = "mesh / tendon-subdivision convergence of frequencies and stresses (dissertation 6.3)"


def _header(key: str) -> str:
    """CSV column name with its unit (``h [m]``, ``f1 [Hz]``; counts and labels bare)."""
    unit = unit_of(key)
    return f"{key} [{unit}]" if unit not in (None, "-") else key


def _ints(text: str, what: str) -> list[int]:
    try:
        v = [int(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise InputError(f"{what}: expected comma-separated integers, found {text!r}") from None
    if not v or min(v) < 1:
        raise InputError(f"{what}: expected integers >= 1, found {text!r}")
    return v


def configure(parser) -> None:
    add_system_args(parser)
    specs = models_with("finite-element")
    parser.add_argument("--model", choices=sorted(specs), default="mtc",
                        help="finite-element model (" + "; ".join(
                            f"{n}: {spec.help}" for n, spec in specs.items()) + ")")
    parser.add_argument("--backend", choices=backend_names(), default="auto",
                        help=f"linear-algebra backend (auto: PETSc from {AUTO_CROSSOVER_DOFS} free dofs "
                             "where installed; docs/guides/backends.md)")
    parser.add_argument("--mesh", default="10",
                        help="comma-separated membrane subdivisions n (N quads of n x n each)")
    parser.add_argument("--tendon-elements", default="3",
                        help="comma-separated numbers of truss elements per tendon")
    parser.add_argument("--modes", type=int, default=12,
                        help="number of modes per run (Table 6.6: 12)")
    add_attachment_args(parser)
    add_membrane_law_arg(parser)
    parser.add_argument("--rest-lengths", default=None,
                        help="rest lengths held fixed on every mesh: 'system', 'design@n' (the "
                             "ch. 3 design on the n x n mesh with point corners; default "
                             "design@10, the design of 6.2, for a system without rest lengths) "
                             "or GROUP=VALUE pairs such as S1=1.5025; or recomputed on each mesh: "
                             "'design' (the ch. 3 design on that mesh, the default of `tmfem "
                             "modal`/`static`) or 'mtc' (docs/guides/mtc.md)")
    parser.add_argument("--csv", help="write one row per run, as it finishes")
    parser.add_argument("--plot", help="PNG: frequencies and peak stresses against h")


def run(args) -> dict:
    from tmfem.reference.convergence import (ROW_KEYS, convergence_rows, fit_convergence,
                                             resolve_rest_lengths)
    system, rest = apply_rest_lengths(system_from_args(args), args.rest_lengths)
    meshes = _ints(args.mesh, "--mesh")
    tendons = _ints(args.tendon_elements, "--tendon-elements")
    if not (isinstance(args.modes, int) and args.modes >= 1):
        raise InputError(f"--modes: expected an integer >= 1, found {args.modes!r}")
    check_attachment_options(system, attachment=args.attachment, patch=args.patch)
    for n in meshes:
        for k in tendons:
            check_model_budget(system, mesh=n, tendon_elements=k, modes=args.modes,
                               dofs_per_node=get_spec(args.model).dofs_per_node,
                               backend=args.backend)
    check_outputs(args, NAME)
    rest, rule = resolve_rest_lengths(system, rest_lengths=rest)
    rows = []
    writer = fh = None
    complete = False
    try:
        if args.csv:                   # NAME.csv.partial until the last run (docs/guides/cli.md)
            Path(args.csv).unlink(missing_ok=True)
            fh = open(partial_name(args.csv), "w", newline="")
        for row in convergence_rows(system, meshes=meshes, tendon_elements=tendons,
                                    attachment=args.attachment, rest_lengths=rest,
                                    modes=args.modes, patch=args.patch, backend=args.backend,
                                    membrane_law=args.membrane_law, model=args.model):
            rows.append(row)
            if fh is not None:
                if writer is None:
                    keys = list(ROW_KEYS) + [f"f{i + 1}" for i in range(args.modes)]
                    writer = csv.DictWriter(fh, fieldnames=keys, lineterminator="\n")
                    writer.writerow({k: _header(k) for k in keys})
                writer.writerow(row)
                fh.flush()
        complete = True
    finally:
        if fh is not None:
            fh.close()
            if complete:
                os.replace(partial_name(args.csv), args.csv)
    out = {"system": system.name, "model": args.model, "attachment": args.attachment,
           "membrane_law": args.membrane_law, "rest_lengths_rule": rule,
           "rest_lengths_note": describe_rule(rule, per_mesh_study=True),
           "rest_lengths": (None if isinstance(rest, str) else
                            {t.name: float(v) for t, v in zip(system.tendons, rest)}),
           "rows": rows}
    if len(meshes) >= 3 and len(tendons) == 1:
        out["fit"] = fit_convergence(rows, modes=args.modes)
    elif len(tendons) >= 2 and len(meshes) == 1:
        f0 = [rows[0][f"f{i + 1}"] for i in range(args.modes)]
        out["max_relative_change_over_tendon_elements"] = max(
            abs(r[f"f{i + 1}"] / f0[i] - 1) for r in rows for i in range(args.modes))
    if args.plot:
        out["plot"] = str(plot_convergence_study(args.plot, rows, args.modes, system.name,
                                                 args.attachment, model=args.model.upper(),
                                                 by_tendons=len(meshes) == 1 and len(tendons) > 1))
    if args.csv:
        out["csv"] = args.csv
    return out


def format_text(r: dict) -> str:
    rows = r["rows"]
    if not rows:
        return "no runs"
    nf = sum(1 for k in rows[0] if k.startswith("f") and k[1:].isdigit())
    head = f"{'n':>3s} {'k':>2s} {'elem':>6s} {'dofs':>7s} {'backend':>7s} {'Delta mm':>9s} " \
           f"{'sp1 MPa':>8s} {'vm MPa':>8s} " \
           + " ".join(f"{'f' + str(i + 1) + ' Hz':>7s}" for i in range(nf))
    fixed = r.get("rest_lengths")
    lines = [f"{r['system']} {r.get('model', 'mtc').upper()} convergence, {r['attachment']} attachment, "
             f"{r.get('membrane_law', 'svk')} membrane",
             f"rest lengths: {r['rest_lengths_rule']} ({r['rest_lengths_note']})"
             + (": " + shorten(f"{k}={v:.5f} m" for k, v in fixed.items()) if fixed else ""), head]
    for w in rows:
        lines.append(f"{w['mesh_n']:3d} {w['tendon_elements']:2d} {w['elements']:6d} {w['dofs']:7d} "
                     f"{w.get('backend', ''):>7s} "
                     f"{w['Delta_mm']:9.4f} {w['sigma_p1_max_MPa']:8.3f} {w['von_mises_max_MPa']:8.3f} "
                     + " ".join(f"{w[f'f{i + 1}']:7.4f}" for i in range(nf)))
    fit = r.get("fit")
    if fit and "frequency_rates" in fit:
        lines.append("fitted rates |f(h) - f(h_min)| ~ h^p (the finest mesh as the limit): "
                     + ", ".join(f"{p:.2f}" if np.isfinite(p) else "-" for p in fit["frequency_rates"]))
        lines.append("change between the two finest meshes: "
                     + ", ".join(f"{100 * c:.3f}%" for c in fit["frequency_change_last"]))
        if "successive_change_rates" in fit:
            lines.append("successive changes per halving of h ~ h^q (q <= 0: no convergence), q: "
                         + ", ".join(f"{q:.2f}" for q in fit["successive_change_rates"]))
        else:
            lines.append("successive changes per halving of h ~ h^q: from four meshes on")
        lines.append("change per halving between the two finest meshes: "
                     + ", ".join(f"{100 * c:.2f}%" for c in fit["frequency_change_per_halving_last"]))
        lines.append(f"peak stress ~ h^p: sigma_p1 p = {fit['sigma_p1_max_MPa_exponent']:.2f}, "
                     f"von Mises p = {fit['von_mises_max_MPa_exponent']:.2f}, element-mean sigma_p1 "
                     f"p = {fit['sigma_p1_elem_max_MPa_exponent']:.2f}; Delta p = "
                     f"{fit['Delta_mm_exponent']:.3f}")
    if "max_relative_change_over_tendon_elements" in r:
        lines.append(f"largest relative frequency change over tendon subdivisions: "
                     f"{100 * r['max_relative_change_over_tendon_elements']:.4f}%")
    for k in ("csv", "plot"):
        if k in r:
            lines.append(f"wrote {r[k]}")
    return "\n".join(lines)
