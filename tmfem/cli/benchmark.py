"""``tmfem benchmark``: the element benchmarks (dissertation 4.5) against their references."""
from __future__ import annotations

import csv

from tmfem.errors import InputError

NAME = "benchmark"
HELP = "element benchmarks against closed forms and published results (4.5); --list names them"


def configure(parser) -> None:
    parser.add_argument("name", nargs="?", help="benchmark name (see --list)")
    parser.add_argument("--list", action="store_true", help="list the benchmarks and exit")
    parser.add_argument("--reduced", action="store_true",
                        help="run a smaller size (a quick check; CI runs the benchmarks this way)")
    parser.add_argument("--csv", help="write the result rows to this CSV file")
    parser.add_argument("--plot", help="write the benchmark's figure to this PNG")


def run(args) -> dict:
    from tmfem.reference.benchmarks import get, registry
    if args.list:
        if args.name or args.csv or args.plot or args.reduced:
            raise InputError("--list takes no benchmark name and no output options")
        return {"benchmarks": {name: mod.HELP for name, mod in registry().items()}}
    if not args.name:
        raise InputError("expected a benchmark name or --list, found neither")
    mod = get(args.name)
    if args.plot and not hasattr(mod, "plot"):
        raise InputError(f"--plot: benchmark {args.name!r} has no figure")
    if args.plot:
        from tmfem.io.paths import check_path
        check_path(args.plot, suffixes=(".png",))
    if args.csv:
        from tmfem.io.paths import check_path
        check_path(args.csv, suffixes=(".csv",))
    out = {"benchmark": args.name, "units": dict(mod.COLUMNS), **mod.run(reduced=args.reduced)}
    if args.csv:
        from tmfem.io.atomic import atomic_open
        with atomic_open(args.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(mod.COLUMNS), extrasaction="ignore",
                               lineterminator="\n")
            w.writerow({k: f"{k} [{u}]" if u else k for k, u in mod.COLUMNS.items()})
            w.writerows(out["rows"])
        out["csv"] = args.csv
    if args.plot:
        out["png"] = str(mod.plot(out, args.plot))
    return out


def format_text(r: dict) -> str:
    if "benchmarks" in r:
        width = max(len(n) for n in r["benchmarks"])
        return "\n".join(f"{n:<{width}}  {h}" for n, h in r["benchmarks"].items())
    cols = list(r["units"])
    lines = [f"benchmark {r['benchmark']}: {len(r['rows'])} rows; source: {r.get('source', '-')}",
             "  ".join(f"{c} [{r['units'][c]}]" for c in cols)]
    for row in r["rows"]:
        lines.append("  ".join(f"{row[c]:.6g}" for c in cols))
    for k, v in r.items():
        if k not in ("rows", "units", "benchmark", "source") and not isinstance(v, (list, dict)):
            lines.append(f"{k}: {v}")
    return "\n".join(lines)
