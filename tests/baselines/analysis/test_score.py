"""The score between LQR (0) and the clairvoyant bound (1), and its cached references."""

import json

import gymnasium as gym
import numpy as np
import pytest

import baselines.analysis.references as references_module
from acld_gym.benchmark import evaluation_set
from baselines.analysis.references import cache_path, references
from baselines.analysis.score import episode_scores, score_of, score_policy
from baselines.evaluate import bound_episode, metrics_row, rollout
from baselines.policies import LQRPolicy, SMCPolicy

TEST = evaluation_set("ACLDBeam-v1")


@pytest.fixture(scope="module")
def refs5():
    return references(TEST.first(5))


class Replay:
    """Plays a fixed voltage sequence, whatever it observes (open loop)."""

    def __init__(self, voltages):
        self.v, self.k = np.asarray(voltages, np.float32), 0

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        v = self.v[min(self.k, self.v.size - 1)]
        self.k += 1
        return np.array([v], np.float32), state


def test_the_bounds_own_episodes_score_one_and_lqr_zero(refs5):
    assert np.all(score_of(refs5.bound_ise, refs5).scores == 1.0)
    s = score_policy(LQRPolicy(), n_episodes=5, refs=refs5)
    assert np.all(s.scores == 0.0) and s.iqm == s.ci_low == s.ci_high == 0.0
    assert s.as_dict() == {
        "iqm": 0.0,
        "ci_low": 0.0,
        "ci_high": 0.0,
        "n_episodes": 5,
        "test_set": "ACLDBeam-v1/test-v1",
        "mean_ise": pytest.approx(np.mean(refs5.lqr_ise), rel=1e-12),
    }


def test_replaying_the_bounds_voltages_open_loop_scores_one(refs5):
    env = gym.make("ACLDBeam-v1", load_case="random")
    ise = []
    for s in refs5.seeds:
        env.reset(seed=s)
        bound = bound_episode(env)
        ise.append(metrics_row("test", "replay", rollout(Replay(bound.voltage), env, seed=s)).ise)
    scores = episode_scores(ise, refs5.lqr_ise, refs5.bound_ise)
    np.testing.assert_allclose(scores, 1.0, atol=1e-6)  # the voltages are the env's float32


def test_the_interval_shrinks_as_episodes_are_added():
    widths = [
        (lambda s: s.ci_high - s.ci_low)(score_policy(SMCPolicy(), n_episodes=n))
        for n in (10, 20, 40)
    ]
    assert widths[0] > widths[1] > widths[2] > 0


def test_episode_scores_need_a_bound_below_lqr():
    np.testing.assert_allclose(episode_scores([2.0, 1.0], [3.0, 3.0], [1.0, 1.0]), [0.5, 1.0])
    with pytest.raises(ValueError, match="bound"):
        episode_scores([1.0], [1.0], [1.0])
    with pytest.raises(ValueError, match="one length"):
        episode_scores([1.0, 2.0], [3.0], [1.0])


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
    "damage", ["not json", "bound above lqr", "stale first episode", "other seeds"]
)
def test_a_damaged_or_stale_file_is_recomputed(counted, tmp_path, damage, capsys):
    test = TEST.first(3)
    good = references(test)
    path = _file(tmp_path)
    rec = json.loads(path.read_text())
    if damage == "not json":
        path.write_text("{")
    else:
        if damage == "bound above lqr":
            rec["bound_ise"][1] = 2 * rec["lqr_ise"][1]
        elif damage == "stale first episode":
            rec["lqr_ise"][0] *= 1.001
        else:
            rec["seeds"][2] += 1
        path.write_text(json.dumps(rec))
    counted.clear()
    again = references(test)
    assert len(counted) >= 3  # recomputed
    assert "recomputing the references" in capsys.readouterr().err
    np.testing.assert_array_equal(again.lqr_ise, good.lqr_ise)
    assert json.loads(path.read_text())["lqr_ise"] == good.lqr_ise.tolist()  # rewritten


def test_other_env_arguments_have_their_own_file(counted, tmp_path):
    test = TEST.first(2)
    references(test)
    references(test, {"param_noise": 0.05})
    assert len(list(tmp_path.glob("references-*.json"))) == 2
