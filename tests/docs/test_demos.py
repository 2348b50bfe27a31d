"""Every script of demos/ (one per reproduced dissertation result) runs to the end, in a
reduced size where it has one, as ``.venv/bin/python demos/<name>.py ARGS`` would.

The scripts run in this process (``runpy``, ``__name__ == "__main__"``, their arguments in
``sys.argv``), in a scratch directory, so that tmfem is imported once. A script whose full
size takes longer than a few seconds runs with arguments that shrink it (a shorter time span,
a coarser mesh, one system) and is marked ``slow``. What each reproduces, and the full-size
command: docs/validation/reproduction.md. The numbers they print are asserted by the tests of
the library functions they call (tests/reference/, tests/models/, ...).
"""
import runpy
import sys
from pathlib import Path

import pytest

DEMOS = Path(__file__).resolve().parents[2] / "demos"

# script -> reduced arguments; the second entry marks the slow ones
RUNS = {
    "equilibrium_1_4.py": ([], False),
    "equilibrium_1_4D.py": ([], False),
    "equilibrium_1_6D.py": ([], False),
    "equilibrium_2_3.py": ([], False),
    "equilibrium_2_3_deploy.py": ([], False),
    "equilibrium_2_3_lpv.py": ([], False),
    "mtc_1_4.py": ([], False),
    "mtc_2_3.py": ([], False),
    "com_frequencies.py": (["--systems", "1-4", "--k-study", "2"], True),
    "com_free_vibration.py": (["--out", "com", "--t-end", "0.5"], True),
    "free_vibration_compare.py": (["--out", "vib", "--t-end", "0.2", "--mesh", "4"], True),
    "element_benchmarks.py": (["--out", "elements"], True),
}


def test_every_demo_is_run():
    assert sorted(p.name for p in DEMOS.glob("*.py")) == sorted(RUNS)


@pytest.mark.parametrize("name", [pytest.param(n, marks=[pytest.mark.slow] if slow else [])
                                  for n, (_, slow) in RUNS.items()])
def test_demo_runs(name, tmp_path, monkeypatch, capsys):
    args, _ = RUNS[name]
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setattr(sys, "argv", [str(DEMOS / name), *args])
    monkeypatch.syspath_prepend(str(DEMOS))
    try:
        runpy.run_path(str(DEMOS / name), run_name="__main__")
    except SystemExit as exc:
        assert exc.code in (0, None), f"{name} exited with {exc.code}"
    assert capsys.readouterr().out.strip(), f"{name} printed nothing"
