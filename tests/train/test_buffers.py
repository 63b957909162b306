"""train.core.buffers.FlatNStepReplayBuffer returns stable-baselines3's n-step samples bit
for bit, and the SAC recipe's model uses it."""

import gymnasium as gym
import numpy as np
import pytest
import torch
from benchmark_scripts import load_script
from gymnasium import spaces
from stable_baselines3.common.buffers import NStepReplayBuffer
from stable_baselines3.common.running_mean_std import RunningMeanStd
from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize
from tiny_sb3 import tiny_sac_recipe

from train.core.buffers import FlatNStepReplayBuffer

OBS = spaces.Box(-np.inf, np.inf, (5,), np.float32)


def _filled(cls, size: int, n_envs: int, rows: int, n_steps: int):
    """benchmarks/bench_sac.py's random buffer, a tenth of its transitions ending an episode
    (half of those by the time limit)."""
    return load_script("bench_sac").filled_buffer(cls, size, n_envs, rows, n_steps, 0.99, 0.1)


def _norm_env():
    """A ``VecNormalize`` with statistics of its own (over a 5-value observation), which
    normalises observations and rewards."""
    env = VecNormalize(DummyVecEnv([lambda: gym.make("Pendulum-v1")]))
    env.obs_rms = RunningMeanStd(shape=OBS.shape)
    env.obs_rms.mean, env.obs_rms.var = np.linspace(-1, 1, 5), np.linspace(0.5, 2, 5)
    env.ret_rms.var = np.array(3.0)
    return env


@pytest.mark.parametrize(
    "size, n_envs, rows, n_steps",
    [(500, 8, 120, 5), (50, 4, 137, 5), (50, 3, 50, 3), (40, 2, 95, 1)],
)
@pytest.mark.parametrize("normalize", [False, True])
def test_same_samples_as_sb3(size, n_envs, rows, n_steps, normalize):
    ours = _filled(FlatNStepReplayBuffer, size, n_envs, rows, n_steps)
    sb3 = _filled(NStepReplayBuffer, size, n_envs, rows, n_steps)
    env = _norm_env() if normalize else None
    for k in range(30):
        np.random.seed(k)  # noqa: NPY002 (SB3 samples from numpy's global generator)
        a = ours.sample(64, env)
        np.random.seed(k)  # noqa: NPY002 (SB3 samples from numpy's global generator)
        b = sb3.sample(64, env)
        for field in b._fields:
            x, y = getattr(a, field), getattr(b, field)
            assert x.dtype == y.dtype and x.shape == y.shape, field
            assert torch.equal(x, y), field
    # the temporary truncation of the last written row is undone
    np.testing.assert_array_equal(ours.timeouts, sb3.timeouts)


def test_the_samples_cover_episode_ends_and_the_wrap():
    """The comparison above is not vacuous: its batches hold n-step returns cut short by an
    episode end (discount below gamma^n) and n-step windows across the buffer's end."""
    buf = _filled(FlatNStepReplayBuffer, 50, 4, 137, 5)
    np.random.seed(0)  # noqa: NPY002 (SB3 samples from numpy's global generator)
    cut = full = 0
    for _ in range(30):
        s = buf.sample(64)
        d = s.discounts.numpy().ravel()
        cut += int((d > 0.99**5 + 1e-6).sum())
        full += int(np.isclose(d, 0.99**5).sum())
    assert cut > 0 and full > 0
    assert buf.full and buf.pos != 0  # wrapped, the write position inside the storage


def test_sac_recipe_model_uses_it():
    from train.core.sb3_train import make_model
    from train.vec import make_vec_env

    cfg = tiny_sac_recipe(1000)
    venv = make_vec_env(cfg, 0, "ACLDBeam-v1")
    model = make_model(cfg, venv, 0)
    assert type(model.replay_buffer) is FlatNStepReplayBuffer
    assert model.replay_buffer.n_steps == cfg.model["n_steps"] == 5
    assert model.replay_buffer.gamma == cfg.model["gamma"]
    venv.close()


def test_sac_trains_bit_for_bit_as_with_sb3s_buffer(monkeypatch):
    """The tiny SAC recipe trained with the flat buffer and with SB3's own (the buffer swap
    undone) ends at the same parameters, exactly."""
    from train.core import sb3_train

    cfg = tiny_sac_recipe(1200)
    ours, _ = sb3_train.train_sb3(cfg, 3, "ACLDBeam-v1")
    monkeypatch.setattr(sb3_train, "_flat_n_step_buffer", lambda cls, venv, kw: kw)
    theirs, _ = sb3_train.train_sb3(cfg, 3, "ACLDBeam-v1")
    assert type(theirs.model.replay_buffer) is NStepReplayBuffer
    a, b = ours.model.policy.state_dict(), theirs.model.policy.state_dict()
    assert a.keys() == b.keys()
    for key in a:
        assert torch.equal(a[key], b[key]), key
    assert ours.model.num_timesteps == theirs.model.num_timesteps == 1200 - 128


@pytest.mark.parametrize("verbose", [0, 1])
def test_a_model_leaves_no_sb3_folder_in_the_temp_dir(verbose, tmp_path, monkeypatch):
    """SB3's default logger makes an empty ``<tmp>/SB3-<date>`` folder per model, quiet or
    not; the package's models log to the console or nowhere, without one."""
    import tempfile

    from train.core.sb3_train import make_model
    from train.vec import make_vec_env

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    monkeypatch.delenv("SB3_LOGDIR", raising=False)
    cfg = tiny_sac_recipe(300)
    venv = make_vec_env(cfg, 0, "ACLDBeam-v1")
    model = make_model(cfg, venv, 0, verbose=verbose)
    model.learn(300)
    venv.close()
    assert not list(tmp_path.glob("SB3-*"))
    kinds = [type(f).__name__ for f in model.logger.output_formats]
    assert kinds == (["HumanOutputFormat"] if verbose else [])  # the console, when verbose
