"""``--quiet``: a command's own progress lines (``tmfem static: 1-4 MTC, ... free dofs``)
go through the CLI's message channel (:func:`tmfem.cli.common.say`) and are hidden with it,
as the library's progress is; errors still print (docs/guides/cli.md, "Progress and
messages")."""
import json

import pytest

from tests.cli.test_cli_misuse import TOO_LARGE, last_line, run


def test_static_prints_its_progress_lines_without_quiet(capsys):
    rc, out, err = run(["static", "--preset", "1-4", "--json"], capsys)
    assert rc == 0, err
    dofs = json.loads(out)["dofs"]                 # the model's own count, from the result
    lines = err.strip().splitlines()
    assert f"tmfem static: backend scipy ({dofs} free dofs)" in lines, err
    assert f"tmfem static: 1-4 MTC, {dofs} free dofs" in lines, err


def test_quiet_static_prints_nothing_on_stderr(capsys):
    rc, out, err = run(["static", "--preset", "1-4", "--quiet"], capsys)
    assert rc == 0, err
    assert err == ""
    assert "1-4" in out                            # the result itself still prints


def test_quiet_still_prints_the_error(capsys):
    rc, _, err = run(["static", "--preset", "1-4", "--mesh", "2000", "--quiet"], capsys)
    assert rc == TOO_LARGE
    assert len(err.strip().splitlines()) == 1
    assert last_line(err).startswith("tmfem static: error: ")


@pytest.mark.parametrize("argv, line", [
    (["modal", "--preset", "1-4"], "tmfem modal: 1-4 MTC, "),
    (["control", "hinf", "--preset", "1-4D"], "tmfem control hinf: 1-4D: building the plant"),
    (["vibrate", "--preset", "1-4", "--model", "com", "--t-end", "0.1"],
     "tmfem vibrate: 1-4 COM, "),
])
def test_quiet_hides_each_commands_own_line(argv, line, capsys):
    rc, _, err = run(argv, capsys)
    assert rc == 0 and any(l.startswith(line) for l in err.splitlines()), err
    rc, _, err = run(argv + ["--quiet"], capsys)
    assert rc == 0 and err == ""
