"""``tmfem presets``: list the built-in systems."""
from __future__ import annotations

from tmfem.system import load_preset, list_presets

NAME = "presets"
HELP = "list the built-in systems of the dissertation"


def configure(parser) -> None:
    pass


def run(args) -> dict:
    out = []
    for name in list_presets():
        s = load_preset(name)
        out.append({"name": name, "M": s.M, "N": s.N, "deployable": s.deployable,
                    "description": s.description, "notes": list(s.notes)})
    return {"presets": out}


def format_text(result: dict) -> str:
    rows = [f"{p['name']:<14} {p['M']}-{p['N']}{'(D)' if p['deployable'] else '   '}  {p['description']}"
            for p in result["presets"]]
    return "\n".join(rows)
