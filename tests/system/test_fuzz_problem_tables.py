"""Property-based fuzz test of the problem tables of a system file: ``[control]``,
``[deployment]``, ``[packaged]``, ``[lpv]``, ``[report]``, ``[monitor]`` and ``[models.com]``.

Property (as tests/system/test_fuzz_spec.py for the whole file): whatever these tables hold,
:func:`tmfem.system.load_system` returns a System or raises a
:class:`tmfem.errors.TmfemError` with a short message, never another exception. Mutations
land inside the tables only (the whole-file fuzz test reaches them rarely), with values
aimed at them: empty, long and unsorted grids, negative and huge numbers, nested and
misplaced tables."""
import copy

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.system.test_fuzz_spec import PRESETS, _paths, _set, check_document

TABLES = ("control", "deployment", "packaged", "lpv", "report", "monitor", "models")
#: the presets that carry each table (every table is in at least one)
HOLDERS = {t: sorted(n for n, d in PRESETS.items() if t in d) for t in TABLES}

_values = st.one_of(
    st.just([]), st.just({}), st.just(""), st.booleans(),
    st.sampled_from([0, -1, 1, 2, 40, 41, 1000, 10**7, 2**63 - 1]),
    st.sampled_from([0.0, -0.0, -1.0, 1e-300, 1e300, float("inf"), float("nan"), 90.0, 180.0,
                     181.0, -360.0]),
    st.lists(st.floats(-400, 400), max_size=8),                      # unsorted angles
    st.just([60.0 + 0.01 * i for i in range(2000)]),                 # a long axis
    st.just([[0.0, 0.0]] * 3), st.just([[1e9, 1e9]]), st.just([[0.1]]),   # points
    st.sampled_from(["delta", "linear", "table-7-7-bases", "no-MG", "exact", "initial", "x",
                     "B_11", "A_21", "lpv", "adaptive"]),
    st.dictionaries(st.sampled_from(["omega_0", "omega_e", "tau", "d_c", "x", "theta_deg",
                                     "symmetric", "packaged", "membrane_modes", "K"]),
                    st.one_of(st.floats(allow_nan=True), st.integers(-5, 50),
                              st.lists(st.floats(-100, 100), max_size=3)), max_size=4),
    st.fixed_dictionaries({"symmetric": st.fixed_dictionaries(
        {"theta_deg": st.lists(st.floats(-100, 100), min_size=1, max_size=3)})}),
)


@st.composite
def table_documents(draw):
    table = draw(st.sampled_from(TABLES))
    doc = copy.deepcopy(PRESETS[draw(st.sampled_from(HOLDERS[table]))])
    for _ in range(draw(st.integers(1, 3))):
        paths = [p for p in _paths(doc) if p[0] == table]
        if not paths:                        # the table was deleted: put something there
            doc[table] = copy.deepcopy(draw(_values))
            continue
        path = draw(st.sampled_from(paths))
        if draw(st.integers(0, 4)) == 0:
            _set(doc, path, None, delete=True)
        else:
            _set(doc, path, copy.deepcopy(draw(_values)))        # st.just shares its value
    return doc


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                    HealthCheck.function_scoped_fixture])
@given(doc=table_documents())
def test_problem_tables_load_or_raise_tmfem_error(tmp_path, doc):
    check_document(tmp_path, doc)


def test_every_table_is_fuzzed():
    assert all(HOLDERS[t] for t in TABLES), HOLDERS
