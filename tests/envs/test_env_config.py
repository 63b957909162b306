"""One configuration (issue 21): ``EnvConfig`` is validated once, every env class takes it (as
``config=`` or as keywords), and every registered id is a configuration of the one class."""

from __future__ import annotations

import dataclasses
import warnings

import gymnasium as gym
import numpy as np
import pytest

import acld_gym  # noqa: F401  (registers the ids)
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.config import EnvConfig, config_table, make_config
from acld_gym.envs.presets import PRESETS, preset
from acld_gym.envs.sb3 import SB3VecEnv
from acld_gym.envs.vector_env import ACLDBeamVectorEnv
from acld_gym.physics.loads import Pulse, TipLoad


@pytest.mark.parametrize(
    "field, value",
    [
        ("load_case", 4),
        ("load_case", "1"),
        ("load_case", True),
        ("mesh", "coarse"),
        ("dt", 0.0),
        ("dt", 1.0),
        ("episode_length", -1.0),
        ("observer", "perfect"),
        ("obs_mode", "pixels"),
        ("sensor_noise", -1e-9),
        ("y_ref", 0.0),
        ("lam", float("nan")),
        ("param_noise", 0.2),
        ("deflection_limit", 5.0),
        ("harmonic_modes", (1.0,)),
        ("harmonic_modes", (100.0, -3.0)),
        ("model_std", -1.0),
        ("param_noise_max", 0.0),
        ("env_id", ""),
    ],
)
def test_every_field_is_validated_by_name(field, value):
    with pytest.raises(ValueError, match=field):
        EnvConfig(**{field: value})


def test_config_is_frozen_and_replace_validates_again():
    c = EnvConfig()
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.dt = 2e-3
    assert c.replace(dt=5e-4).max_steps == 2000
    with pytest.raises(ValueError, match="dt"):
        c.replace(dt=-1.0)
    with pytest.raises(TypeError, match="unexpected keyword"):
        c.replace(foo=1)
    with pytest.raises(TypeError, match="config must be an EnvConfig"):
        make_config({"dt": 1e-3})
    # numbers of any real type are stored as floats; a numpy integer case as an int
    c = EnvConfig(dt=np.float32(1e-3), load_case=np.int64(2), harmonic_modes=[170, 900])
    assert type(c.dt) is float and c.load_case == 2 and type(c.load_case) is int
    assert c.harmonic_modes == (170.0, 900.0)


def test_every_field_is_documented_with_unit_and_meaning():
    table = config_table()
    doc = ACLDBeamEnv.__doc__
    for f in dataclasses.fields(EnvConfig):
        assert f.metadata["unit"] and f.metadata["doc"], f.name
        assert f"`{f.name}`" in table and f"``{f.name}``" in doc, f.name


def test_envs_take_the_config_or_its_fields_as_keywords():
    cfg = EnvConfig(load_case=2, obs_mode="measurement", episode_length=0.05)
    single = ACLDBeamEnv(config=cfg)
    assert single.config is cfg and single.obs_mode == "measurement" and single.max_steps == 50
    # keywords replace the config's fields
    assert ACLDBeamEnv(config=cfg, lam=0.5).config == cfg.replace(lam=0.5)
    vec = ACLDBeamVectorEnv(num_envs=2, config=cfg)
    assert vec.config is cfg and vec.horizon == 50
    sb3 = SB3VecEnv(num_envs=2, config=cfg, lam=0.5)
    assert sb3.venv.config == cfg.replace(lam=0.5)
    made = gym.make("ACLDBeam-v1", config=cfg).unwrapped
    assert made.config == cfg
    made = gym.make_vec("ACLDBeam-v1", num_envs=2, config=cfg, y_ref=2e-3).unwrapped
    assert made.config == cfg.replace(y_ref=2e-3)
    with pytest.raises(TypeError, match="unexpected keyword"):
        ACLDBeamEnv(load_cas=1)
    with pytest.raises(ValueError, match="either venv= or"):
        SB3VecEnv(venv=vec, config=cfg)


def test_every_registered_id_is_a_configuration_of_the_one_class():
    for env_id, fields in PRESETS.items():
        spec = gym.spec(env_id)
        assert spec.entry_point == "acld_gym.envs.beam_env:ACLDBeamEnv"
        assert spec.vector_entry_point == "acld_gym.envs.vector_env:ACLDBeamVectorEnv"
        assert spec.kwargs == fields
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # v0: "out of date"
            env = gym.make(env_id).unwrapped
        assert type(env) is ACLDBeamEnv and env.config == preset(env_id)
        assert env.config.env_id == env_id


def test_v0_equals_v1_on_the_thesis_mesh_with_its_three_settings():
    # issue 19/21: nothing else distinguishes v0 -- the same episode, bit for bit
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        v0 = gym.make("ACLDBeam-v0", load_case="random").unwrapped
    same = ACLDBeamEnv(
        load_case="random",
        mesh="thesis",
        harmonic_modes=(179.0, 1115.0),
        model_std=0.0,
        param_noise_max=0.5,
    )
    acts = np.random.default_rng(3).uniform(-150, 150, (300, 1)).astype(np.float32)
    for env in (v0, same):
        env.reset(seed=9)
    for a in acts:
        o0, r0, *_ = v0.step(a)
        o1, r1, *_ = same.step(a)
        assert o0.tobytes() == o1.tobytes() and r0 == r1


def test_load_case_accepts_a_tip_load_everywhere():
    pulse = TipLoad((Pulse(0.01, 2e-3, 0.5),))
    assert EnvConfig(load_case=pulse).load_case is pulse
    env = gym.make("ACLDBeam-v1", load_case=pulse).unwrapped
    env.reset(seed=0)
    assert env.load is pulse
    vec = gym.make_vec("ACLDBeam-v1", num_envs=2, load_case=pulse).unwrapped
    vec.reset(seed=0)
    assert vec.loads == [pulse, pulse]
    sb3 = SB3VecEnv(num_envs=2)
    sb3.set_attr("load_case", pulse)
    sb3.reset()
    assert sb3.venv.loads == [pulse, pulse]


@pytest.mark.parametrize("env_id", ["ACLDBeamLab-v1", "ACLDBeamHard-v1"])
def test_presets_pass_check_env_and_work_through_make_and_make_vec(env_id):
    from gymnasium.utils.env_checker import check_env

    env = gym.make(env_id, render_mode="rgb_array")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the volts action box (README, chosen warnings)
        check_env(env.unwrapped, skip_render_check=False)
    vec = gym.make_vec(env_id, num_envs=3)
    assert type(vec.unwrapped) is ACLDBeamVectorEnv and vec.unwrapped.config == preset(env_id)
    obs, _ = vec.reset(seed=0)
    obs, r, *_ = vec.step(np.full((3, 1), 50.0, np.float32))
    assert obs.shape == (3, 9) and np.isfinite(r).all()


def test_preset_values_are_their_sources():
    from acld_gym.envs.presets import HARD, LAB
    from acld_gym.physics.actuator import REFERENCE_SLEW_RATE

    assert LAB["slew_rate"] == pytest.approx(REFERENCE_SLEW_RATE, rel=1e-3)
    assert LAB["sensor_noise"] == pytest.approx(6.23167e-5 * 10e-3 / np.sqrt(12), rel=1e-2)
    assert LAB["actuator_delay"] == 1 and HARD["obs_mode"] == "measurement"
    assert {k: HARD[k] for k in LAB} == LAB  # the hard level is the lab rig and more
