"""mkdocs hook: the API reference and the CLI reference are generated at build time.

* ``reference/api/<package>.md``: one page per subpackage of ``tmfem``, with a
  mkdocstrings ``:::`` block for the package and each of its public modules (modules whose
  name starts with ``_`` are left out). The modules are found on the file system, so a new
  module appears in the reference without editing anything.
* ``reference/cli.md``: the ``--help`` text of ``tmfem`` and of every subcommand (nested
  ones such as ``tmfem control hinf`` included), taken from ``tmfem.cli.build_parser()``.

The generated pages are added to the navigation under "Reference".

A strict build (``mkdocs build --strict``, ``tests/docs/test_docs_build.py``) fails on every
warning about the written pages: broken links, missing pages, unknown anchors. Warnings about
the *formatting of docstrings* (griffe cannot parse a numpydoc section, a bracket in an
equation such as ``[N_R 0; 0 I]`` read as a cross-reference) are shown as INFO instead: they
do not make a page or a link wrong.
"""
from __future__ import annotations

import argparse
import logging
import os
from pathlib import Path

from mkdocs.structure.files import File
from mkdocs.utils import CountHandler

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "tmfem"
# The CLI's modules are described by the CLI reference (their parsers), not by their code.
API_SKIP = {"cli"}


def _modules(package_dir: Path) -> list[str]:
    """Dotted names of the public modules under ``package_dir`` (package first, sorted)."""
    names = []
    for path in sorted(package_dir.rglob("*.py")):
        rel = path.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(p.startswith("_") for p in parts):
            continue
        names.append(".".join(parts))
    return sorted(names)  # a package sorts before its modules


def api_pages() -> dict[str, str]:
    """Markdown of every API page, keyed by its path below the docs directory."""
    pages = {}
    for pkg in sorted(p for p in PACKAGE.iterdir() if (p / "__init__.py").exists()):
        if pkg.name in API_SKIP:
            continue
        mods = _modules(pkg)
        text = [f"# `tmfem.{pkg.name}`\n"]
        for mod in mods:
            text.append(f"::: {mod}\n")
        pages[f"reference/api/{pkg.name}.md"] = "\n".join(text)
    top = ["# `tmfem`\n", "The names importable from the top-level package.\n", "::: tmfem\n",
           "    options:\n      members: true\n"]
    top.append("::: tmfem.errors\n")
    pages["reference/api/index.md"] = "\n".join(top)
    return pages


def _subparsers(parser: argparse.ArgumentParser):
    for action in parser._actions:  # argparse keeps its subcommands here only
        if isinstance(action, argparse._SubParsersAction):
            return action.choices
    return {}


def cli_page() -> str:
    """The ``--help`` of ``tmfem`` and of every (nested) subcommand, as one Markdown page."""
    os.environ.setdefault("COLUMNS", "100")
    from tmfem.cli import build_parser

    parser = build_parser()
    out = ["# CLI reference\n",
           "Generated from the command-line parser: the `--help` text of every command. "
           "How to use the commands together, exit codes and error messages: "
           "[the CLI guide](../guides/cli.md).\n"]

    def walk(p: argparse.ArgumentParser, words: list[str]):
        title = " ".join(words)
        level = "#" * min(len(words) + 1, 4)
        out.append(f"{level} `{title}`\n")
        out.append("```text\n" + p.format_help().rstrip() + "\n```\n")
        for name, child in _subparsers(p).items():
            walk(child, words + [name])

    walk(parser, ["tmfem"])
    return "\n".join(out)


def on_files(files, config, **kwargs):
    for path, text in {**api_pages(), "reference/cli.md": cli_page()}.items():
        files.append(File.generated(config, path, content=text))
    return files


def _is_docstring_format(record: logging.LogRecord) -> bool:
    """A warning about how a docstring is written, not about a page or a link."""
    msg = record.getMessage()
    if "griffe" in record.name or msg.startswith("griffe:"):
        return True
    if "Could not find cross-reference target" in msg and f"{os.sep}tmfem{os.sep}" in msg:
        return True
    return msg.startswith("Doc file 'reference/api/") and "unrecognized relative link" in msg


def _demote(record: logging.LogRecord) -> bool:
    if record.levelno == logging.WARNING and _is_docstring_format(record):
        record.levelno, record.levelname = logging.INFO, "INFO"
    return True


def _install_log_filters():
    for handler in logging.getLogger("mkdocs").handlers:
        if isinstance(handler, CountHandler):  # strict mode counts what reaches it
            handler.addFilter(lambda r: not _is_docstring_format(r))
        handler.addFilter(_demote)


def on_config(config, **kwargs):
    _install_log_filters()
    api = [{"tmfem": "reference/api/index.md"}]
    api += [{f"tmfem.{name}": f"reference/api/{name}.md"}
            for name in sorted(p.name for p in PACKAGE.iterdir()
                               if (p / "__init__.py").exists() and p.name not in API_SKIP)]
    for entry in config.nav or []:
        if isinstance(entry, dict) and "Reference" in entry:
            entry["Reference"] = [{"CLI": "reference/cli.md"}, {"API": api}]
    return config
