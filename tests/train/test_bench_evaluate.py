"""The benchmark's evaluators agree with each other: the side-by-side batched ISE is the
single-env rollouts' ISE (one episode per seed, the same loads), and the validation rollout
counts every step of every episode."""

import gymnasium as gym
import numpy as np
import pytest

from baselines.policies import LQRPolicy
from train.core import evaluate

EPISODES = {1: (0,), 3: (0,), "random": (100000, 100001, 100002)}


@pytest.fixture(scope="module")
def lqr():
    return LQRPolicy.for_env(gym.make("ACLDBeam-v1").unwrapped)


def test_batched_ise_is_the_single_env_ise(lqr):
    batched = evaluate.batched_ise(lqr, "ACLDBeam-v1", EPISODES)
    single = evaluate.rollout_ise(lqr, "ACLDBeam-v1", EPISODES)
    assert batched.keys() == single.keys() == EPISODES.keys()
    for case in EPISODES:
        assert batched[case] > 0
        assert batched[case] == pytest.approx(single[case], rel=1e-9), case


class _Push:
    """A constant 120 V, whatever the observation."""

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(obs)
        return np.full(obs.shape[:-1] + (1,), 120.0, dtype=np.float32), state


def test_validation_rollout_counts_each_episode_until_it_ends():
    cost, steps = evaluate.validation_rollout(_Push(), "ACLDBeam-v1", seeds=(200000, 200001))
    env = gym.make("ACLDBeam-v1").unwrapped
    assert steps == 2 * env.config.max_steps  # no early end at the default 20 mm limit
    assert np.isfinite(cost) and cost > 1.0  # a constant 120 V is worse than no control
