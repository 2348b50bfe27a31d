"""Reading .npz archives (tmfem.io.npz): another kind of file is named as what it is (never
"pickled data" with advice to load it unsafely)."""
import numpy as np
import pytest

from tests.cli.test_cli_misuse import BAD_INPUT, last_line, run
from tmfem.errors import InputError
from tmfem.io.npz import file_kind, read_npz
from tmfem.system import dump_system, load_preset


@pytest.fixture
def files(tmp_path):
    out = {"toml": tmp_path / "s.toml", "csv": tmp_path / "h.csv", "npy": tmp_path / "a.npy",
           "npz": tmp_path / "k.npz", "empty": tmp_path / "e.npz", "pickle": tmp_path / "p.npz"}
    dump_system(load_preset("1-4"), out["toml"])
    out["csv"].write_text("t [s],x [m]\n0,1\n")
    np.save(out["npy"], np.eye(2))
    np.savez(out["npz"], A=np.eye(2))
    out["empty"].write_bytes(b"")
    import pickle
    out["pickle"].write_bytes(pickle.dumps({"a": 1}))
    return out


def test_file_kinds(files):
    assert {k: file_kind(p) for k, p in files.items()} == {
        "toml": "a TOML file (a system file?)", "csv": "a text file", "npy": "an .npy array",
        "npz": "an .npz archive", "empty": "an empty file", "pickle": "a pickle"}
    assert np.array_equal(read_npz(files["npz"], expected="x")["A"], np.eye(2))


@pytest.mark.parametrize("kind", ["toml", "csv", "npy", "empty", "pickle"])
def test_recheck_names_the_expected_file_type(kind, files, capsys):
    rc, _, err = run(["control", "recheck", str(files[kind])], capsys)
    line = last_line(err)
    assert rc == BAD_INPUT
    assert "expected an .npz design file written by `tmfem control hinf --save`" in line
    assert f"found {file_kind(files[kind])}" in line
    assert "pickle" not in line.replace("found a pickle", "") and "unsafe" not in line


def test_lpv_controller_file_of_another_kind(files):
    from tmfem.control.lpv.synthesis import LPVStateFeedback
    with pytest.raises(InputError, match=r"expected an .npz LPV controller .* found a TOML file"):
        LPVStateFeedback.load(files["toml"])
