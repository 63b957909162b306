"""ACLDBeamVectorEnv (native batched ACLDBeam-v1) and its SB3 adapter."""

import pickle

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode
from stepping import single_rollout

import acld_gym  # noqa: F401  (registers ACLDBeam-v1)
from acld_gym.envs.sb3 import SB3VecEnv
from acld_gym.envs.step import INFO_KEYS
from acld_gym.envs.vector_env import ACLDBeamVectorEnv

N = 3
SHORT = 0.05  # 50-step episodes: 120 steps cross two autoresets


def _vector_rollout(kw, seed, acts):
    env = ACLDBeamVectorEnv(num_envs=N, **kw)
    o, info = env.reset(seed=seed)
    steps = [(o, None, None, None, info)]
    for a in acts:
        steps.append(env.step(a))
    return steps


@pytest.mark.parametrize(
    "kw",
    [
        dict(load_case="random"),
        dict(load_case="random", obs_mode="measurement", lam=0.1),
        dict(load_case=1, observer="thesis"),
        dict(load_case=2, obs_mode="full"),
        dict(load_case=3, sensor_noise=0.0),
        dict(load_case="random", param_noise=0.05, obs_mode="full"),
        dict(load_case="random", mesh="thesis", param_noise=0.05),
    ],
)
def test_equal_trajectories_with_single_env_across_autoresets(kw):
    kw = dict(kw, episode_length=SHORT)
    acts = np.random.default_rng(0).uniform(-150, 150, (120, N, 1)).astype(np.float32)
    single = single_rollout(kw, N, acts, seed=11)
    vec = _vector_rollout(kw, 11, acts)
    n_done = 0
    for (so, sr, ste, str_, sinfo), (vo, vr, vte, vtr, vinfo) in zip(single, vec, strict=True):
        np.testing.assert_allclose(vo, so, rtol=1e-6, atol=1e-6)
        if sr is not None:
            np.testing.assert_allclose(vr, sr, rtol=1e-9, atol=1e-12)
            np.testing.assert_array_equal(vte, ste)
            np.testing.assert_array_equal(vtr, str_)
            n_done += int(vtr.sum())
        for key in INFO_KEYS:
            want = np.array([d[key] for d in sinfo])
            if key == "terminated_by":
                np.testing.assert_array_equal(vinfo[key], want)
            else:
                np.testing.assert_allclose(vinfo[key], want, rtol=1e-9, atol=1e-15, err_msg=key)
            assert vinfo["_" + key].all()
    assert n_done == 2 * N


def test_next_step_autoreset_and_truncation():
    env = ACLDBeamVectorEnv(num_envs=2, episode_length=SHORT, load_case=1, sensor_noise=0.0)
    assert env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    obs0, _ = env.reset(seed=0)
    a = np.zeros((2, 1), np.float32)
    for k in range(1, 51):
        obs, r, te, tr, info = env.step(a)
        assert not te.any()
        assert tr.all() == (k == 50)
    obs, r, te, tr, info = env.step(np.full((2, 1), 100.0, np.float32))  # ignored
    np.testing.assert_array_equal(obs, obs0)
    np.testing.assert_array_equal(r, 0.0)
    assert not te.any() and not tr.any()
    np.testing.assert_array_equal(info["time"], 0.0)
    np.testing.assert_array_equal(info["voltage"], 0.0)


def test_max_episode_steps_truncates_and_termination():
    env = ACLDBeamVectorEnv(num_envs=2, max_episode_steps=5)
    env.reset(seed=0)
    for _ in range(4):
        assert not env.step(np.zeros((2, 1)))[3].any()
    assert env.step(np.zeros((2, 1)))[3].all()
    env = ACLDBeamVectorEnv(num_envs=2, deflection_limit=1e-4)
    env.reset(seed=0)
    te = np.zeros(2, bool)
    for _ in range(20):
        _, _, te, tr, _ = env.step(np.zeros((2, 1)))
        if te.any():
            break
    assert te.all()


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_bad_action_raises_and_leaves_state(bad):
    env = ACLDBeamVectorEnv(num_envs=3, load_case="random")
    env.reset(seed=1)
    env.step(np.full((3, 1), 10.0))
    before = pickle.dumps(env)
    with pytest.raises(ValueError, match="finite"):
        env.step(np.array([[1.0], [bad], [2.0]]))
    with pytest.raises(ValueError, match="voltage"):
        env.step(np.zeros((2, 1)))
    a = np.array([[5.0], [-300.0], [0.0]])
    o1, r1, *_ = env.step(a)
    o2, r2, *_, info = pickle.loads(before).step(a)
    np.testing.assert_array_equal(o1, o2)
    np.testing.assert_array_equal(r1, r2)
    np.testing.assert_array_equal(info["clipped"], [False, True, False])
    np.testing.assert_array_equal(info["voltage"], [5.0, -120.0, 0.0])


def test_same_validation_errors_as_single_env():
    for kw in (
        dict(load_case=4),
        dict(dt=-1.0),
        dict(obs_mode="x"),
        dict(sensor_noise=-1.0),
        dict(episode_length=1e-4),
        dict(render_mode="human"),
    ):
        with pytest.raises(ValueError):
            ACLDBeamVectorEnv(num_envs=2, **kw)
    with pytest.raises(ValueError):
        ACLDBeamVectorEnv(num_envs=0)
    env = ACLDBeamVectorEnv(num_envs=2)
    with pytest.raises(ValueError, match="options"):
        env.reset(options={"foo": 1})


def test_make_vec_returns_native_class():
    env = gym.make_vec("ACLDBeam-v1", num_envs=4, load_case="random")
    assert type(env.unwrapped) is ACLDBeamVectorEnv
    assert env.num_envs == 4 and env.unwrapped.horizon == 1000
    obs, info = env.reset(seed=3)
    assert obs.shape == (4, 9) and obs.dtype == np.float32
    assert env.observation_space.contains(obs)
    obs, r, te, tr, info = env.step(env.action_space.sample())
    assert r.shape == (4,) and info["tip_deflection"].shape == (4,)
    sync = gym.make_vec("ACLDBeam-v1", num_envs=2, vectorization_mode="sync")
    assert not isinstance(sync.unwrapped, ACLDBeamVectorEnv)


def test_seed_reproducible_and_pickle_continues():
    a = ACLDBeamVectorEnv(num_envs=4, load_case="random", param_noise=0.02)
    b = ACLDBeamVectorEnv(num_envs=4, load_case="random", param_noise=0.02)
    np.testing.assert_array_equal(a.reset(seed=5)[0], b.reset(seed=5)[0])
    for _ in range(10):
        a.step(np.full((4, 1), 20.0))
    clone = pickle.loads(pickle.dumps(a))
    for _ in range(10):
        act = np.full((4, 1), -30.0)
        np.testing.assert_array_equal(a.step(act)[0], clone.step(act)[0])


def test_render_rgb_array_of_env_zero():
    env = ACLDBeamVectorEnv(num_envs=2, render_mode="rgb_array")
    env.reset(seed=0)
    env.step(np.zeros((2, 1)))
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8
    env.close()


def test_sb3_adapter_same_step_autoreset():
    venv = SB3VecEnv(num_envs=2, episode_length=SHORT, load_case="random")
    venv.seed(4)
    obs = venv.reset()
    assert obs.shape == (2, 9)
    for k in range(1, 51):
        venv.step_async(np.zeros((2, 1), np.float32))
        obs, rew, dones, infos = venv.step_wait()
        assert dones.all() == (k == 50)
    assert all(i["TimeLimit.truncated"] for i in infos)
    assert infos[0]["terminal_observation"].shape == (9,)
    # the returned observation is the new episode's first one
    np.testing.assert_array_equal(venv.venv.batch.k, 0)
    assert venv.get_attr("dt") == [1e-3, 1e-3]
    assert venv.env_is_wrapped(gym.Wrapper) == [False, False]
    venv.close()


def test_sb3_adapter_infos_are_the_vector_envs_per_sub_env():
    """``infos[i][key]`` is the vector env's ``info[key][i]`` as a Python value (numpy
    scalars converted as ``item()`` does; the true state's row as an array), over an
    episode's end; with ``reward_scale`` its value too."""
    kw = {"episode_length": SHORT, "load_case": "random", "reward_scale": "passive"}
    venv, ref = SB3VecEnv(num_envs=N, **kw), ACLDBeamVectorEnv(num_envs=N, **kw)
    venv.seed(7)
    venv.reset()
    ref.reset(seed=7)
    acts = np.random.default_rng(0).uniform(-150, 150, (50, N, 1)).astype(np.float32)
    for k, a in enumerate(acts):
        venv.step_async(a)
        infos = venv.step_wait()[3]
        info = ref.step(a)[4]
        keys = (*INFO_KEYS, "reward_scale")
        for i in range(N):
            extra = {"terminal_observation", "TimeLimit.truncated"} if k == len(acts) - 1 else set()
            assert set(infos[i]) == set(keys) | extra
            for key in keys:
                want = info[key][i]
                got = infos[i][key]
                if key == "xr_true":
                    assert isinstance(got, np.ndarray)
                    np.testing.assert_array_equal(got, want)
                else:
                    assert not isinstance(got, np.generic), key
                    assert got == (want.item() if isinstance(want, np.generic) else want)
                    assert type(got) is type(want.item() if isinstance(want, np.generic) else want)
    assert all(i["TimeLimit.truncated"] for i in infos)


def test_sb3_ppo_learns_and_evaluates():
    from stable_baselines3 import PPO
    from stable_baselines3.common.evaluation import evaluate_policy
    from stable_baselines3.common.vec_env import VecMonitor

    venv = SB3VecEnv(num_envs=4, episode_length=0.02, load_case="random")
    model = PPO("MlpPolicy", venv, n_steps=32, batch_size=64, n_epochs=1, seed=0, device="cpu")
    model.learn(total_timesteps=256)
    mean, std = evaluate_policy(model, VecMonitor(venv), n_eval_episodes=4)
    assert np.isfinite(mean) and np.isfinite(std)


def test_sb3_adapter_seed_groups_share_their_episodes():
    """``seed_group=2``: sub-envs 2i and 2i+1 get seed + i, so under the same actions they
    run the same random loads and sensor noise, over an episode's end too; sub-env 2i is
    the default adapter's sub-env i (seed + i). A group size that does not divide the
    sub-envs is refused, naming it."""
    kw = {"episode_length": SHORT, "load_case": "random"}
    paired, plain = SB3VecEnv(num_envs=4, seed_group=2, **kw), SB3VecEnv(num_envs=2, **kw)
    assert paired.seed(11) == [11, 11, 12, 12] and plain.seed(11) == [11, 12]
    op, oq = paired.reset(), plain.reset()
    np.testing.assert_array_equal(op[0::2], op[1::2])
    np.testing.assert_array_equal(op[0::2], oq)
    assert not np.array_equal(op[0], op[2])
    acts = np.random.default_rng(0).uniform(-150, 150, (120, 2, 1)).astype(np.float32)
    for a in acts:  # 120 steps: over the end of the 50-step episodes
        op, rp, dp, ip = paired.step(np.repeat(a, 2, axis=0))
        oq, rq, dq, iq = plain.step(a)
        np.testing.assert_array_equal(op[0::2], op[1::2])
        np.testing.assert_array_equal(op[0::2], oq)
        np.testing.assert_array_equal(rp[0::2], rq)
    for bad, msg in ((3, "divisor"), (0, "seed_group must be"), (True, "seed_group must be")):
        with pytest.raises(ValueError, match=msg):
            SB3VecEnv(num_envs=4, seed_group=bad)
