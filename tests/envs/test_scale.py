"""The per-episode reward scale (``reward_scale``, ``observe_reward_scale``;
acld_gym.envs.scale). Closed form: the passive policy's scaled return is exactly -T on every
load and every plant option that does not act at zero voltage, in the single and the vector
env, compiled or not; the reward terms in ``info`` stay unscaled."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import acld_gym  # noqa: F401
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.config import EnvConfig

SCALED = {"reward_scale": "passive", "observe_reward_scale": True}


def _passive_episode(env, seed):
    obs, info = env.reset(seed=seed)
    c0 = info["reward_scale"]
    total, rewards, done = 0.0, [], False
    while not done:
        obs, r, te, tr, info = env.step(np.zeros(1, np.float32))
        total += r
        rewards.append(
            (r, info["reward_deflection"] + info["reward_voltage"], info["reward_scale"], obs[-1])
        )
        done = te or tr
    return total, c0, rewards, len(rewards)


@pytest.mark.parametrize("case", [1, 3, "random"])
@pytest.mark.parametrize("compiled", [True, False])
def test_passive_return_is_minus_steps(case, compiled):
    env = ACLDBeamEnv(load_case=case, **SCALED)
    env.compiled_step = compiled
    total, c0, rewards, T = _passive_episode(env, seed=4)
    assert T == env.max_steps and env.batch.compiled == (compiled and env.batch.compiled)
    assert total == pytest.approx(-T, rel=1e-9)
    for r, unscaled, c, log_c in rewards:  # terms unscaled, the reward divided by c
        assert c == c0 and r == pytest.approx(unscaled / c, rel=1e-12)
        assert log_c == np.float32(np.log(c))


@pytest.mark.parametrize(
    "changes",
    [
        {"temperature": 35.0},  # another plant: its own c
        {"amplifier_bandwidth": 500.0, "actuator_delay": 2},  # not acting at zero voltage
        {"mesh": "thesis", "episode_length": 0.3},
    ],
)
def test_passive_return_with_plant_options(changes):
    env = ACLDBeamEnv(load_case="random", **SCALED, **changes)
    total, _, _, T = _passive_episode(env, seed=11)
    assert total == pytest.approx(-T, rel=1e-9)


def test_scale_depends_on_load_and_temperature():
    c = {}
    for case in (1, 2, 3):
        _, c[case], _, _ = _passive_episode(ACLDBeamEnv(load_case=case, **SCALED), 0)
    assert len({round(v, 12) for v in c.values()}) == 3  # one scale per load
    _, warm, _, _ = _passive_episode(ACLDBeamEnv(load_case=1, temperature=35.0, **SCALED), 0)
    assert warm != pytest.approx(c[1], rel=1e-3)


def test_vector_env_scales_each_sub_env_and_its_next_episode():
    n = 4
    venv = gym.make_vec("ACLDBeam-v1", num_envs=n, load_case="random", episode_length=0.2, **SCALED)
    obs, info = venv.reset(seed=7)
    assert obs.shape == (n, 10) and np.allclose(obs[:, -1], np.log(info["reward_scale"]))
    first = info["reward_scale"].copy()
    total = np.zeros(n)
    for _ in range(200):
        obs, r, te, tr, info = venv.step(np.zeros((n, 1), np.float32))
        total += r
    assert tr.all() and np.allclose(total, -200, rtol=1e-9)
    assert np.array_equal(info["reward_scale"], first)  # the ended episodes' own scale
    obs, r, te, tr, info = venv.step(np.zeros((n, 1), np.float32))  # NEXT_STEP autoreset
    assert np.all(r == 0) and not np.allclose(info["reward_scale"], first)
    assert np.allclose(obs[:, -1], np.log(info["reward_scale"]))
    # the same draws as the single env: sub-env 0 of seed 7 is the single env of seed 7
    _, c0, _, _ = _passive_episode(ACLDBeamEnv(load_case="random", episode_length=0.2, **SCALED), 7)
    assert c0 == pytest.approx(first[0], rel=1e-12)  # same load; batched round-off


def test_off_by_default_and_unchanged():
    plain = ACLDBeamEnv(load_case=1)
    obs, info = plain.reset(seed=0)
    assert "reward_scale" not in info and obs.shape == (9,)
    scaled = ACLDBeamEnv(load_case=1, reward_scale="passive")  # scaled, not observed
    obs2, info2 = scaled.reset(seed=0)
    assert np.array_equal(obs, obs2) and "reward_scale" in info2
    a = np.array([30.0], np.float32)
    o1, r1, *_ = plain.step(a)
    o2, r2, _, _, i2 = scaled.step(a)
    assert np.array_equal(o1, o2) and r2 == pytest.approx(r1 / i2["reward_scale"], rel=1e-12)


def test_check_env_with_the_options():
    check_env(
        ACLDBeamEnv(load_case="random", episode_length=0.05, **SCALED), skip_render_check=True
    )


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"reward_scale": "episode"}, "reward_scale must be one of"),
        ({"reward_scale": True}, "reward_scale must be one of"),
        ({"observe_reward_scale": True}, "observe_reward_scale=True needs a reward_scale"),
        ({"reward_scale": "passive", "observe_reward_scale": "yes"}, "observe_reward_scale must"),
    ],
)
def test_bad_options_name_the_field(kwargs, match):
    with pytest.raises(ValueError, match=match):
        EnvConfig(**kwargs)


# --- reward_scale="lqr": c is LQR's own cost --------------------------------------------------


def _policy_episode(env, policy, seed):
    """The scaled return and the unscaled step costs of ``policy`` on one episode."""
    obs, info = env.reset(seed=seed)
    total, cost, done = 0.0, [], False
    while not done:
        action, _ = policy.predict(obs)
        obs, r, te, tr, info = env.step(action)
        total += r
        cost.append(-(info["reward_deflection"] + info["reward_voltage"]))
        done = te or tr
    return total, info["reward_scale"], np.asarray(cost)


@pytest.mark.parametrize(
    "case, changes",
    [
        (1, {}),
        (3, {}),
        ("random", {"actuator_delay": 1, "amplifier_bandwidth": 2000.0}),  # the env's own chain
        ("random", {"temperature": 35.0, "observer": "thesis"}),
    ],
)
def test_lqr_return_is_minus_steps_without_noise(case, changes):
    """Closed form: c is LQR's mean step cost on the load, so the thesis LQR (the baseline
    policy, run through the env) returns exactly -T on every load and plant option when the
    sensor is noise-free."""
    from baselines.policies import LQRPolicy

    env = ACLDBeamEnv(load_case=case, reward_scale="lqr", sensor_noise=0.0, **changes)
    lqr = LQRPolicy.for_env(env)
    total, c, cost = _policy_episode(env, lqr, seed=5)
    assert total == pytest.approx(-env.max_steps, rel=1e-9)
    assert c == pytest.approx(cost.mean(), rel=1e-9)
    assert (
        np.abs(env.unwrapped.batch.scale_cost([env.unwrapped.batch.loads[0]])[0] - c) <= 1e-12 * c
    )


def test_lqr_scale_against_passive_and_with_sensor_noise():
    """LQR's c is the passive c over LQR's gain on the load (the benchmark's passive / LQR
    ratio: 3.73 on case 1, 1.54 on case 3, with noise); with the default sensor noise LQR's
    scaled return stays within 1 % of -T."""
    from baselines.policies import LQRPolicy

    c = {}
    for scale in ("passive", "lqr"):
        env = ACLDBeamEnv(load_case=1, reward_scale=scale)
        c[scale] = env.reset(seed=0)[1]["reward_scale"]
    assert 3.2 < c["passive"] / c["lqr"] < 3.8
    env = ACLDBeamEnv(load_case=1, reward_scale="lqr")
    total, _, _ = _policy_episode(env, LQRPolicy.for_env(env), seed=3)
    assert total == pytest.approx(-env.max_steps, rel=1e-2)


def test_lqr_scale_vector_env_pickle_and_check_env():
    import pickle

    venv = gym.make_vec(
        "ACLDBeam-v1",
        num_envs=3,
        load_case="random",
        episode_length=0.1,
        reward_scale="lqr",
        observe_reward_scale=True,
    )
    obs, info = venv.reset(seed=2)
    single = [
        ACLDBeamEnv(load_case="random", episode_length=0.1, reward_scale="lqr").reset(seed=2)[1][
            "reward_scale"
        ]
    ]
    assert np.allclose(obs[:, -1], np.log(info["reward_scale"]))
    assert info["reward_scale"][0] == pytest.approx(single[0], rel=1e-9)
    env = ACLDBeamEnv(
        load_case="random", episode_length=0.05, reward_scale="lqr", observe_reward_scale=True
    )
    env.reset(seed=1)
    clone = pickle.loads(pickle.dumps(env))
    a = np.array([40.0], np.float32)
    assert np.array_equal(env.step(a)[0], clone.step(a)[0])
    assert clone.reset(seed=9)[1]["reward_scale"] == env.reset(seed=9)[1]["reward_scale"]
    check_env(
        ACLDBeamEnv(load_case="random", episode_length=0.05, reward_scale="lqr"),
        skip_render_check=True,
    )
