"""A test set's references (passive, thesis LQR, bound per episode) and their cache: reused
after one spot check, recomputed with one line when damaged, stale or of an older format."""

import json
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import baselines.evaluation.references as references_module
from baselines.evaluation.cache import FORMAT, read_record
from baselines.evaluation.references import KIND, _damage, cache_path, references
from baselines.evaluation.seeds import evaluation_set

TEST = evaluation_set("ACLDBeam-v1")


# --- the cache ----------------------------------------------------------------------------
@pytest.fixture
def counted(monkeypatch, tmp_path):
    """A fresh cache directory, and a count of the episodes the references run."""
    monkeypatch.setenv("ACLD_GYM_CACHE_DIR", str(tmp_path))
    calls = []
    real = references_module.reference_episode

    def counting(env, seed):
        calls.append(seed)
        return real(env, seed)

    monkeypatch.setattr(references_module, "reference_episode", counting)
    return calls


def _file(tmp_path):
    (path,) = tmp_path.glob("references-*.json")
    return path


def test_a_cached_file_is_reused_after_one_spot_check(counted, tmp_path):
    test = TEST.first(3)
    first = references(test)
    assert len(counted) == 3
    again = references(test)
    assert counted[3:] == [test.seeds[0]]  # only the spot check ran
    np.testing.assert_array_equal(again.bound_ise, first.bound_ise)
    assert _file(tmp_path) == cache_path(test, _file(tmp_path).stem.rsplit("-", 1)[1])


@pytest.mark.parametrize(
    "damage",
    [
        "not json",
        "bound above lqr",
        "stale first episode",
        "other seeds",
        "format 1",
        "format 2",
        "nested 50000 deep",  # was a RecursionError
        "ISE as strings",  # numpy would have parsed them
    ],
)
def test_a_damaged_or_stale_file_is_recomputed(counted, tmp_path, damage, capsys):
    test = TEST.first(3)
    good = references(test)
    path = _file(tmp_path)
    rec = json.loads(path.read_text())
    if damage == "not json":
        path.write_text("{")
    elif damage == "nested 50000 deep":
        path.write_text("[" * 50000 + "]" * 50000)
    else:
        if damage == "bound above lqr":
            rec["bound_ise"][1] = 2 * rec["lqr_ise"][1]
        elif damage == "stale first episode":
            rec["lqr_ise"][0] *= 1.001
        elif damage == "ISE as strings":
            rec["lqr_ise"] = [str(v) for v in rec["lqr_ise"]]
        elif damage == "format 1":  # score v1's cache: no passive ISE
            del rec["passive_ise"]
            rec["format"] = 1
        elif damage == "format 2":  # score v2's cache before the one format: no kind
            del rec["kind"]
            rec["format"] = 2
        else:
            rec["seeds"][2] += 1
        path.write_text(json.dumps(rec))
    counted.clear()
    again = references(test)
    assert len(counted) >= 3  # recomputed
    err = capsys.readouterr().err
    assert "recomputing the references" in err and len(err.strip().splitlines()) == 1
    if damage.startswith("format"):
        assert f"need format {FORMAT}" in err
    np.testing.assert_array_equal(again.lqr_ise, good.lqr_ise)
    assert json.loads(path.read_text())["lqr_ise"] == good.lqr_ise.tolist()  # rewritten
    assert json.loads(path.read_text())["passive_ise"] == good.passive_ise.tolist()


def test_other_env_arguments_have_their_own_file(counted, tmp_path):
    test = TEST.first(2)
    references(test)
    references(test, {"param_noise": 0.05})
    assert len(list(tmp_path.glob("references-*.json"))) == 2


_RECORD = {"format": FORMAT, "kind": KIND, "key": "k", "seeds": [5, 6]} | {
    "passive_ise": [3.0, 4.0],
    "lqr_ise": [2.0, 3.0],
    "bound_ise": [1.0, 1.5],
}
_JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner),
    max_leaves=8,
)


@settings(max_examples=150, deadline=None)
@given(
    drop=st.sampled_from([None, *_RECORD]),
    field=st.sampled_from(list(_RECORD)),
    value=_JSON,
    cut=st.integers(0, 400),
)
def test_the_cache_check_is_total_on_mutated_records(tmp_path_factory, drop, field, value, cut):
    # deletion, type change and truncation of a record: the check says why or returns the
    # three arrays of the checked form, never another exception
    test = SimpleNamespace(seeds=(5, 6))
    rec = dict(_RECORD)
    if drop is not None:
        rec.pop(drop)
    rec[field] = value
    text = json.dumps(rec)
    if cut % 4 == 0:
        text = text[: cut % (len(text) + 1)]
    path = tmp_path_factory.mktemp("refs") / "r.json"
    path.write_text(text)
    rec = read_record(path, KIND, "k")
    got = rec if isinstance(rec, str) else _damage(rec, test)
    if isinstance(got, str):
        return
    assert len(got) == 3 and all(a.shape == (2,) and np.all(a > 0) for a in got)
    assert all(np.all(np.isfinite(a)) for a in got)
