"""``studies/probes/paired_minibatches.py``: the rollout's samples are dealt in a random order of
antithetic pairs, so every minibatch holds whole pairs (sub-envs 2i and 2i + 1 at the same
step), every sample once per epoch; an odd count is named."""

import numpy as np
import pytest

from studies.tests.probe_scripts import load_probe, tiny_model
from tests.train.tiny_sb3 import shrink_ppo

pm = load_probe("paired_minibatches")


def test_the_order_is_a_permutation_of_whole_pairs():
    n_steps, n_envs = 16, 6
    order = pm.paired_permutation(n_steps, n_envs, np.random.default_rng(0))
    assert sorted(order.tolist()) == list(range(n_steps * n_envs))
    env, step = np.divmod(order.reshape(-1, 2), n_steps)  # swap_and_flatten's index
    assert np.all(env[:, 0] % 2 == 0) and np.all(env[:, 1] == env[:, 0] + 1)
    assert np.all(step[:, 0] == step[:, 1])
    again = pm.paired_permutation(n_steps, n_envs, np.random.default_rng(1))
    assert not np.array_equal(order, again)
    with pytest.raises(ValueError, match="n_envs must be even"):
        pm.paired_permutation(n_steps, 5)


def test_the_buffer_deals_minibatches_of_whole_pairs():
    """A rollout of the recipe's tiny model: each minibatch's samples, in pairs, are the
    two sub-envs of a pair at one step (their stored values tell them apart only by the
    sub-env), and the epoch covers the rollout once."""
    cfg = shrink_ppo(pm.config())
    assert cfg.model["rollout_buffer_class"] is pm.PairedRolloutBuffer and cfg.paired_loads
    model, _ = tiny_model(cfg)
    buf = model.rollout_buffer
    assert isinstance(buf, pm.PairedRolloutBuffer)
    # tag each stored sample with its (sub-env, step) and read the tags back
    tag = np.arange(buf.buffer_size)[:, None] * 1000 + np.arange(buf.n_envs)[None, :]
    buf.values[:] = tag
    buf.full = True
    seen = []
    for batch in buf.get(8):
        v = batch.old_values.numpy().astype(int).reshape(-1, 2)
        step, env = np.divmod(v, 1000)
        assert np.all(step[:, 0] == step[:, 1])
        assert np.all(env[:, 0] % 2 == 0) and np.all(env[:, 1] == env[:, 0] + 1)
        seen += v.ravel().tolist()
    assert sorted(seen) == sorted(tag.ravel().tolist())
    with pytest.raises(ValueError, match="batch_size must be even"):
        next(buf.get(3))
