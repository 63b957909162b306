"""``studies/probes/phase_weights.py``: each rollout's advantages are centred and divided by the
RMS of the last episode's rollouts' standard deviations, so rollouts keep their ratios;
SB3's per-minibatch normalization is off and everything else is the recipe's."""

import numpy as np
import torch
from stable_baselines3.common.buffers import RolloutBuffer

from studies.tests.probe_scripts import load_probe, tiny_model
from tests.train.tiny_sb3 import shrink_ppo
from train.config import load_config

pw = load_probe("phase_weights")


def rollouts(buf, scales, rng):
    """Fill ``buf`` with rewards of the given sizes, one rollout per scale, and return each
    rollout's advantages after the buffer's scaling and before it (SB3's GAE)."""
    after, before = [], []
    for scale in scales:
        buf.reset()
        buf.rewards[:] = scale * rng.standard_normal(buf.rewards.shape)
        buf.values[:] = 0.0
        buf.episode_starts[:] = 0.0
        buf.pos, buf.full = buf.buffer_size, True
        last, dones = torch.zeros(buf.n_envs), np.zeros(buf.n_envs)
        RolloutBuffer.compute_returns_and_advantage(buf, last, dones)  # SB3's own
        before.append(buf.advantages.copy())
        buf.compute_returns_and_advantage(last, dones)
        after.append(buf.advantages.copy())
    return after, before


def test_the_config_is_the_recipe_with_the_buffer_and_without_sb3s_normalization():
    cfg, recipe = pw.config(), load_config("ppo")
    assert cfg.model["rollout_buffer_class"] is pw.PhaseScaledRolloutBuffer
    assert cfg.model["normalize_advantage"] is False
    rest = {
        k: v
        for k, v in cfg.model.items()
        if k not in ("rollout_buffer_class", "normalize_advantage")
    }
    assert rest == recipe.model and cfg.restarts == 1


def test_rollouts_keep_their_ratios_and_unit_size_over_the_window():
    cfg = shrink_ppo(pw.config())
    model, _ = tiny_model(cfg)
    buf = model.rollout_buffer
    assert isinstance(buf, pw.PhaseScaledRolloutBuffer) and not model.normalize_advantage
    rng = np.random.default_rng(0)
    scales = [1.0, 10.0, 1.0, 3.0]
    after, before = rollouts(buf, scales, rng)
    stds = [float(np.std(b)) for b in before]
    for i, (a, b) in enumerate(zip(after, before, strict=True)):
        window = stds[max(0, i + 1 - pw.WINDOW) : i + 1]
        rms = np.sqrt(np.mean(np.square(window)))
        np.testing.assert_allclose(a, (b - b.mean()) / rms, rtol=1e-5, atol=1e-6)
        assert abs(a.mean()) < 1e-5
    # the second rollout, ten times the first's rewards, stays larger than the third, of
    # the first's size: SB3's own normalization would have made all three of unit size
    assert np.std(after[1]) > 1.3 and np.std(after[2]) < 0.5


def test_the_window_is_one_episode_of_rollouts():
    cfg = shrink_ppo(pw.config())
    model, _ = tiny_model(cfg)
    buf = model.rollout_buffer
    rollouts(buf, [1.0] * (pw.WINDOW + 3), np.random.default_rng(1))
    assert len(buf.variances) == pw.WINDOW == 16
    assert pw.WINDOW * 64 >= 1000 > (pw.WINDOW - 1) * 64  # the recipe's 64-step rollouts
