"""Property-based fuzz test of the system-file reader (tmfem.system.spec).

Property: whatever the bytes of a system file, :func:`tmfem.system.load_system` returns a
:class:`~tmfem.system.System` or raises a :class:`tmfem.errors.TmfemError` (a one-line
message for the CLI); never another exception. Mutations start from the shipped presets
(a real, valid file), so most examples get deep into the validation.
"""
import copy

import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tmfem.errors import TmfemError
from tmfem.system import load_system
from tmfem.system.presets import list_presets, preset_dict

from tests.system.test_validate import general_2_3
from tmfem.system.validate import MAX_FILE_BYTES

PRESETS = {name: preset_dict(name) for name in list_presets()}
PRESETS["general-2-3"] = general_2_3()         # [general] with a [[tendon]] list

# values a user might put where another type is expected
_odd = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-10**30, max_value=10**30),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -1.0, 1e300, -1e300, 1e-300, 2.0, 3, 1000, 10**9]),
    st.text(max_size=8), st.sampled_from(["1.5", "abc", "", "nan", "S_11"]),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4),
    st.lists(st.text(max_size=3), max_size=3),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
    # the fields of tmfem.system.validate: names, families, tendon entries, list lengths
    st.sampled_from(["a/b", "../x", "1-4", "S_11", "SL", "X", "q" * 70, "x y"]),
    st.lists(st.floats(-10, 10), max_size=40),
    st.lists(st.fixed_dictionaries({"name": st.sampled_from(["S_11", "S_12", "T"]),
                                    "family": st.sampled_from(["S", "V", "X", "SU"]),
                                    # a new list per draw: st.just would put one list object
                                    # into every document, so that a later mutation of it
                                    # changed the strategy (and could make it contain itself)
                                    "ends": st.builds(lambda: ["A_11", "B_13"])}), max_size=3),
    st.integers(min_value=0, max_value=10**6))


def _paths(d, prefix=()):
    """Every (path to a leaf or table) of a nested dict/list document."""
    out = []
    if isinstance(d, dict):
        for k, v in d.items():
            out.append(prefix + (k,))
            out += _paths(v, prefix + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            out.append(prefix + (i,))
            out += _paths(v, prefix + (i,))
    return out


def _set(d, path, value, delete=False):
    for k in path[:-1]:
        d = d[k]
    if delete:
        del d[path[-1]]
    else:
        d[path[-1]] = value


@st.composite
def mutated_documents(draw):
    name = draw(st.sampled_from(sorted(PRESETS)))
    doc = copy.deepcopy(PRESETS[name])
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(doc)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        delete = draw(st.booleans()) and draw(st.booleans())
        value = None if delete else draw(_odd)
        if value is None and not delete:
            delete = True          # TOML has no null: a missing key is the closest
        _set(doc, path, value, delete=delete)
    return doc


def _toml_bytes(doc):
    """The document as TOML, or None when tomli_w cannot express it (NaN keys are fine)."""
    try:
        return tomli_w.dumps(doc).encode()
    except (TypeError, ValueError):
        return None


def _check(path):
    try:
        load_system(path)
    except TmfemError as exc:
        msg = str(exc)
        assert msg and "\n" not in msg.strip() or len(msg.splitlines()) < 4, msg
    # any other exception fails the test with its traceback


def check_document(tmp_path, doc):
    """``doc`` written as a system file loads or raises a TmfemError (:func:`_check`); a
    document TOML cannot express is skipped."""
    data = _toml_bytes(doc)
    if data is None:
        return
    p = tmp_path / "fuzz.toml"
    p.write_bytes(data)
    _check(p)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                    HealthCheck.function_scoped_fixture])
@given(doc=mutated_documents())
def test_mutated_preset_files_load_or_raise_tmfem_error(tmp_path, doc):
    check_document(tmp_path, doc)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.one_of(st.binary(max_size=200),
                      st.builds(lambda s, b, k: s[:k] + b + s[k:],
                                st.just(tomli_w.dumps(PRESETS["1-4"]).encode()),
                                st.binary(min_size=1, max_size=8), st.integers(0, 400))))
def test_arbitrary_bytes_load_or_raise_tmfem_error(tmp_path, data):
    p = tmp_path / "fuzz.toml"
    p.write_bytes(data)
    _check(p)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(extra=st.integers(-64, 64))
def test_files_around_the_size_limit(tmp_path, extra):
    """A valid file padded to MAX_FILE_BYTES + extra bytes: loaded up to the limit, refused
    with the limit beyond it."""
    text = tomli_w.dumps(PRESETS["1-4"]).encode()
    size = MAX_FILE_BYTES + extra
    p = tmp_path / "padded.toml"
    p.write_bytes(text + b"#" * (size - len(text) - 1) + b"\n")
    assert p.stat().st_size == size
    if size > MAX_FILE_BYTES:
        with pytest.raises(TmfemError, match="at most 1,048,576 bytes"):
            load_system(p)
    else:
        assert load_system(p).name == "1-4"


def test_non_utf8_file_is_an_input_error(tmp_path):
    from tmfem.errors import InputError
    p = tmp_path / "latin1.toml"
    p.write_bytes('name = "caf\xe9"\nN = 4\n'.encode("latin-1"))
    with pytest.raises(InputError, match="UTF-8"):
        load_system(p)
