"""The example of :mod:`acld_gym.envs.sb3`'s docstring runs as written (training stubbed:
the budget is the example's, not a test's) and builds what the guide gives any library:
one torch thread, actions in [-1, 1], the reward per load, mode 1 and the tip, and the
model on a VecNormalize."""

from __future__ import annotations

import textwrap

import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("torch")

import stable_baselines3  # noqa: E402
import torch  # noqa: E402
from stable_baselines3.common.vec_env import VecNormalize  # noqa: E402

import acld_gym.envs  # noqa: E402
from acld_gym.envs import sb3  # noqa: E402
from acld_gym.envs.presets import preset  # noqa: E402


def example() -> str:
    doc = sb3.__doc__
    return textwrap.dedent(doc[doc.index("::\n") + 3 : doc.index("Without wrappers")])


def test_the_example_builds_the_documented_setup(monkeypatch):
    built, learned = [], []

    class Recorded(sb3.SB3VecEnv):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            built.append(self)

    def learn(self, total_timesteps, **kwargs):
        learned.append((self.get_env(), total_timesteps))
        return self

    monkeypatch.setattr(acld_gym.envs, "SB3VecEnv", Recorded)
    monkeypatch.setattr(stable_baselines3.PPO, "learn", learn)
    threads = torch.get_num_threads()
    try:
        exec(example(), {})
        assert torch.get_num_threads() == 1
    finally:
        torch.set_num_threads(threads)
    assert len(built) == 3  # ACLDBeam-v1, the Lab by id, the adapted gym.make_vec
    for venv, level in zip(built, ["ACLDBeam-v1", "ACLDBeamLab-v1", "ACLDBeam-v1"], strict=True):
        assert venv.venv.config == preset(level, load_case="random", reward_scale="passive")
        assert venv.num_envs == 16
        assert (venv.action_space.low, venv.action_space.high) == (-1.0, 1.0)
        assert venv.observation_space.shape == (3,)  # mode 1's two states and the tip
        venv.close()
    [(env, steps)] = learned
    assert isinstance(env, VecNormalize) and env.venv is built[0] and steps == 100_000
