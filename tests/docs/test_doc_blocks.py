"""Every ```python block of the tutorial and the guides runs, as a reader would run it.

The blocks of one page run in order in one namespace (a page is read top to bottom, and its
later blocks use the names of its earlier ones), in a scratch directory where ``examples/``
and ``meshes/`` of the repository are reachable, so the files a page writes do not land in
the repository.

Two markers, each the first line of a block, change that; they are part of the page, so the
reader sees them too:

* ``# doc-test: skip (<reason>)``: the block is not run (a sketch with placeholders, a run of
  minutes); pytest shows the reason.
* ``# doc-test: requires <module>``: the block runs only where ``<module>`` imports (for
  example ``petsc4py``); elsewhere it is skipped with that reason. README.md's blocks are run by
``test_readme.py``.
"""
import importlib
import os
import re
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
SKIP = re.compile(r"#\s*doc-test:\s*skip\s*\((.+)\)")
REQUIRES = re.compile(r"#\s*doc-test:\s*requires\s+([\w.]+)")


def skip_reason(block: str) -> str | None:
    """Why a block is not run here, from its first line; None if it runs."""
    first = block.lstrip().splitlines()[0] if block.strip() else ""
    if m := SKIP.match(first):
        return m.group(1)
    if m := REQUIRES.match(first):
        try:
            importlib.import_module(m.group(1))
        except ImportError:
            return f"needs {m.group(1)}"
    return None


def python_blocks(md: Path) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", md.read_text(), flags=re.S | re.M)


PAGES = sorted(p for p in DOCS.rglob("*.md") if python_blocks(p))
#: pages whose blocks take long (the tutorial designs, deploys and reports a system of its own):
#: they run with the studies
SLOW_PAGES = {"tutorial.md", "guides/system-file.md", "guides/shells.md", "guides/lpvsyn.md"}


def test_tutorial_and_guides_have_blocks():
    names = {p.relative_to(DOCS).as_posix() for p in PAGES}
    assert "tutorial.md" in names and sum(n.startswith("guides/") for n in names) >= 5


@pytest.mark.parametrize("page", [pytest.param(p, marks=pytest.mark.slow)
                                  if p.relative_to(DOCS).as_posix() in SLOW_PAGES else p for p in PAGES],
                         ids=lambda p: p.relative_to(DOCS).as_posix())
def test_page_python_blocks_run(page, tmp_path, monkeypatch):
    for name in ("examples", "meshes"):
        os.symlink(ROOT / name, tmp_path / name)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace, skipped = {"__name__": "__doc_block__"}, []
    for k, block in enumerate(python_blocks(page), start=1):
        if reason := skip_reason(block):
            skipped.append(f"block {k}: {reason}")
            continue
        exec(compile(block, f"{page.relative_to(ROOT)} python block {k}", "exec"), namespace)
    if skipped and len(skipped) == len(python_blocks(page)):
        pytest.skip("; ".join(skipped))
    elif skipped:
        warnings.warn(f"{page.name}: not run: {'; '.join(skipped)}")


def test_tutorial_shows_the_example_file():
    """The system file printed in the tutorial is the one its code loads."""
    toml = re.findall(r"^```toml\n(.*?)^```", (DOCS / "tutorial.md").read_text(), flags=re.S | re.M)
    assert toml and toml[0] == (ROOT / "examples/pentagon.toml").read_text()


def test_markers_are_recognized():
    assert skip_reason("# doc-test: skip (a sketch)\nx = 1\n") == "a sketch"
    assert skip_reason("# doc-test: requires no_such_module_xyz\n") == "needs no_such_module_xyz"
    assert skip_reason("# doc-test: requires json\nimport json\n") is None
    assert skip_reason("# a comment\n") is None
