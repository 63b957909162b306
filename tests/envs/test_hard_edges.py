"""Issue 14, the environment's hard edges: each test failed on the code before the fix.

Episode length through every entry point, NaN and unstable plants, memory limits,
strict action parsing, validation before seeding, stepping before reset, and
parameters that are not physical.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import acld_gym  # noqa: F401  (registers the ids)
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.config import MAX_EPISODE_STEPS
from acld_gym.envs.sb3 import SB3VecEnv
from acld_gym.envs.vector_env import ACLDBeamVectorEnv
from acld_gym.physics.model import build_model


def _steps_until_done(env, action) -> int:
    env.reset(seed=0)
    n = 0
    while True:
        *_, terminated, truncated, _ = env.step(action)
        n += 1
        if terminated or truncated:
            return n


# --- 1. episode length follows episode_length and dt ------------------------------
@pytest.mark.parametrize(
    "kw, steps",
    [
        ({}, 1000),
        ({"episode_length": 1.5}, 1500),
        ({"dt": 5e-4, "episode_length": 0.2}, 400),
        ({"max_episode_steps": 300}, 300),
        ({"max_episode_steps": None}, 1000),
    ],
)
def test_gym_make_follows_episode_length(kw, steps):
    env = gym.make("ACLDBeam-v1", **kw)
    assert _steps_until_done(env, np.zeros(1, np.float32)) == steps
    assert env.spec.max_episode_steps == steps


def test_make_vec_and_sb3_follow_episode_length():
    venv = gym.make_vec("ACLDBeam-v1", num_envs=2, episode_length=1.2)
    assert venv.spec.max_episode_steps == 1200 and venv.unwrapped.horizon == 1200
    sb3 = SB3VecEnv(num_envs=2, episode_length=0.3)
    sb3.reset()
    n = 0
    while True:
        sb3.step_async(np.zeros((2, 1), np.float32))
        *_, done, _ = sb3.step_wait()
        n += 1
        if done.all():
            break
    assert n == 300


# --- 3. no silent NaN, bounded randomization and reward ------------------------------
@pytest.mark.parametrize(
    "kw, name",
    [
        ({"param_noise": 20}, "param_noise"),
        ({"param_noise": 0.2}, "param_noise"),
        ({"mesh": "thesis", "param_noise": 0.1}, "param_noise"),
        ({"y_ref": 1e-300}, "y_ref"),
        ({"sensor_noise": 1e300}, "sensor_noise"),
        ({"lam": float("inf")}, "lam"),
        ({"deflection_limit": 10.0}, "deflection_limit"),
    ],
)
def test_out_of_range_arguments_name_themselves(kw, name):
    with pytest.raises(ValueError, match=name):
        ACLDBeamEnv(**kw)


def test_randomized_plants_at_the_bound_stay_finite():
    env = ACLDBeamEnv(load_case="random", param_noise=0.1)
    for seed in range(5):
        env.reset(seed=seed)
        for _ in range(200):
            obs, reward, terminated, _, info = env.step(np.array([120.0], np.float32))
            assert np.isfinite(obs).all() and np.isfinite(reward)
            assert info["terminated_by"] is None


def test_vector_env_terminates_on_non_finite_state():
    venv = ACLDBeamVectorEnv(num_envs=3, load_case=1)
    venv.reset(seed=0)
    venv.x[1, 0] = np.nan
    _, _, terminated, _, info = venv.step(np.zeros((3, 1)))
    assert terminated.tolist() == [False, True, False]
    assert info["terminated_by"].tolist() == [None, "non_finite_state", None]


# --- 4. memory is bounded -----------------------------------------------------------
@pytest.mark.parametrize(
    "kw, name",
    [
        ({"episode_length": 1e4}, "episode_length"),
        ({"dt": 1e-7}, "dt"),
        ({"episode_length": 2 * MAX_EPISODE_STEPS * 1e-4, "dt": 1e-4}, "episode_length"),
    ],
)
def test_episode_size_is_bounded(kw, name):
    with pytest.raises(ValueError, match=name):
        ACLDBeamEnv(**kw)


def test_vector_env_tables_are_bounded():
    with pytest.raises(ValueError, match="num_envs"):
        ACLDBeamVectorEnv(num_envs=8192, episode_length=1.0)


# --- 6. actions -----------------------------------------------------------------
@pytest.mark.parametrize(
    "action",
    [
        np.zeros((2, 2)),
        np.zeros((1, 4)),
        np.zeros(3),
        np.zeros((4, 1), complex),
        np.full((4, 1), True),
        np.array(["1"] * 4),
    ],
)
def test_vector_env_takes_n_or_n_by_1_real_actions_only(action):
    venv = ACLDBeamVectorEnv(num_envs=4, load_case=1)
    venv.reset(seed=0)
    venv.step(np.zeros(4))
    venv.step(np.zeros((4, 1)))
    before = venv.batch.Z.copy()
    with pytest.raises(ValueError, match="action"):
        venv.step(action)
    assert np.array_equal(venv.batch.Z, before)


# --- 7. smaller edges -------------------------------------------------------------
def test_rejected_reset_does_not_reseed():
    env = ACLDBeamEnv(load_case="random")
    env.reset(seed=1)
    state = env.np_random.bit_generator.state
    with pytest.raises(ValueError, match="options"):
        env.reset(seed=99, options={"load_cas": 1})
    with pytest.raises(ValueError, match="load_case"):
        env.reset(seed=99, options={"load_case": 9})
    assert env.np_random.bit_generator.state == state
    with pytest.raises(ValueError, match="seed"):
        env.reset(seed=-1)


def test_sb3_set_attr_validates_now():
    sb3 = SB3VecEnv(num_envs=2)
    with pytest.raises(ValueError, match="load_case"):
        sb3.set_attr("load_case", 9)
    with pytest.raises(ValueError, match="fixed"):
        sb3.set_attr("dt", 1e-4)
    sb3.set_attr("load_case", "random")
    assert sb3.get_attr("load_case") == ["random", "random"]


def test_any_real_scalar_type_is_accepted():
    a = ACLDBeamEnv(
        dt=np.float32(1e-3),
        y_ref=np.float64(1e-3),
        lam=np.float16(0.01),
        episode_length=np.int64(1),
    )
    assert a.dt == pytest.approx(1e-3) and a.max_steps == 1000


def test_step_before_reset_raises():
    with pytest.raises(RuntimeError, match="reset"):
        ACLDBeamEnv().step(np.zeros(1, np.float32))
    with pytest.raises(RuntimeError, match="reset"):
        ACLDBeamEnv().step([0.0])  # the numpy path too
    with pytest.raises(RuntimeError, match="reset"):
        ACLDBeamVectorEnv(num_envs=2).step(np.zeros(2))
    with pytest.raises(RuntimeError, match="reset"):
        SB3VecEnv(num_envs=2).step_async(np.zeros((2, 1)))


@pytest.mark.parametrize("seed", [1.5, "3", [1, 2], -4])
def test_vector_reset_seed_is_checked(seed):
    with pytest.raises(ValueError, match="seed"):
        ACLDBeamVectorEnv(num_envs=3).reset(seed=seed)


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"shear_correction": 1e308}, "shear_correction"),
        ({"beam_density": 1e-300}, "beam_density"),
        ({"d31": -1.0}, "d31"),
    ],
)
def test_unphysical_parameters_are_rejected_by_name(kw, name):
    with pytest.raises(ValueError, match=name):
        build_model(**kw)
