"""Every command that solves with a backend names it, in its text and in its JSON."""
import json

import pytest

from tmfem.cli import main
from tmfem.solvers.backends import AUTO_CROSSOVER_DOFS
from tests.solvers.test_petsc_backend import needs_petsc


def _json(capsys, argv):
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("backend", ["auto", pytest.param("petsc", marks=needs_petsc)])
def test_vibrate_json_names_the_backend(capsys, backend):
    # source: the documented crossover of --backend auto (scipy below AUTO_CROSSOVER_DOFS free
    # dofs; the 4 x 4 x 4 mesh has 267) and the backend asked for
    d = _json(capsys, ["vibrate", "--preset", "1-4", "--model", "mtc", "--mesh", "4",
                       "--t-end", "0.02", "--backend", backend])
    assert d["ndof"] < AUTO_CROSSOVER_DOFS
    assert d["backend"] == ("scipy" if backend == "auto" else backend)


def test_converge_rows_name_the_backend_of_each_mesh(capsys):
    # source: the documented crossover of --backend auto, mesh by mesh (each row's own model)
    d = _json(capsys, ["converge", "--preset", "1-4", "--mesh", "4,6", "--modes", "2"])
    assert [r["backend"] for r in d["rows"]] == ["scipy" if r["dofs"] < AUTO_CROSSOVER_DOFS
                                                 else "petsc" for r in d["rows"]]
    assert main(["converge", "--preset", "1-4", "--mesh", "4", "--modes", "2"]) == 0
    assert "backend" in capsys.readouterr().out
