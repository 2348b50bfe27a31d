"""``tmfem equilibrium``: the prestressed equilibrium design of a system (dissertation ch. 3).

Prints node coordinates, Delta, tendon lengths, forces, force densities, rest lengths and
the design checks (eqs. 3.16, 3.22, 3.35, 5.29-5.31). A violated equilibrium condition
(slack membrane, slack tendon, no equilibrium) is a one-line error and exit code 1 unless
``--allow-infeasible`` is given. When the system carries rest lengths (e.g. ``--as-printed``)
the forces they imply at the design geometry are shown beside the designed ones.
"""
from __future__ import annotations

from decimal import Decimal

import numpy as np

from tmfem.cli.common import (add_attachment_args, add_membrane_law_arg, add_system_args,
                              check_attachment_options, check_mesh_budget, system_from_args)
from tmfem.errors import InputError

NAME = "equilibrium"
HELP = "design the prestressed equilibrium of a system (ch. 3): forces, rest lengths, checks"


def configure(parser) -> None:
    add_system_args(parser)
    parser.add_argument("--mesh", type=int, default=10, metavar="n",
                        help="membrane mesh n x n per quadrilateral patch (default 10, as in 6.2)")
    parser.add_argument("--allow-infeasible", action="store_true",
                        help="print the design even when an equilibrium condition is violated")
    add_attachment_args(parser)
    add_membrane_law_arg(parser)
    g = parser.add_argument_group("design assistance (symmetric systems, docs/guides/system-file.md)")
    g.add_argument("--target-delta", type=float, metavar="MM",
                   help="solve for the membrane radius r_mb that gives this corner displacement "
                        "Delta [mm] (eq. 3.22), print it with the feasible range, and design with it")
    g.add_argument("--bases", action="store_true",
                   help="M >= 2: search stage bases (r_i, z_i, sigma_i) with a positive null vector "
                        "and Delta > 0 at the file's theta, psi; print them as [symmetric] entries "
                        "(degrees, metres)")
    g.add_argument("--packaged", type=float, metavar="THETA_DEG",
                   help="a [packaged] configuration at this theta [deg] with a feasible deployment "
                        "path: 1-N(D): the band of psi where the system is a feasible equilibrium "
                        "and the psi whose Delta matches the deployed one; symmetric M >= 2: the "
                        "stage bases at the deployed Delta (eq. 3.22) from which the automatic "
                        "path is feasible")


def design_result(system, *, mesh_n: int, strict: bool, attachment: str = "point",
                  patch: float | None = None, membrane_law: str = "svk") -> tuple[dict, object]:
    """Run the design and return (JSON-able result, EquilibriumDesign)."""
    from tmfem.equilibrium.design import design_equilibrium

    if mesh_n < 1:
        raise InputError(f"--mesh: expected n >= 1, found {mesh_n}")
    check_mesh_budget(N=system.N, n=mesh_n, dofs_per_node=2)
    check_attachment_options(system, attachment=attachment, patch=patch)
    d = design_equilibrium(system, mesh_n=mesh_n, strict=strict, attachment=attachment,
                           patch=patch, membrane_law=membrane_law)
    out = d.to_dict()
    out["mesh_n"] = mesh_n
    out["attachment"] = attachment
    out["membrane_law"] = membrane_law
    out["patch"] = d.membrane_model.patch
    out["node_labels"] = list(system.node_labels)
    out["printed"] = dict(system.printed)
    if d.given_rest_lengths is not None:
        g = d.given_rest_lengths
        out["given_rest_lengths"] = {
            "residual": g["residual"],
            "tendons": [{"name": n, "rest_length": float(r), "strain": float(e),
                         "force": float(T), "slack": bool(sl)}
                        for n, r, e, T, sl in zip(system.tendon_names(), g["rest_lengths"],
                                                  g["strain"], g["forces"], g["slack"])]}
    return out, d


def run(args) -> dict:
    from tmfem.control.deployment.packaged import packaged_configurations, packaged_stages
    from tmfem.equilibrium import assist
    from tmfem.errors import InfeasibleDesign
    system = system_from_args(args)
    chosen = [o for o, v in (("--target-delta", args.target_delta), ("--bases", args.bases or None),
                             ("--packaged", args.packaged)) if v is not None]
    if len(chosen) > 1:
        raise InputError(f"expected at most one of --target-delta, --bases, --packaged, found {chosen}")
    if args.bases:
        return {"system": system.name, "assist": "bases", **assist.feasible_bases(system)}
    if args.packaged is not None and system.M >= 2 and system.symmetric is not None:
        r = packaged_stages(system, theta_deg=args.packaged)
        return {"system": system.name, "assist": "packaged-stages", **{k: v for k, v in r.items() if k != "config"}}
    if args.packaged is not None:
        return {"system": system.name, "assist": "packaged",
                **on_scan_step(packaged_configurations(system, theta_deg=args.packaged))}
    radius = None
    if args.target_delta is not None:
        radius = assist.membrane_radius_for_delta(system, delta=args.target_delta * 1e-3)
        system = assist.with_membrane_radius(system, radius["r_mb"])
    try:
        out, _ = design_result(system, mesh_n=args.mesh, strict=not args.allow_infeasible,
                               attachment=args.attachment, patch=args.patch,
                               membrane_law=args.membrane_law)
    except InfeasibleDesign as exc:
        hint = assist.infeasibility_hint(system, exc)
        if not hint:
            raise
        raise type(exc)(f"{exc}; {hint}") from None
    out["as_printed"] = bool(args.as_printed)
    if radius is not None:
        out["membrane_radius"] = radius
    return out


def on_scan_step(r: dict) -> dict:
    """The ``--packaged`` result with its psi values (a scan from -89 deg in steps of
    ``step_deg``, accumulated in binary floating point) rounded to that grid and to the step's
    decimals: psi = 30.5, not 30.499999999993207."""
    decimals = max(0, -Decimal(repr(r["step_deg"])).as_tuple().exponent)

    def snap(v: float) -> float:
        return round(round(v / r["step_deg"]) * r["step_deg"], decimals)
    return {**r, "psi_deg": snap(r["psi_deg"]), "psi_deg_bands": [[snap(a), snap(b)] for a, b in r["psi_deg_bands"]]}


def format_assist(r: dict) -> str:
    """Text of ``--bases`` and ``--packaged``."""
    if r["assist"] == "bases":
        s = r["symmetric"]
        head = (f"{r['system']}: stage bases at theta = {s['theta_deg'][0]:g} deg, psi_1 = "
                f"{s['psi_deg'][0]:g} deg: " + ("feasible" if r["feasible"] else "NOT feasible")
                + f" (null-vector margin {r['margin']:.3g}, Delta = {1e3 * r['Delta']:.4g} mm)")
        tail = (["Delta is small: set r_mb with `--target-delta` after writing these bases "
                 "(R_M - r_mb = Delta, eq. 3.22)"] if r["feasible"] and r["Delta"] < 1e-4 else [])
        if r.get("r_mb") is not None:
            tail = [(f"no bases stretch the file's membrane; with these the membrane radius "
                     f"[membrane] r_mb = {r['r_mb']:.6g} m gives Delta = {1e3 * r['Delta']:.4g} mm")]
        return "\n".join([head, "[symmetric]"] + [f"{k} = {v}" for k, v in s.items()] + tail)
    if r["assist"] == "packaged-stages":
        p = r["path"]
        entries = ", ".join(f"{k} = {v}" for k, v in r["symmetric"].items())
        return (f"{r['system']}: at theta = {r['theta_deg']:g} deg, {r['candidates']} feasible packaged "
                f"equilibria with the deployed Delta = {1e3 * r['Delta_deployed']:.4g} mm (eq. 3.22; psi "
                f"in steps down to {r['psi_step_deg']:g} deg, rest lengths >= {1e3 * r['r_min']:.4g} mm); "
                f"the automatic path from the one below (null-vector margin {r['margin']:.3g}, top bar "
                f"ends {r['height']:.4g} m above the base) is feasible at its "
                f"{p['points_checked']} checked points (worst margin {p['min_margin']:.3g} at s = "
                f"{p['min_margin_progress']:.3g}):\n[packaged]\nsymmetric = {{ {entries} }}")
    bands = ", ".join(f"[{a:g}, {b:g}]" for a, b in r["psi_deg_bands"])
    return (f"{r['system']}: at theta = {r['theta_deg']:g} deg the system is a feasible 1-N(D) "
            f"equilibrium for psi in {bands} deg (steps of {r['step_deg']:g} deg)"
            + f"; psi = {r['psi_deg']:g} deg gives Delta = {1e3 * r['Delta']:.4g} mm (deployed "
            f"{1e3 * r['Delta_deployed']:.4g} mm; the deployment path from it checked at "
            f"{r['path_points_checked']} points):\n[packaged]\nsymmetric = {{ theta_deg = "
            f"[{r['theta_deg']:g}], psi_deg = [{r['psi_deg']:g}] }}"
            + (f"\nthe deployed Delta is reachable only for theta <= {r['theta_max_deg']:.4g} deg "
               f"(eq. 3.22: Delta >= l sin(theta) - r_1 - r_mb); a packaged theta above it "
               f"stretches the membrane more" if r["theta_deg"] > r["theta_max_deg"] else ""))


def _groups(r: dict) -> dict:
    """Per-group rows: tendons of a symmetric group share their values."""
    rows = {}
    for t in r["tendons"]:
        rows.setdefault(t["group"], []).append(t)
    return rows


def format_text(r: dict) -> str:
    if "assist" in r:
        return format_assist(r)
    L = [f"system {r['system']} ({r['M']}-{r['N']}{'(D)' if r['deployable'] else ''}), "
         f"membrane mesh {r['mesh_n']}x{r['mesh_n']} per patch"
         + (f", distributed corners (patch radius {r['patch']:.4g} m)"
            if r.get("attachment") == "distributed" else ", point corners")
         + (f", {r['membrane_law']} membrane law" if r.get("membrane_law", "svk") != "svk" else "")
         + ": "
         + ("all checks passed" if r["ok"] else "CHECKS FAILED")]
    L.append("")
    L.append("nodes [m]:")
    for lab, x in r["nodes"].items():
        L.append(f"  {lab:<6} {x[0]:10.5f} {x[1]:10.5f} {x[2]:10.5f}")
    L.append("")
    if r.get("membrane_radius"):
        m = r["membrane_radius"]
        L.append(f"membrane radius r_mb = {m['r_mb']:.6g} m for Delta = {1e3 * m['Delta']:.4g} mm "
                 f"(eq. 3.22; the membrane is stretched for r_mb < {m['r_mb_max']:.6g} m; the "
                 f"file's r_mb = {m['r_mb_file']:.6g} m gives Delta = {1e3 * m['Delta_file']:.4g} mm)")
    if r["Delta"] is not None:
        L.append(f"membrane corner displacement Delta (eq. 3.22) = {r['Delta'] * 1e3:.5g} mm")
    L.append(f"membrane corner force F_Delta (mean radial)   = {r['F_Delta']:.5g} N")
    L.append(f"equilibrium residual (eq. 3.16)               = {r['residual']:.3g}")
    sn = r.get("symmetric_null")
    if sn is not None:
        n = len(sn["rows"])
        L.append(f"reduced matrix of 3.3.2: {n} x {len(sn['columns'])}, null space dimension "
                 f"{sn['dim']} (smallest relative singular value {sn['smallest_sv']:.2g}), "
                 f"positive null vector: {'yes' if sn['positive'] else 'no'}")
        if sn["per_F_Delta"] is not None:
            L.append("  forces per unit F_Delta: " + ", ".join(
                f"{c} {v:.4g}" for c, v in zip(sn["columns"], sn["per_F_Delta"])))
    L.append("")
    given = {t["name"]: t for t in r.get("given_rest_lengths", {}).get("tendons", [])}
    head = (f"  {'tendon':<8}{'length [m]':>12}{'force [N]':>12}{'T/L [N/m]':>12}"
            f"{'rest [m]':>12}{'stress [MPa]':>14}")
    if given:
        head += f"{'given rest':>12}{'strain %':>10}{'force [N]':>11}"
    L.append("tendons (one row per symmetric group when all members agree):")
    L.append(head)
    for g, ts in _groups(r).items():
        same = all(abs(t["force"] - ts[0]["force"]) <= 1e-9 * max(1.0, abs(ts[0]["force"]))
                   and abs(t["length"] - ts[0]["length"]) <= 1e-12 for t in ts)
        for t in ([ts[0]] if same else ts):
            name = f"{g} x{len(ts)}" if same and len(ts) > 1 else t["name"]
            rest = f"{t['rest_length']:12.5f}" if t["rest_length"] is not None else f"{'-':>12}"
            line = (f"  {name:<8}{t['length']:12.5f}{t['force']:12.5g}{t['force_density']:12.5g}"
                    + rest + f"{t['stress'] / 1e6:14.5g}")
            if given:
                gt = given[t["name"]]
                line += (f"{gt['rest_length']:12.5f}{gt['strain'] * 100:10.4f}{gt['force']:11.4g}"
                         + ("  slack" if gt["slack"] else ""))
            L.append(line)
    if given:
        L.append(f"  given rest lengths: equilibrium residual with their forces "
                 f"{r['given_rest_lengths']['residual']:.3g} (0 = in equilibrium)")
    L.append("")
    bl = np.asarray(r["bar_loads"])
    L.append("bar compressive loads [N] by stage: "
             + "; ".join(f"stage {i + 1}: " + ", ".join(f"{v:.4g}" for v in row)
                         for i, row in enumerate(bl)))
    L.append(f"membrane max sigma_p1 = {r['membrane_max_principal'] / 1e6:.4g} MPa, "
             f"max von Mises = {r['membrane_max_von_mises'] / 1e6:.4g} MPa")
    L.append("")
    L.append("checks:")
    for c in r["checks"]:
        L.append(f"  [{'ok' if c['ok'] else 'FAIL'}] {c['name']} ({c['equation']}): "
                 f"{c['message']}")
    return "\n".join(L)
