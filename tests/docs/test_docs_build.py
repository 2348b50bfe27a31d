"""The documentation site builds in strict mode (mkdocs.yml): every link between pages, every
anchor and every page of the navigation exists, the API reference is generated from the
docstrings of every public module and the CLI reference from ``tmfem.cli.build_parser()``."""
import importlib.util
import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
pytest.importorskip("mkdocs", reason="the doc tools are in the dev extra: pip install -e '.[dev]'")
pytest.importorskip("mkdocstrings", reason="the doc tools are in the dev extra: pip install -e '.[dev]'")


def _hook():
    spec = importlib.util.spec_from_file_location("reference_pages", ROOT / "docs/hooks/reference_pages.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, PYTHONPATH=str(ROOT), NO_MKDOCS_2_WARNING="1", OPENBLAS_NUM_THREADS="1")
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-f",
                          str(ROOT / "mkdocs.yml"), "-d", str(out)],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-4000:]
    return out


@pytest.mark.slow
def test_site_builds_strict(site):
    for page in ["index.html", "tutorial/index.html", "architecture/index.html",
                 "validation/errata/index.html", "reference/cli/index.html"]:
        assert (site / page).is_file(), page


@pytest.mark.slow
def test_every_markdown_page_is_in_the_site(site):
    """No page of docs/ is left out of the build (a guide nobody can reach)."""
    docs = ROOT / "docs"
    for md in docs.rglob("*.md"):
        rel = md.relative_to(docs).with_suffix("")
        html = site / ("index.html" if rel.name == "index" and rel.parent == Path(".")
                       else rel / "index.html")
        assert html.is_file(), md


@pytest.mark.slow
def test_api_reference_has_every_package_and_module(site):
    """Each subpackage of tmfem has a page that documents each of its public modules."""
    hook = _hook()
    pages = hook.api_pages()
    for pkg in (ROOT / "tmfem").iterdir():
        if (pkg / "__init__.py").exists() and pkg.name not in hook.API_SKIP:
            html = (site / "reference/api" / pkg.name / "index.html").read_text()
            for mod in hook._modules(pkg):
                assert f"::: {mod}" in pages[f"reference/api/{pkg.name}.md"]
                assert f'id="{mod}"' in html, mod


@pytest.mark.slow
def test_cli_reference_has_every_subcommand(site):
    from tmfem.cli import build_parser
    hook = _hook()
    html = (site / "reference/cli/index.html").read_text()
    for name, sub in hook._subparsers(build_parser()).items():
        assert f"tmfem {name}" in html, name
        for nested in hook._subparsers(sub):
            assert f"tmfem {name} {nested}" in html, (name, nested)


@pytest.mark.parametrize("logger, message, docstring", [
    ("mkdocs.plugins.griffe", "griffe: tmfem/x.py:1: Parameter 'A' does not appear in the function signature", True),
    ("mkdocs.plugins.mkdocs_autorefs",
     f"api.md: from {os.sep}r{os.sep}tmfem{os.sep}x.py:1: Could not find cross-reference target 'N_R 0'", True),
    ("mkdocs.structure.pages", "Doc file 'guides/a.md' contains a link 'b.md', but the target 'guides/b.md' "
                               "is not found among documentation files.", False),
    ("mkdocs.structure.pages", "Doc file 'guides/a.md' contains a link 'b.md#x', but the doc 'guides/b.md' "
                               "does not contain an anchor '#x'.", False),
    ("mkdocs.plugins.mkdocs_autorefs", "guides/a.md: Could not find cross-reference target 'tmfem.nothing'", False),
])
def test_only_docstring_formatting_is_demoted(logger, message, docstring):
    """Broken links, anchors and cross-references of the written pages stay fatal."""
    record = logging.LogRecord(logger, logging.WARNING, "", 0, message, None, None)
    assert _hook()._is_docstring_format(record) is docstring
