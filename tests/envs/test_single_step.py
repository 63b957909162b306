"""The single env as the N = 1 case of the batched step (acld_gym/envs/single_step.py): its
state attributes are views of env 0 of the batch, its reset info has the step's keys, and
its fast path is the compiled step (scaled where the reward is) or none."""

from __future__ import annotations

import numpy as np
import pytest

from acld_gym.envs.batch import COMPILED_STEP
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.single_step import fast_step, no_fast_path, not_reset
from acld_gym.envs.step import INFO_KEYS


@pytest.mark.parametrize("scale", [None, "passive"])
def test_reset_info_has_the_step_keys_at_rest(scale):
    env = ACLDBeamEnv(load_case=1, reward_scale=scale)
    _, info = env.reset(seed=0)
    _, _, _, _, step_info = env.step(np.array([10.0], np.float32))
    extra = {"reward_scale"} if scale else set()
    assert list(info) == list(INFO_KEYS) + sorted(extra)
    assert set(step_info) == set(INFO_KEYS) | extra
    assert info["voltage"] == info["tip_deflection"] == info["time"] == 0.0
    assert info["tip_load"] == 1.0 and info["terminated_by"] is None  # case 1: 1 N at t = 0
    assert info["xr_true"].shape == (env.nom.design.reduced.order,) and not info["xr_true"].any()
    if scale:
        assert info["reward_scale"] == step_info["reward_scale"] > 0


def test_the_state_attributes_are_views_of_the_batch():
    env = ACLDBeamEnv(load_case=2)
    env.reset(seed=1)
    for _ in range(5):
        env.step(np.array([-30.0], np.float32))
    b = env.batch
    assert env.k == int(b.k[0]) == 5
    assert np.shares_memory(env.x, b.Z) and np.shares_memory(env.xhat, b.Z)
    assert env.v == float(b.Z[0, b.layout.voltage]) == -30.0
    assert env.y_meas == float(b.Z[0, b.layout.y_meas])
    assert env.episode_plant is b.plants[0]


def test_the_fast_path_is_the_compiled_step_or_none():
    with pytest.raises(RuntimeError, match="reset"):
        ACLDBeamEnv().step(np.array([0.0], np.float32))
    with pytest.raises(RuntimeError, match="reset"):
        not_reset(None)
    numpy_env = ACLDBeamEnv()
    numpy_env.compiled_step = False
    numpy_env.reset(seed=0)
    assert fast_step(numpy_env.batch) is no_fast_path and no_fast_path(0.0) is None
    if COMPILED_STEP:
        env = ACLDBeamEnv()
        env.reset(seed=0)
        assert fast_step(env.batch) == env.batch.core.step_one
        scaled = ACLDBeamEnv(reward_scale="passive")
        scaled.reset(seed=0)
        step = fast_step(scaled.batch)
        assert step != scaled.batch.core.step_one  # the reward scale applied on top
        reward = step(np.array([5.0], np.float32))[1]
        assert np.isfinite(reward) and reward < 0
