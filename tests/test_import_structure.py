"""The import graph of tmfem has no cycle and no module imports another module's private name.

The graph is grimp's (the library import-linter builds on), which reads every import
statement of every module, function-local imports included: a cycle hidden in a function
is still a cycle (the two modules cannot be understood, tested or loaded apart). A private
name (``_x``) is private to its module; a name another module needs is public, with a
docstring, in the module where it belongs (docs/architecture.md, "Imports").
"""
import ast
from pathlib import Path

import grimp
import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "tmfem"


@pytest.fixture(scope="module")
def graph():
    return grimp.build_graph("tmfem", include_external_packages=False, cache_dir=None)


def import_cycles(edges: dict) -> list:
    """The strongly connected components of more than one module (or a module importing
    itself) of the directed graph ``edges`` {module: imported modules} (Tarjan's algorithm,
    iterative), each sorted, in sorted order."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = 0
    for root in sorted(edges):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(edges.get(w, ())))))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1 or v in edges.get(v, ()):
                    out.append(sorted(comp))
    return sorted(out)


def test_cycle_finder_finds_a_cycle_through_three_modules_and_a_self_import():
    """The finder against graphs whose components are known by construction."""
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set(), "e": {"e"}, "f": {"d"}}
    assert import_cycles(edges) == [["a", "b", "c"], ["e"]]
    assert import_cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycle_between_tmfem_modules(graph):
    edges = {m: graph.find_modules_directly_imported_by(m) for m in graph.modules}
    cycles = import_cycles(edges)
    assert cycles == [], "import cycles (function-local imports included):\n" + "\n".join(
        " <-> ".join(c) for c in cycles)


def private_imports(path: Path, module: str) -> list:
    """``from M import _x`` of a tmfem module M other than ``module`` itself in the file
    ``path`` (module-level and function-local), as "module: M._x" strings."""
    tree = ast.parse(path.read_text(), filename=str(path))
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom):
            continue
        if node.level:
            base = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
            source = f"{base}.{node.module}" if node.module else base
        else:
            source = node.module or ""
        if not (source == "tmfem" or source.startswith("tmfem.")) or source == module:
            continue
        out += [f"{module}: {source}.{a.name}" for a in node.names
                if a.name.startswith("_") and not a.name.startswith("__")]
    return out


def test_private_import_finder_sees_function_local_and_relative_imports(tmp_path):
    f = tmp_path / "mod.py"
    f.write_text("from tmfem.x import a, _b\n\ndef g():\n    from .y import _c\n    from tmfem.p.mod import _own\n")
    assert private_imports(f, "tmfem.p.mod") == ["tmfem.p.mod: tmfem.x._b", "tmfem.p.mod: tmfem.p.y._c"]


def test_no_module_imports_a_private_name_of_another():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        found += private_imports(path, module)
    assert found == [], "private names imported across modules:\n" + "\n".join(found)
