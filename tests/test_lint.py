"""ruff (configured in pyproject.toml) finds nothing in the package, tests, benchmarks,
examples and demos."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_ruff_is_clean():
    ruff = Path(sys.executable).with_name("ruff")
    paths = [p for p in ("tmfem", "tests", "benchmarks", "examples", "demos") if (ROOT / p).exists()]
    r = subprocess.run([str(ruff), "check", "--no-cache", *paths], cwd=ROOT, capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
