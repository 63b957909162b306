"""The benchmark's trained policies as safe agent directories: the exported actor program
acts exactly like the trained policy. (That the benchmark's agent folders load, say "from
scratch" with no teacher, reproduce their trial's evaluation and are picked up by
``train.ship`` / ``train.compare`` is checked on the end-to-end run of
``tests/train/test_benchmark.py::test_benchmark_runs_end_to_end``.)"""

import gymnasium as gym
import numpy as np
import pytest

import acld_gym  # noqa: F401  (registers the env ids)
from acld_gym.wrappers import whitening
from train.agent import TrainedAgent, linear_program
from train.core.search import LinearDirectionActor


def _observations(n=64, seed=0):
    """Observations of a passive episode (so of the env's scale and correlations)."""
    env = gym.make("ACLDBeam-v1", load_case="random").unwrapped
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for _ in range(n - 1):
        obs, *_ = env.step(np.zeros(1, np.float32))
        out.append(obs)
    return np.array(out)


@pytest.mark.parametrize("features", [None, "direction"])
@pytest.mark.parametrize("whiten", [False, True])
def test_linear_program_acts_like_the_random_search_actor(features, whiten):
    z = _observations()
    rng = np.random.default_rng(1)
    transform = whitening(z / np.linalg.norm(z, axis=1, keepdims=True)) if whiten else None
    dim = z.shape[1] + 1 + (features == "direction")
    actor = LinearDirectionActor(rng.normal(0, 3.0, dim), 120.0, features, transform)
    agent = TrainedAgent(linear_program(actor.theta, transform, features), {}, "vrs")
    v_actor, _ = actor.predict(z)
    v_agent, _ = agent.predict(z)
    assert np.abs(v_actor).max() == pytest.approx(120.0)  # the clip is exercised
    np.testing.assert_allclose(v_agent, v_actor, rtol=1e-5, atol=1e-4)


def test_linear_program_rejects_unknown_features():
    with pytest.raises(ValueError, match="features"):
        linear_program(np.zeros(3), None, "quadratic")
