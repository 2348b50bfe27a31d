"""tmfem's on-disk cache (tmfem.cache): where it lives, what a read accepts, and that it never
makes a result fail.

References: the XDG base-directory specification (the directory), the entries the cache itself
wrote (a read returns exactly them).
"""
import json
import logging

import pytest

from tmfem import cache


def test_the_directory_follows_the_environment(monkeypatch, tmp_path):
    """TMFEM_CACHE_DIR, else $XDG_CACHE_HOME/tmfem (absolute only, as the specification says),
    else ~/.cache/tmfem."""
    monkeypatch.setenv("TMFEM_CACHE_DIR", str(tmp_path / "mine"))
    assert cache.cache_dir() == tmp_path / "mine"
    monkeypatch.delenv("TMFEM_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.cache_dir() == tmp_path / "xdg" / "tmfem"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/dir")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert cache.cache_dir() == tmp_path / "home" / ".cache" / "tmfem"


def test_an_entry_is_read_back_and_a_changed_key_or_version_misses(monkeypatch, tmp_path):
    monkeypatch.setenv("TMFEM_CACHE_DIR", str(tmp_path))
    store = cache.JsonCache("kind")
    path = store.put({"a": 1}, {"x": [1.5, 2.0]})
    assert path.parent == tmp_path / "kind" and store.get({"a": 1}) == {"x": [1.5, 2.0]}
    assert store.get({"a": 2}) is None
    assert [p.name for p in path.parent.iterdir()] == [path.name]      # no temporary file left
    monkeypatch.setattr(cache, "__version__", "0.0.0")
    assert store.get({"a": 1}) is None


@pytest.mark.parametrize("text", ["{not json", "[]", '{"key": {}, "value": {}}', ""])
def test_a_corrupt_or_foreign_entry_is_ignored_with_a_log_line(monkeypatch, tmp_path, caplog, text):
    monkeypatch.setenv("TMFEM_CACHE_DIR", str(tmp_path))
    store = cache.JsonCache("kind")
    path = store.put({"a": 1}, {"x": 1})
    path.write_text(text)
    with caplog.at_level(logging.INFO, logger="tmfem.cache"):
        assert store.get({"a": 1}) is None
    assert "recomputing" in caplog.text and str(path) in caplog.text


def test_an_entry_that_holds_another_key_is_ignored(monkeypatch, tmp_path):
    """The file repeats its key: a file copied under another key's name is not taken for it."""
    monkeypatch.setenv("TMFEM_CACHE_DIR", str(tmp_path))
    store = cache.JsonCache("kind")
    other = store.put({"a": 2}, {"x": 2})
    store.path({"a": 1}).write_text(other.read_text())
    assert json.loads(store.path({"a": 1}).read_text())["value"] == {"x": 2}
    assert store.get({"a": 1}) is None


def test_an_unwritable_directory_warns_once_and_goes_on(monkeypatch, tmp_path, caplog):
    """A cache directory below a regular file cannot be created (also as root): put returns
    None, one warning names the directory and the variable, a second put is silent."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("TMFEM_CACHE_DIR", str(blocker / "cache"))
    monkeypatch.setattr(cache, "_UNWRITABLE", set())
    store = cache.JsonCache("kind")
    with caplog.at_level(logging.WARNING, logger="tmfem.cache"):
        assert store.put({"a": 1}, {"x": 1}) is None
        assert store.put({"a": 2}, {"x": 2}) is None
    warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1 and "TMFEM_CACHE_DIR" in warnings[0].getMessage()
    assert store.get({"a": 1}) is None


def test_content_digest_follows_the_content_not_the_objects():
    import dataclasses
    import numpy as np

    @dataclasses.dataclass
    class Pair:
        a: np.ndarray
        names: list

    one = Pair(np.arange(3.0), ["x", "y"])
    assert cache.content_digest(one, {"k": 1.0}) == cache.content_digest(Pair(np.arange(3.0), ["x", "y"]),
                                                                           {"k": 1.0})
    changed = Pair(np.arange(3.0), ["x", "y"])
    changed.a[2] = np.nextafter(2.0, 3.0)                        # one bit of one entry
    assert cache.content_digest(changed) != cache.content_digest(one)
    assert cache.content_digest(np.zeros(2)) != cache.content_digest(np.zeros((2, 1)))
    assert cache.content_digest(1) != cache.content_digest(1.0)
    with pytest.raises(TypeError, match="found object"):
        cache.content_digest(object())


def test_memory_memo_keeps_the_last_values_and_computes_what_it_cannot_digest():
    memo, calls = cache.MemoryMemo(2), []

    def compute(v):
        calls.append(v)
        return v * 10

    for v in (1, 2, 1, 3, 1, 2):                 # 3 drops 2 (least recently used), 1 stays
        assert memo.get(v, lambda: compute(v)) == v * 10
    assert calls == [1, 2, 3, 2]
    obj = object()
    memo.get(obj, lambda: compute(0))
    memo.get(obj, lambda: compute(0))
    assert calls == [1, 2, 3, 2, 0, 0]
