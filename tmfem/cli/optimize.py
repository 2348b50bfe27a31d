"""``tmfem optimize``: the optimal design of a system on the MTC or SBC model with exact gradients
(:func:`tmfem.design.optimize`, docs/guides/design.md)."""
from __future__ import annotations

from tmfem.cli.common import (add_system_args, finite_float, output_dir, positive_float, positive_int,
                              say, system_from_args)
from tmfem.errors import InputError

NAME = "optimize"
HELP = "optimal design (rest lengths, thickness, diameters) with exact sensitivities"


def configure(parser) -> None:
    add_system_args(parser)
    parser.add_argument("--objective", help="min:RESPONSE or max:RESPONSE (max:freq: the lowest "
                                            "frequency, bound formulation); default the file's [design]")
    parser.add_argument("--constraint", action="append", default=None,
                        help="RESPONSE<=BOUND, >= or == (BOUND a number or 'start'); repeatable; "
                             "default the file's [design] constraints")
    parser.add_argument("--variable", action="append", default=None, metavar="NAME=LOWER:UPPER",
                        help="a design variable and its bounds (repeatable); default the file's "
                             "[design] variables")
    parser.add_argument("--model", choices=["mtc", "sbc"], default="mtc",
                        help="finite-element model")
    parser.add_argument("--mesh", type=positive_int, default=10, help="membrane elements per side")
    parser.add_argument("--modes", type=positive_int, default=4, help="eigenvalues in the bound formulation")
    parser.add_argument("--aperture", type=positive_float, default=None,
                        help="wrinkling indicator within this fraction of the membrane's inradius")
    parser.add_argument("--max-iter", type=positive_int, default=60, help="SLSQP iterations")
    parser.add_argument("--out", help="directory for history.csv, history.png and optimal.toml")


def _variables(items) -> dict:
    out = {}
    for it in items:
        name, _, rng = it.partition("=")
        lo, _, hi = rng.partition(":")
        try:
            out[name.strip()] = (finite_float(lo), finite_float(hi))
        except Exception:
            raise InputError(f"--variable: expected NAME=LOWER:UPPER, found {it!r}") from None
    return out


def run(args) -> dict:
    from tmfem.design.optimizer import optimize, result_dict
    from tmfem.design.plots import plot_history
    from tmfem.design.sensitivities import RESPONSES
    from tmfem.system import dump_system

    out = output_dir(args.out, option="--out")
    system = system_from_args(args)
    design = system.problem.design
    objective = args.objective or (design.objective if design else None)
    if objective is None:
        raise InputError("optimize: expected --objective or an objective in the file's [design]")
    constraints = args.constraint if args.constraint is not None else (design.constraints if design else ())
    variables = _variables(args.variable) if args.variable else None
    aperture = args.aperture if args.aperture is not None else (design.aperture if design else None)
    say(NAME, f"{system.name} {args.model.upper()}, mesh {args.mesh}: {objective} subject to {list(constraints)}")
    res = optimize(system, objective=objective, constraints=constraints, variables=variables,
                   model=args.model, mesh_n=args.mesh, k=args.modes, aperture=aperture, max_iter=args.max_iter,
                   history=None if out is None else out / "history.csv")
    r = result_dict(res)
    if out is not None:
        dump_system(res.system.replace(name=f"{system.name}-optimal"), out / "optimal.toml")
        name = res.objective.split(":")[1]
        unit = RESPONSES.get(name, RESPONSES.get(name.rpartition("_")[0], ("", "")))[1]
        plot_history(res.history, out / "history.png", objective=f"{res.objective} [{unit}]")
        r["files"] = {k: str(out / f) for k, f in (("history", "history.csv"), ("plot", "history.png"),
                                                   ("system", "optimal.toml"))}
    r["ok"] = res.success and not res.violated
    r["failed_checks"] = ([f"{v['constraint']} violated" for v in res.violated]
                          + ([] if res.success else [f"optimiser: {res.message}"]))
    resp_units = {k: RESPONSES.get(k, RESPONSES.get(k.rpartition("_")[0], ("", "-")))[1]
                  for k in res.start_responses}
    r["units"] = {"lower": "m", "upper": "m", "start": "m", "optimum": "m", "kkt_residual": "-",
                  "time_s": "s", "start_responses": resp_units, "optimum_responses": resp_units,
                  "active": "multipliers of the scaled problem (objective / |start value|, "
                            "constraints / |bound|, variables / their range): -",
                  "history": "[iteration, objective in its response's unit, scaled violation -, step m]",
                  "violated": "violation scaled by the constraint's bound: -"}
    r["response_units"] = resp_units
    return r


def format_text(r: dict) -> str:
    lines = [f"objective {r['objective']}, constraints {r['constraints']}",
             f"{'variable':14s} {'lower':>10s} {'start':>12s} {'optimum':>12s} {'upper':>10s}"]
    for n, lo, a, b, hi in zip(r["names"], r["lower"], r["start"], r["optimum"], r["upper"]):
        lines.append(f"{n:14s} {lo:10.5g} {a:12.6g} {b:12.6g} {hi:10.5g}")
    lines.append(f"{'response':30s} {'start':>24s} {'optimum':>24s}")
    units = r.get("response_units", {})
    for k, v in r["start_responses"].items():
        w = r["optimum_responses"][k]
        fmt = (lambda x: ", ".join(f"{y:.5g}" for y in x)) if isinstance(v, list) else (lambda x: f"{x:.6g}")
        lines.append(f"{k + ' [' + units.get(k, '-') + ']':30s} {fmt(v):>24s} {fmt(w):>24s}")
    lines.append("active constraints (Lagrange multiplier, scaled):")
    lines += [f"  {a['constraint']:36s} {a['multiplier']:.4g}" for a in r["active"]] or ["  none"]
    if r.get("violated"):
        lines.append("VIOLATED at the returned design (violation scaled by the bound):")
        lines += [f"  {v['constraint']:36s} {v['violation']:.3g}" for v in r["violated"]]
        lines += [f"hint: {h}" for h in dict.fromkeys(v["hint"] for v in r["violated"] if "hint" in v)]
    lines.append(f"KKT residual {r['kkt_residual']:.2e}; {r['message']}; {len(r['history'])} iterations, "
                 f"{r['evaluations']} evaluations, {r['time_s']:.1f} s")
    for k, f in r.get("files", {}).items():
        lines.append(f"{k}: {f}")
    return "\n".join(lines)
