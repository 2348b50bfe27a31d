"""The product speaks of the product: no text in the package, its docs, tests, benchmarks,
examples or demos refers to the process that made it (issue numbers, sessions, stops,
branches, commit hashes, who did what). History belongs in git."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCANNED = ("tmfem", "docs", "tests", "benchmarks", "examples", "demos", "README.md")
SUFFIXES = {".py", ".md", ".toml", ".txt", ".yml", ".yaml", ".html", ".j2", ".sh"}

#: each pattern with what it catches
PATTERNS = {
    "issue reference": r"\bissues? ?#?\d+|\(issue\b|\bissue tracker\b",
    "session or stop": r"\b(this|that|earlier|later|next|previous|last) sessions?\b|\bsessions? \d+|\bstop \d+\b",
    "worker role": r"\bhelpers? [A-Z]\d?\b|\b(the|a) lead\b|\blead's\b|\bhelper-\d",
    "branch or commit": r"\b(on|branch|main|commit|HEAD) (?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}\b"
                        r"|\bgit (log|blame|show|checkout)\b|\bbranch (main|master)\b",
}
SELF = Path(__file__).resolve()


def _files():
    for entry in SCANNED:
        p = ROOT / entry
        if p.is_file():
            yield p
        elif p.is_dir():
            yield from (f for f in p.rglob("*") if f.suffix in SUFFIXES and f.is_file()
                        and "__pycache__" not in f.parts and f.resolve() != SELF)


def test_no_process_words():
    hits = []
    for f in _files():
        for n, line in enumerate(f.read_text(errors="replace").splitlines(), 1):
            for what, pat in PATTERNS.items():
                m = re.search(pat, line, flags=re.I)
                if m:
                    hits.append(f"{f.relative_to(ROOT)}:{n}: {what}: {m.group(0)!r}")
    assert not hits, f"{len(hits)} process references:\n" + "\n".join(hits[:80])


def test_the_scan_catches_each_pattern():
    # the patterns themselves are checked on one sample each, so the scan cannot pass vacuously
    samples = {"issue reference": "fixed in (issue 15)", "session or stop": "as this session found",
               "worker role": "built by helper B2", "branch or commit": "measured on main b5c1033"}
    for what, text in samples.items():
        assert re.search(PATTERNS[what], text, flags=re.I), what
