"""The documentation, examples, demos and benchmarks speak of the product: what it does, how
to use it, why it is built so, its limits. They name no issue numbers, work sessions,
branches, commit hashes, dates of measurements or people working on it (history is in git)."""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FILES = sorted([*ROOT.glob("docs/**/*.md"), ROOT / "README.md", *ROOT.glob("examples/*.py"),
                *ROOT.glob("demos/*.py"), *ROOT.glob("benchmarks/*.py"), *ROOT.glob("docs/hooks/*.py")])
#: process words; "branch" and "helper" count only in their process uses (a git branch, a
#: worker), not as the branch of an equilibrium path or a helper function
PROCESS = re.compile(r"\bissues? \d+|\(issue\b|\bissue's\b|\bsessions?\b|\b(on|git) branch(es)?\b|"
                     r"\bbranch(es)? (main|[a-z]+\d+)\b|\bhelpers? [A-Z]\d?\b|\bhelper-\d|\bthe helpers?\b|"
                     r"\bthe lead\b|\(lead\b|\bstop \d+\b|\b20\d\d-\d\d-\d\d\b|\bthis machine state\b",
                     re.IGNORECASE)
HASH = re.compile(r"(?<![\w.+-])[0-9a-f]{7,40}(?![\w.])")


def process_words(text: str) -> list[str]:
    found = [m.group(0) for m in PROCESS.finditer(text)]
    found += [h for h in HASH.findall(text)
              if re.search(r"[a-f]", h) and re.search(r"\d", h) and not re.fullmatch(r"\d+e\d*", h)]
    return found


def test_the_scan_finds_process_words():
    assert process_words("fixed in issue 13 on branch sbc14d, commit 862f9a6 (2026-12-03)") == \
        ["issue 13", "on branch", "2026-12-03", "862f9a6"]
    assert process_words("written by helper B2") == ["helper B2"]
    assert process_words("the far branch of the path; option helpers") == []
    assert process_words("E = 1.539595e-3, 165000000 Pa, mode 12") == []


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_process_words(path):
    assert process_words(path.read_text()) == []


# The package, its preset files and the tests speak of the product too. Their words are
# scanned with the same patterns less the plain words that code uses in their ordinary
# sense ("branch" of a root, "helper" function): there only their process uses are caught.
CODE_FILES = sorted([*ROOT.glob("tmfem/**/*.py"), *ROOT.glob("tmfem/**/*.toml"), *ROOT.glob("tests/**/*.py")])
CODE_PROCESS = re.compile(r"\bissues? \d+|\(issue\b|\bissue's\b|\b(this|that|earlier|later|last|next) sessions?\b|"
                          r"\bhelpers? [A-Z]\d?\b|\bthe lead\b|\(lead\b|\bstop \d+\b|\bbranch (main|[a-z]+\d+)\b|"
                          r"\bcommit [0-9a-f]{7,40}\b|\bmain [0-9a-f]{7,40}\b", re.IGNORECASE)
SELF = Path(__file__).resolve()


def test_the_code_scan_finds_process_words():
    found = [m.group(0) for m in CODE_PROCESS.finditer(
        "as measured (issue 15) by helper B2 in this session on main b5c1033; the branch of asin")]
    assert found == ["(issue", "helper B2", "this session", "main b5c1033"]


@pytest.mark.parametrize("path", [f for f in CODE_FILES if f.resolve() != SELF],
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_no_process_words_in_code(path):
    assert [m.group(0) for m in CODE_PROCESS.finditer(path.read_text())] == []
