"""baselines.evaluation.cache, the one cache of the references: a record is reused only if
it is of this format, kind and key and passes its kind's check; anything else is one line
on stderr, recomputed and replaced; reading is total on any bytes."""

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from baselines.evaluation.cache import FORMAT, MAX_BYTES, cached, read_record, record_key


class Compute:
    """A payload, and how many times it was computed."""

    def __init__(self, payload):
        self.payload, self.calls = payload, 0

    def __call__(self):
        self.calls += 1
        return dict(self.payload)


def fine(rec):
    return None if isinstance(rec.get("x"), int) else "x: expected an integer"


def test_a_record_is_computed_once_then_read_back(tmp_path, capsys):
    path, compute = tmp_path / "r.json", Compute({"x": 3})
    first = cached(path, "kind", "k1", compute, fine, "the test's references")
    assert first == {"format": FORMAT, "kind": "kind", "key": "k1", "x": 3}
    assert json.loads(path.read_text()) == first
    assert cached(path, "kind", "k1", compute, fine, "the test's references") == first
    assert compute.calls == 1 and capsys.readouterr().err == ""
    assert cached(None, "kind", "k1", compute, fine, "-") == first and compute.calls == 2
    assert sorted(tmp_path.iterdir()) == [path]  # None: nothing written


@pytest.mark.parametrize(
    "record, why",
    [
        ({"env_id": "ACLDBeam-v1", "lqr": {}}, "another format"),  # before the one format
        ({"format": 2, "key": "k1", "x": 3}, "another format"),  # the test sets' format 2
        ({"format": FORMAT, "kind": "other", "key": "k1", "x": 3}, "another format"),
        ({"format": FORMAT, "kind": "kind", "key": "k0", "x": 3}, "another key"),
        ({"format": FORMAT, "kind": "kind", "key": "k1", "x": "3"}, "x: expected an integer"),
        ([1, 2], "not a mapping"),
    ],
)
def test_another_format_kind_key_or_payload_is_one_line_then_recomputed(
    tmp_path, capsys, record, why
):
    path, compute = tmp_path / "r.json", Compute({"x": 4})
    path.write_text(json.dumps(record))
    got = cached(path, "kind", "k1", compute, fine, "the test's references")
    assert got["x"] == 4 and compute.calls == 1
    assert json.loads(path.read_text()) == got  # replaced
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and why in err[0] and str(path) in err[0]
    assert err[0].startswith("baselines: recomputing the test's references")


def test_an_unwritable_cache_costs_only_the_time_unless_required(tmp_path):
    folder = tmp_path / "a-file"
    folder.write_text("")
    path = folder / "r.json"  # its parent is a file: cannot be written
    assert cached(path, "kind", "k", Compute({"x": 1}), fine, "-")["x"] == 1
    with pytest.raises(OSError):
        cached(path, "kind", "k", Compute({"x": 1}), fine, "-", required=True)


def test_the_key_depends_on_every_input():
    assert record_key({"a": 1}) == record_key({"a": 1})
    assert len({record_key({"a": 1}), record_key({"a": 2}), record_key({"b": 1})}) == 3
    assert len(record_key({"a": 1})) == 16


_JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner),
    max_leaves=8,
)


@settings(max_examples=150, deadline=None)
@given(value=_JSON, raw=st.binary(max_size=60), cut=st.integers(0, 200))
def test_reading_is_total_on_any_bytes(tmp_path_factory, value, raw, cut):
    path = tmp_path_factory.mktemp("cache") / "r.json"
    good = {"format": FORMAT, "kind": "kind", "key": "k"}
    for data in (raw, json.dumps(value).encode(), json.dumps(good | {"x": value}).encode()[:cut]):
        path.write_bytes(data)
        got = read_record(path, "kind", "k")
        assert isinstance(got, str) or (isinstance(got, dict) and got["key"] == "k")


def test_too_large_and_too_deep_files_are_refused(tmp_path):
    path = tmp_path / "r.json"
    path.write_text("[" * 50_000 + "]" * 50_000)
    assert "not JSON" in read_record(path, "kind", "k")
    with open(path, "wb") as fh:
        fh.truncate(MAX_BYTES + 1)
    assert "larger than" in read_record(path, "kind", "k")
