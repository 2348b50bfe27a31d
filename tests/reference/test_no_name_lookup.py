"""No data is looked up by a system's name below the CLI's preset loader: the library reads
what a System carries (its file's tables), never a table keyed by ``system.name``.

The scan is syntactic (AST): it flags a system's ``.name`` (or a variable assigned from it in
the same function) used as a subscript ``D[...]``, as the key of ``.get(...)``/``.pop(...)``/
``.setdefault(...)``, in a comparison (``==``, ``!=``, ``in``, ``not in``) or as a dict-lookup
argument of ``in``. Receivers are the names a System goes by in the code (``system``,
``sysm``, ``final``, ``initial``, ``deployed``, ``s``, and any ``....system``).
"""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2] / "tmfem"
#: the preset loader: a preset is found by its name there, and only there
LOADER = {ROOT / "system" / "presets.py"}
RECEIVERS = {"system", "sysm", "final", "initial", "deployed", "s", "sys_k"}


def _is_system_name(node) -> bool:
    """``<system>.name`` for a receiver a System goes by."""
    if not (isinstance(node, ast.Attribute) and node.attr == "name"):
        return False
    v = node.value
    if isinstance(v, ast.Name):
        return v.id in RECEIVERS
    return isinstance(v, ast.Attribute) and v.attr in RECEIVERS


def name_lookups(tree) -> list:
    """(line, text) of every lookup by a system's name in ``tree`` (module docstring)."""
    found = []

    def tainted(node, names) -> bool:
        return _is_system_name(node) or (isinstance(node, ast.Name) and node.id in names)

    scopes = [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
    scopes.append(tree)
    for scope in scopes:
        names = set()
        for n in ast.walk(scope):
            if isinstance(n, ast.Assign) and _is_system_name(n.value):
                names |= {t.id for t in n.targets if isinstance(t, ast.Name)}
        for n in ast.walk(scope):
            subscript = isinstance(n, ast.Subscript) and tainted(n.slice, names)
            getter = (isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)
                      and n.func.attr in ("get", "pop", "setdefault") and bool(n.args)
                      and tainted(n.args[0], names))
            compare = isinstance(n, ast.Compare) and (
                tainted(n.left, names) or any(tainted(c, names) for c in n.comparators))
            if subscript or getter or compare:
                found.append((n.lineno, ast.unparse(n)))
    return sorted(set(found))


def library_files():
    return sorted(p for p in ROOT.rglob("*.py") if p not in LOADER)


def test_no_library_module_looks_data_up_by_system_name():
    bad = {}
    for path in library_files():
        hits = name_lookups(ast.parse(path.read_text(), filename=str(path)))
        if hits:
            bad[str(path.relative_to(ROOT.parent))] = hits
    assert not bad, bad


@pytest.mark.parametrize("source, expected", [
    ("def f(system):\n    return TABLE[system.name]\n", 1),
    ("def f(system):\n    return TABLE.get(system.name, {})\n", 1),
    ("def f(model):\n    return D.get(model.system.name)\n", 1),
    ("def f(system):\n    name = system.name\n    return IMPLIED.get(name)\n", 1),
    ("def f(system):\n    if system.name == '1-4':\n        pass\n", 1),
    ("def f(system):\n    return system.name in DEPLOYED\n", 1),
    # not lookups: messages and labels, other objects' names
    ("def f(system):\n    raise ValueError(f'system {system.name!r}')\n", 0),
    ("def f(law):\n    return law.name != 'svk'\n", 0),
    ("def f(system):\n    return {'system': system.name}\n", 0),
])
def test_the_scan_finds_lookups_and_only_lookups(source, expected):
    """The scan itself on small sources: each lookup form is found, labels are not."""
    assert len(name_lookups(ast.parse(source))) == expected
