"""Every line a command writes besides its result goes through the CLI's message channel:
warnings as ``tmfem: WARNING: ...`` once per run and also with ``--quiet``, progress through
``say`` (silenced by ``--quiet``); no module of the package prints by itself."""
import ast
import logging
from pathlib import Path

import tomli_w

from tests.cli.test_cli_misuse import run
from tests.cli.test_hostile_budget import stages
from tmfem.cli import presets
from tmfem.cli.common import warn

ROOT = Path(__file__).resolve().parents[2]

#: The functions that write to the terminal: the CLI's entry point (the result, errors, the
#: signal lines) and the message channel's progress line.
WRITERS = {("tmfem/cli/__init__.py", None), ("tmfem/cli/common.py", "say")}


def writes(tree):
    """(function, line) of every ``print(...)`` and ``sys.std{out,err}.write(...)`` call."""
    found = []

    def visit(node, func):
        for child in ast.iter_child_nodes(node):
            inner = child.name if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)) else func
            if isinstance(child, ast.Call):
                f = child.func
                if isinstance(f, ast.Name) and f.id == "print":
                    found.append((func, child.lineno))
                elif (isinstance(f, ast.Attribute) and f.attr == "write"
                      and isinstance(f.value, ast.Attribute) and f.value.attr in ("stdout", "stderr")):
                    found.append((func, child.lineno))
            visit(child, inner)
    visit(tree, None)
    return found


def test_no_module_prints_by_itself():
    bad = []
    for path in sorted((ROOT / "tmfem").rglob("*.py")):
        rel = str(path.relative_to(ROOT))
        for func, line in writes(ast.parse(path.read_text())):
            if (rel, None) not in WRITERS and (rel, func) not in WRITERS:
                bad.append(f"{rel}:{line} ({func})")
    assert not bad, "print/write outside the message channel: " + ", ".join(bad)


def test_export_warning_once_through_the_channel_also_quiet(tmp_path, capsys):
    # a 3-stage tower whose equilibrium design has slack tendons: export writes the
    # geometry and warns (the design's SlackTendon names 12 of 39 tendons)
    d = stages(3)
    d.pop("monitor", None)
    spec = tmp_path / "tower.toml"
    spec.write_bytes(tomli_w.dumps(d).encode())
    for quiet in ([], ["--quiet"]):
        rc, out, err = run(["export", str(spec), str(tmp_path / "t.vtu"), "--mesh", "2", *quiet],
                           capsys)
        assert rc == 0, err
        lines = err.strip().splitlines()
        assert [x for x in lines if "WARNING" in x] == [lines[-1]], err
        assert lines[-1].startswith("tmfem: WARNING: no equilibrium design (SlackTendon: ")
        assert "12 of 39 slack" in lines[-1] and "export: warning" not in err


def test_command_warnings_shown_once(monkeypatch, capsys):
    def twice(args):
        for _ in range(2):
            warn("presets", "the same text")
            logging.getLogger("tmfem.somewhere").warning("a library line")
        return {"presets": []}
    monkeypatch.setattr(presets, "run", twice)
    rc, _, err = run(["presets", "--quiet"], capsys)
    assert rc == 0
    assert err.strip().splitlines() == ["tmfem: WARNING: the same text",
                                        "tmfem: WARNING: a library line"]


def test_static_progress_lines_through_say(capsys):
    rc, _, err = run(["static", "--preset", "1-4", "--model", "mtc", "--mesh", "4", "--progress"],
                     capsys)
    assert rc == 0, err
    its = [x for x in err.splitlines() if " static it " in x]
    assert its and all(x.startswith("tmfem static: static it ") for x in its)
    rc, _, err = run(["static", "--preset", "1-4", "--model", "mtc", "--mesh", "4", "--progress",
                      "--quiet"], capsys)
    assert rc == 0 and " static it " not in err
