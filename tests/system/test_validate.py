"""Validation of every field of a system file (tmfem.system.validate): each refusal names the
table and the field, says what was expected and what was found. The files start from the
1-4 and 2-3 presets (valid files), with one field made hostile."""
import os
import re
import subprocess
import threading
import time
from pathlib import Path

import pytest
import tomli_w

from tmfem.errors import InputError, ResourceLimit
from tmfem.system import load_preset, load_system
from tmfem.system.presets import preset_dict
from tmfem.system.spec import system_to_dict
from tmfem.system.validate import BOUNDS, MAX_FILE_BYTES, read_bounded

DOCS = Path(__file__).resolve().parents[2] / "docs" / "guides" / "equilibrium.md"


def preset(name):
    d = preset_dict(name)
    d.pop("as_printed", None)
    return d


def general_2_3():
    """The 2-3 preset as a [general] file with its [[tendon]] list."""
    s = load_preset("2-3")
    d = system_to_dict(s)
    d.pop("symmetric")
    d.pop("rest_lengths", None)
    d["general"] = {"base": s.base.T.tolist(), "l": s.l.tolist(), "q": s.q.tolist()}
    d["tendon"] = [{"name": t.name, "family": t.family, "stage": t.stage, "j": t.j,
                    "ends": list(t.ends)} for t in s.tendons]
    return d


def write(tmp_path, d, name="s.toml"):
    p = tmp_path / name
    p.write_bytes(tomli_w.dumps(d).encode())
    return p


def refused(tmp_path, d, *needles, cls=InputError):
    with pytest.raises(cls) as exc:
        load_system(write(tmp_path, d))
    msg = str(exc.value)
    assert "\n" not in msg
    for n in needles:
        assert n in msg, msg
    return msg


def test_general_file_of_the_preset_loads(tmp_path):
    s = load_system(write(tmp_path, general_2_3()))
    assert len(s.tendons) == len(load_preset("2-3").tendons) == 21


def test_duplicate_tendon_name(tmp_path):
    d = general_2_3()
    d["tendon"][1]["name"] = d["tendon"][0]["name"]
    refused(tmp_path, d, "[[tendon]] entry 2", "unique tendon names", "'S_11'", "entry 1")


def test_unknown_tendon_family(tmp_path):
    d = general_2_3()
    d["tendon"][3]["family"] = "X"
    refused(tmp_path, d, "[[tendon]] entry 4", "'family'", "'X'")


def test_tendon_list_with_symmetric_does_not_apply(tmp_path):
    d = preset("1-4")
    d["tendon"] = general_2_3()["tendon"][:1]
    refused(tmp_path, d, "[[tendon]] does not apply with [symmetric]")


def test_q_with_too_few_values_names_q(tmp_path):
    d = general_2_3()
    d["general"]["q"] = d["general"]["q"][:2]
    # N = 3: 2 N = 6 coordinates for one stage, 21 for two (eqs. 3.1-3.2)
    refused(tmp_path, d, "[general]", "'q'", "6 for M = 1, 21 for M = 2", "found 2")


def test_l_count_must_match_the_stages(tmp_path):
    d = general_2_3()
    d["general"]["l"] = [1.8, 1.8]
    refused(tmp_path, d, "'l'", "M N = 6", "found 2")


def test_empty_theta_names_theta(tmp_path):
    d = preset("1-4")
    d["symmetric"]["theta_deg"] = []
    msg = refused(tmp_path, d, "'theta_deg'", "found []")
    assert "psi_deg" not in msg


@pytest.mark.parametrize("table, key, value", [
    ("membrane", "h", 1e-300), ("symmetric", "l", [1e30]), ("membrane", "E", 1.0),
    ("bar", "d", 50.0), ("symmetric", "r", [1e-9]), ("membrane", "r_mb", 1e6),
    ("symmetric", "psi_deg", [1e4]), ("membrane", "rho", 1e9)])
def test_implausible_values_are_refused_with_their_field(tmp_path, table, key, value):
    d = preset("1-4")
    d[table][key] = value
    lo, hi, unit, _ = BOUNDS[(table, key)]
    refused(tmp_path, d, f"[{table}]", f"'{key}'", f"{lo:g}..{hi:g} {unit}")


def test_implausible_tendon_and_rest_length(tmp_path):
    d = preset("1-4")
    d["tendons"]["S"]["E"] = 1e20
    refused(tmp_path, d, "[tendons.S]", "'E'")
    d = preset("1-4")
    d["rest_lengths"] = {"S1": 5e3}
    refused(tmp_path, d, "[rest_lengths]", "'S1'")


@pytest.mark.parametrize("name", ["a/b", "x y", "../up", "", "-x", "a" * 65, "café"])
def test_name_that_no_output_file_accepts(tmp_path, name):
    d = preset("1-4")
    d["name"] = name
    refused(tmp_path, d, "'name'", repr(name))


def test_missing_name_is_the_file_stem(tmp_path):
    d = preset("1-4")
    d.pop("name")
    assert load_system(write(tmp_path, d, "my system.toml")).name == "my_system"


def test_membrane_modes_bounded_like_the_option(tmp_path):
    d = preset("1-4")
    d["models"]["com"]["membrane_modes"] = 1000
    refused(tmp_path, d, "[models.com] membrane_modes 1000", "K <= 40", cls=ResourceLimit)


def test_bounds_table_of_the_guide_lists_the_code_bounds():
    text = DOCS.read_text()
    rows = re.findall(r"^\| `\[(.+?)\]`.*? \| `(\w+)`.*? \| (\S+) \| (\S+) \| (\S+) \|$", text, re.M)
    documented = {}
    for line in re.findall(r"^\|.*\|$", text.split("<!-- bounds:")[1].split("\n\n")[0], re.M)[2:]:
        cells = [c.strip() for c in line.strip("|").split("|")]
        tables = re.findall(r"`\[(.+?)\]`", cells[0])
        keys = re.findall(r"`(\w+)`", cells[1]) or ["*"]
        for t in tables:
            for k in keys:
                t = "tendons.*" if t == "tendons.KEY" else t
                documented[(t, k)] = (float(cells[2]), float(cells[3]), cells[4])
    assert rows
    assert documented == {k: v[:3] for k, v in BOUNDS.items()}


def test_oversized_file_refused_before_parsing(tmp_path):
    p = tmp_path / "big.toml"
    p.write_bytes(b"#" * (MAX_FILE_BYTES + 1))
    with pytest.raises(InputError, match="at most 1,048,576 bytes"):
        load_system(p)


def test_endless_stream_is_read_bounded():
    t0 = time.perf_counter()
    with pytest.raises(InputError, match="at most 1,048,576 bytes, found more"):
        load_system("/dev/zero")
    assert time.perf_counter() - t0 < 5


def test_fifo_endless_and_silent_writers(tmp_path):
    fifo = tmp_path / "f.toml"
    os.mkfifo(fifo)
    # an endless writer of its own process: it ends on SIGPIPE when the reader stops (a
    # thread here would take the test process with it where a library reset SIGPIPE)
    writer = subprocess.Popen(["sh", "-c", f"exec yes '# comment' > '{fifo}'"])
    try:
        with pytest.raises(InputError, match="found more"):
            load_system(fifo)
    finally:
        writer.kill()
        writer.wait(10)
    # a FIFO whose writer holds it open and sends nothing: refused after the timeout (a FIFO
    # of its own, so nothing the endless writer left in flight can reach it)
    fifo = tmp_path / "silent.toml"
    os.mkfifo(fifo)
    fd = os.open(fifo, os.O_RDWR)          # a writer that never writes (and does not block)
    try:
        t0 = time.perf_counter()
        with pytest.raises(InputError, match="within 0.5 s"):
            read_bounded(fifo, timeout=0.5)
        assert time.perf_counter() - t0 < 3
    finally:
        os.close(fd)


def test_fifo_with_a_system_file_loads(tmp_path):
    fifo = tmp_path / "f.toml"
    os.mkfifo(fifo)
    data = tomli_w.dumps(preset("1-4")).encode()

    def writer():
        with open(fifo, "wb") as fh:
            fh.write(data)
    threading.Thread(target=writer, daemon=True).start()
    assert load_system(fifo).name == "1-4"


def test_every_preset_is_within_the_bounds():
    from tmfem.system import list_presets
    for name in list_presets():
        for as_printed in (False, True):
            load_preset(name, as_printed=as_printed)


@pytest.mark.parametrize("value", [1e-300, 1e300])
def test_rest_lengths_from_an_option_share_the_bounds(value):
    with pytest.raises(InputError, match=r"within 0.001..1000 m .* found 1e[+-]300 m \(tendon 1 of 4\)"):
        load_preset("1-4").with_rest_lengths({"S1": value})


def test_section_and_rest_length_keys_no_tendon_takes(tmp_path):
    d = preset("1-4")
    d["tendons"]["V2"] = dict(d["tendons"]["S"])          # 1-4 has S_1j tendons only
    refused(tmp_path, d, "[tendons.V2]", "'V2'", "['S1']")
    d = preset("1-4")
    d["rest_lengths"] = {"S1": 1.5, "S9": 1.0}
    refused(tmp_path, d, "[rest_lengths]", "'S9'")
