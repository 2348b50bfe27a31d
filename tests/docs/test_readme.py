"""Every ```python block of README.md runs on its own (a fresh namespace each), as a new user
would paste it from the repository root: each block imports what it uses."""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def test_readme_has_python_blocks():
    assert len(BLOCKS) >= 3


@pytest.mark.parametrize("k", range(len(BLOCKS)))
def test_readme_python_block_runs(k, monkeypatch):
    monkeypatch.chdir(ROOT)
    exec(compile(BLOCKS[k], f"README.md python block {k + 1}", "exec"), {})


def test_readme_links_exist():
    """Every relative link of README.md points to a file or directory of the repository."""
    for target in re.findall(r"\]\(([^)#\s]+)", README.read_text()):
        if "://" not in target:
            assert (ROOT / target).exists(), target
