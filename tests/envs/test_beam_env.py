"""ACLDBeam-v1 (and v0): Gymnasium conventions, semantics, bad input, determinism,
pickling."""

import pickle
import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import acld_gym  # noqa: F401  (registers ACLDBeam-v1 and -v0)
from acld_gym.design.nominal import nominal_design
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.physics.loads import random_load

# Warnings we chose: the action box is in volts (+/-120, the design card's choice;
# train with RescaleAction) and observations are unbounded by nature.
CHOSEN = ("symmetric and normalized", "minimum value is -infinity", "maximum value is infinity")


@pytest.mark.parametrize("mode", ["rgb_array", None])
def test_passes_gymnasium_check_env_with_only_chosen_warnings(mode):
    env = gym.make("ACLDBeam-v1", render_mode=mode)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped, skip_render_check=False)
    others = [str(w.message) for w in caught if not any(c in str(w.message) for c in CHOSEN)]
    assert others == []


def test_passes_sb3_check_env():
    from stable_baselines3.common.env_checker import check_env as sb3_check

    sb3_check(ACLDBeamEnv(), warn=False)


def test_make_without_import_registers_itself():
    code = (
        "import gymnasium as gym; e = gym.make('acld_gym:ACLDBeam-v1'); "
        "print(e.spec.max_episode_steps)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "1000"


def _rollout(env, seed, actions):
    obs, _ = env.reset(seed=seed)
    traj = [obs]
    for a in actions:
        obs, r, term, trunc, info = env.step(a)
        traj.append(np.r_[obs, r, info["tip_deflection"]])
    return np.concatenate(traj)


def test_same_seed_same_trajectory_random_loads_and_noise():
    env = ACLDBeamEnv(load_case="random", param_noise=0.05)
    acts = [np.array([v], np.float32) for v in np.linspace(-150, 150, 60)]
    a = _rollout(env, 123, acts)
    b = _rollout(env, 123, acts)
    c = _rollout(env, 124, acts)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_pickle_round_trip_continues_identically():
    env = ACLDBeamEnv(load_case="random")
    env.reset(seed=5)
    for _ in range(10):
        env.step(np.array([30.0], np.float32))
    clone = pickle.loads(pickle.dumps(env))
    for _ in range(20):
        o1, r1, *_ = env.step(np.array([-40.0], np.float32))
        o2, r2, *_ = clone.step(np.array([-40.0], np.float32))
        np.testing.assert_array_equal(o1, o2)
        assert r1 == r2


def test_episode_truncates_after_one_second_never_terminates_for_time():
    env = ACLDBeamEnv(load_case=1)
    env.reset(seed=0)
    for k in range(1000):
        _, _, term, trunc, info = env.step(np.zeros(1, np.float32))
        assert not term
        assert trunc == (k == 999)
    assert info["time"] == pytest.approx(1.0)


def test_physical_limit_terminates():
    env = ACLDBeamEnv(load_case=3, deflection_limit=1e-3)  # case 3 reaches ~5 mm passively
    env.reset(seed=0)
    for _ in range(1000):
        *_, term, trunc, info = env.step(np.zeros(1, np.float32))
        if term:
            break
    assert term and abs(info["tip_deflection"]) > 1e-3


def test_passive_episode_matches_exact_simulation():
    # The env's plant (ZOH + load sub-steps) against the exact continuous simulator.
    from acld_gym.design.simulate import simulate
    from acld_gym.physics.loads import thesis_load

    env = ACLDBeamEnv(load_case=2, sensor_noise=0.0)
    env.reset(seed=0)
    ys = [env.step(np.zeros(1, np.float32))[4]["tip_deflection"] for _ in range(300)]
    d = nominal_design().design
    ref = simulate(
        *d.plant, d.observer("thesis"), d.passive, thesis_load(2), t_end=0.3, v_max=None, dt=1e-3
    )
    grid = np.isclose(ref.t / 1e-3, np.round(ref.t / 1e-3), atol=1e-6)
    np.testing.assert_allclose(ys, ref.y[grid][1:], atol=1e-9 * 1e-3 + 1e-12, rtol=1e-6)


def test_clipping_is_reported_and_applied():
    env = ACLDBeamEnv()
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.array([500.0], np.float32))
    assert info["clipped"] and info["voltage"] == 120.0 and info["requested_voltage"] == 500.0
    _, _, _, _, info = env.step(np.array([50.0], np.float32))
    assert not info["clipped"] and info["voltage"] == 50.0


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_action_raises_and_leaves_state(bad):
    env = ACLDBeamEnv()
    env.reset(seed=0)
    env.step(np.array([10.0], np.float32))
    x, k, xhat = env.x.copy(), env.k, env.xhat.copy()
    state = env.np_random.bit_generator.state
    with pytest.raises(ValueError, match="action"):
        env.step(np.array([bad], np.float32))
    np.testing.assert_array_equal(env.x, x)
    np.testing.assert_array_equal(env.xhat, xhat)
    assert env.k == k and env.np_random.bit_generator.state == state


def test_wrong_action_shape_raises():
    env = ACLDBeamEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(np.array([1.0, 2.0]))


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"load_case": 4}, "load_case"),
        ({"observer": "perfect"}, "observer"),
        ({"obs_mode": "pixels"}, "obs_mode"),
        ({"dt": 0}, "dt"),
        ({"dt": float("nan")}, "dt"),
        ({"y_ref": -1.0}, "y_ref"),
        ({"lam": -0.1}, "lam"),
        ({"param_noise": -0.1}, "param_noise"),
        ({"sensor_noise": -1e-6}, "sensor_noise"),
        ({"episode_length": 0.0}, "episode_length"),
        ({"render_mode": "ansi"}, "render_mode"),
        ({"deflection_limit": 0}, "deflection_limit"),
    ],
)
def test_bad_kwargs_name_the_argument(kw, name):
    with pytest.raises(ValueError, match=name):
        ACLDBeamEnv(**kw)


def test_reset_options_select_load_case_and_reject_unknown_keys():
    env = ACLDBeamEnv(load_case=1)
    env.reset(seed=0, options={"load_case": 3})
    assert env.load.components[0].frequency == 179.0
    with pytest.raises(ValueError, match="load_case"):
        env.reset(options={"load_case": 7})
    with pytest.raises(ValueError, match="options"):
        env.reset(options={"foo": 1})
    with pytest.raises(ValueError, match="load"):
        env.reset(options={"load": 1})
    with pytest.raises(ValueError, match="not both"):
        env.reset(options={"load": env.load, "load_case": 1})


@pytest.mark.parametrize(
    "mesh, mode, n, order",
    [
        ("converged", "estimate", 9, 8),
        ("converged", "measurement", 9, 8),
        ("converged", "full", 36, 8),
        ("thesis", "estimate", 7, 6),
        ("thesis", "full", 38, 6),
    ],
)
def test_observation_modes(mesh, mode, n, order):
    # Converged plant: 18 Ritz coordinates (36 states), 8-state design model (modes 1-4);
    # thesis mesh: 19 DOFs (38 states), 6-state design model (modes 1-3).
    env = ACLDBeamEnv(obs_mode=mode, mesh=mesh)
    obs, info = env.reset(seed=0)
    assert obs.shape == (n,) and obs.dtype == np.float32
    for _ in range(5):
        obs, *_, info = env.step(np.zeros(1, np.float32))
    assert env.observation_space.contains(obs)
    assert {"tip_deflection", "voltage", "tip_load", "time", "xr_true"} <= set(info)
    assert info["xr_true"].shape == (order,)


def test_v0_is_the_thesis_configuration_in_the_canonical_basis():
    from acld_gym.envs.config import EnvConfig
    from acld_gym.envs.presets import preset

    with pytest.warns(DeprecationWarning, match="out of date"):
        env = gym.make("ACLDBeam-v0")
        noisy = gym.make("ACLDBeam-v0", param_noise=0.5).unwrapped
    e = env.unwrapped
    assert type(e) is ACLDBeamEnv and e.mesh == "thesis" and e.nom.basis == "modal"
    assert e.observation_space.shape == (7,) and e.harmonic_modes == (179.0, 1115.0)
    assert e.nom.design.reduced.order == 6 and e.param_noise == 0.0
    assert e.nom.plant.Ad.shape == (38, 38)
    # one configuration of the one class: its three settings are ordinary fields
    assert (
        e.config
        == preset("ACLDBeam-v0")
        == EnvConfig(
            mesh="thesis",
            harmonic_modes=(179.0, 1115.0),
            model_std=0.0,
            param_noise_max=0.5,
            env_id="ACLDBeam-v0",
        )
    )
    assert e.observation_fingerprint["env_id"] == "ACLDBeam-v0"
    assert (
        ACLDBeamEnv(config=preset("ACLDBeam-v0")).observation_fingerprint["env_id"] == "ACLDBeam-v0"
    )
    assert noisy.param_noise == 0.5
    with pytest.raises(ValueError, match="param_noise"):
        gym.make("ACLDBeam-v1", mesh="thesis", param_noise=0.5)


def test_v1_random_loads_aim_at_the_plants_own_modes():
    conv, thes = ACLDBeamEnv(mesh="converged"), ACLDBeamEnv(mesh="thesis")
    # Damped modes 1-2: converged 177.37 / 976.18 rad/s, thesis mesh 178.64 / 1115.40.
    assert conv.harmonic_modes == pytest.approx((177.37, 976.18), rel=1e-4)
    assert thes.harmonic_modes == pytest.approx((178.64, 1115.40), rel=1e-4)
    for seed in range(40):
        conv.reset(seed=seed, options={"load_case": "random"})
        for w in conv.load.harmonic_frequencies:
            assert any(0.95 * m <= w <= 1.05 * m for m in conv.harmonic_modes)


def test_estimate_scales_are_order_one_for_case1():
    env = ACLDBeamEnv(load_case=1, sensor_noise=0.0)
    env.reset(seed=0)
    peaks = np.zeros(env.observation_space.shape[0])
    for _ in range(200):
        obs, *_ = env.step(np.zeros(1, np.float32))
        peaks = np.maximum(peaks, np.abs(obs))
    # Scales are the true reduced states' passive case-1 peaks: modes 1-3 and the tip
    # come out of order one; mode 4 (5330 rad/s, above the 3142 rad/s Nyquist frequency)
    # is seen by the 1 kHz Kalman filter at about a tenth of its true amplitude.
    assert np.all(peaks < 5.0)
    assert np.all(peaks[[0, 1, 2, 3, 4, 5, 8]] > 0.2) and np.all(peaks[6:8] > 0.02)


def test_reward_formula():
    env = ACLDBeamEnv(y_ref=2e-3, lam=0.5)
    env.reset(seed=0)
    _, r, _, _, info = env.step(np.array([60.0], np.float32))
    expected = -((info["tip_deflection"] / 2e-3) ** 2) - 0.5 * (60.0 / 120.0) ** 2
    assert r == pytest.approx(expected, rel=1e-12)


def test_random_loads_are_bounded_and_seeded():
    rng = np.random.default_rng(0)
    t = np.linspace(0, 1, 20001)
    for _ in range(50):
        f = random_load(rng, 1.0, 1e-4)(t)
        assert np.all(np.abs(f) < 3.0)
    a = random_load(np.random.default_rng(3), 1.0, 1e-4)
    b = random_load(np.random.default_rng(3), 1.0, 1e-4)
    assert a == b


def test_param_noise_randomizes_plant_not_observer():
    env = ACLDBeamEnv(param_noise=0.1)
    env.reset(seed=1)
    ad1 = env.episode_plant.Ad.copy()
    env.reset(seed=2)
    assert not np.allclose(env.episode_plant.Ad, ad1)
    assert env.batch.observer is env.nom.kalman  # the observer keeps the nominal design
    assert env.episode_plant is not env.nom.plant


def test_render_rgb_array():
    env = ACLDBeamEnv(render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.array([20.0], np.float32))
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8
    assert frame.std() > 0
    env.close()
    env.close()


def test_works_in_sb3_subprocvecenv():
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import SubprocVecEnv

    venv = make_vec_env(
        ACLDBeamEnv,
        n_envs=2,
        seed=0,
        vec_env_cls=SubprocVecEnv,
        vec_env_kwargs={"start_method": "fork"},
        env_kwargs={"load_case": "random"},
    )
    try:
        obs = venv.reset()
        assert obs.shape == (2, 9)
        for _ in range(5):
            obs, rew, done, infos = venv.step(np.array([[10.0], [-10.0]], np.float32))
        assert obs.shape == (2, 9) and rew.shape == (2,) and not done.any()
        assert all("tip_deflection" in i for i in infos)
    finally:
        venv.close()
