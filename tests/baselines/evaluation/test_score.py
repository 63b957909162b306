"""Score v2, between the passive beam (0) and the clairvoyant bound (1)."""

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from acld_gym.util.stats import iqm_with_ci
from baselines.evaluation.references import references
from baselines.evaluation.rollout import bound_episode, metrics_row, rollout
from baselines.evaluation.score import (
    SCORE_VERSION,
    ScoreUndefined,
    episode_scores,
    format_scores,
    score_of,
    score_policies,
    score_policy,
)
from baselines.evaluation.seeds import TEST_SETS, evaluation_set
from baselines.oracle import ClairvoyantReplay
from baselines.policies import LQRPolicy, PassivePolicy, SMCPolicy

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


def test_the_references_own_ise_score_zero_and_one(refs5):
    assert np.all(score_of(refs5.bound_ise, refs5).scores == 1.0)
    s = score_policy(PassivePolicy(), n_episodes=5, refs=refs5)
    assert np.all(s.scores == 0.0) and s.iqm == s.ci_low == s.ci_high == 0.0
    assert s.as_dict() == {
        "version": SCORE_VERSION,
        "iqm": 0.0,
        "ci_low": 0.0,
        "ci_high": 0.0,
        "n_episodes": 5,
        "test_set": "ACLDBeam-v1/test-v1",
        "mean_ise": pytest.approx(np.mean(refs5.passive_ise), rel=1e-12),
        "ise_rel_thesis_lqr": pytest.approx(np.mean(refs5.passive_ise) / np.mean(refs5.lqr_ise)),
    }
    lqr = score_policy(LQRPolicy(), n_episodes=5, refs=refs5)
    assert 0.0 < lqr.iqm < 1.0 and lqr.ise_rel_thesis_lqr == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("env_id", ["ACLDBeam-v1", "ACLDBeamLab-v1", "ACLDBeamHard-v1"])
def test_passive_scores_zero_and_the_bounds_replay_one_on_every_level(env_id):
    """Computed through the path that scores a policy (the env, rollout, metrics_row), on
    each level's own test episodes: the passive beam's rollout and the bound's commands
    replayed open loop (they reach the amplifier after the level's delay)."""
    env = gym.make(env_id)
    scores = score_policies(
        {"passive": PassivePolicy.for_env(env), "bound_replay": ClairvoyantReplay()},
        env_id=env_id,
        n_episodes=3,
    )
    assert scores["passive"].test_set == TEST_SETS[env_id].name
    np.testing.assert_array_equal(scores["passive"].scores, 0.0)
    # the commands are the env's float32: the tip follows to ~1e-7 of the gap
    np.testing.assert_allclose(scores["bound_replay"].scores, 1.0, atol=1e-6)
    text = format_scores(scores)
    assert f"score on {env_id}/test-v1 (score v{SCORE_VERSION}:" in text and "passive 0" in text


def test_replaying_the_bounds_voltages_open_loop_scores_one(refs5):
    env = gym.make("ACLDBeam-v1", load_case="random")
    ise = []
    for s in refs5.seeds:
        env.reset(seed=s)
        bound = bound_episode(env)
        ise.append(metrics_row("test", "replay", rollout(Replay(bound.voltage), env, seed=s)).ise)
    scores = episode_scores(ise, refs5.passive_ise, refs5.bound_ise)
    np.testing.assert_allclose(scores, 1.0, atol=1e-6)  # the voltages are the env's float32


def test_the_interval_shrinks_as_episodes_are_added():
    """The first n episodes' scores are the first n of the 40-episode run's (each episode's
    score depends on its own references only), so their intervals come from one run."""
    full = score_policy(SMCPolicy(), n_episodes=40)
    assert (full.ci_low, full.ci_high) == pytest.approx(
        [iqm_with_ci(full.scores)[k] for k in ("ci_low", "ci_high")], rel=1e-12
    )
    widths = []
    for n in (10, 20, 40):
        stats = iqm_with_ci(full.scores[:n])
        widths.append(stats["ci_high"] - stats["ci_low"])
    assert widths[0] > widths[1] > widths[2] > 0


def test_episode_scores_need_a_bound_below_passive():
    np.testing.assert_allclose(episode_scores([2.0, 1.0], [3.0, 3.0], [1.0, 1.0]), [0.5, 1.0])
    for bound in (1.0, 1.5):  # equal to passive, above it
        with pytest.raises(ScoreUndefined, match="bound is not below the passive"):
            episode_scores([1.0, 1.0], [3.0, 1.0], [1.0, bound])
    with pytest.raises(ScoreUndefined, match="finite"):
        episode_scores([np.nan], [3.0], [1.0])
    with pytest.raises(ScoreUndefined, match="finite"):
        episode_scores([1.0], [np.inf], [1.0])
    assert issubclass(ScoreUndefined, ValueError)
    with pytest.raises(ValueError, match="one length"):
        episode_scores([1.0, 2.0], [3.0], [1.0])
    with pytest.raises(ValueError, match="one length"):
        episode_scores([[1.0]], [[3.0]], [[1.0]])


@settings(max_examples=60, deadline=None)
@given(
    passive=st.floats(1e-12, 1e-3),
    frac=st.floats(0.01, 0.99),
    ise_factor=st.floats(0.0, 3.0),
)
def test_episode_scores_are_the_affine_map_with_the_two_anchors(passive, frac, ise_factor):
    bound = frac * passive
    ise = ise_factor * passive
    s0, s1, s = episode_scores([passive, bound, ise], [passive] * 3, [bound] * 3)
    assert s0 == 0.0 and s1 == pytest.approx(1.0, rel=1e-12)
    assert s == pytest.approx((1.0 - ise_factor) / (1.0 - frac), rel=1e-9, abs=1e-9)
    assert (s > 1.0) == (ise < bound) and (s < 0.0) == (ise > passive)
