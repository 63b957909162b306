"""No silent conflicts (issue 65, item 4) and the registered episode length (issue 69).

A keyword that a preset's setting would override, an ``env_id`` that is not the env's, a
``max_episode_steps`` longer than the episode, a load the integration cannot resolve and a
``TipLoad`` subclass that overrides evaluation are each refused with one ``ValueError``
naming the argument -- through ``gym.make``, ``gym.make_vec`` (the native vector env) and
the SB3 adapter alike -- and what is accepted is honoured exactly."""

from __future__ import annotations

import dataclasses
import math
import re

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.envs.registration import EnvSpec
from gymnasium.wrappers import TimeLimit
from hypothesis import given, settings
from hypothesis import strategies as st

import acld_gym  # noqa: F401  (registers the ids)
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.config import PARAM_NOISE_MAX, EnvConfig, make_config
from acld_gym.envs.conflicts import LOAD_SUBSTEPS, MESH_TIED, check_resolution
from acld_gym.envs.presets import ENTRY_POINT, PRESETS, episode_steps, kwargs_steps, preset
from acld_gym.envs.sb3 import SB3VecEnv
from acld_gym.envs.vector_env import ACLDBeamVectorEnv
from acld_gym.physics.loads import Harmonic, Pulse, Samples, TipLoad

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # v0: "out of date"

HARD = "ACLDBeamHard-v1"
ALIASING = TipLoad((Harmonic(0.1, 1e15, 0.0, 0.1),))  # the 1e15 rad/s load


def _makers(env_id="ACLDBeam-v1"):
    """The three ways to build an env: gym.make, gym.make_vec and the SB3 adapter (which,
    outside the registry, is given the id's settings as keywords)."""
    return {
        "make": lambda **kw: gym.make(env_id, **kw),
        "make_vec": lambda **kw: gym.make_vec(env_id, num_envs=2, **kw),
        "sb3": lambda **kw: SB3VecEnv(num_envs=2, **{**PRESETS[env_id], **kw}),
    }


def _config(env):
    """The configuration of what a maker built."""
    return env.venv.config if isinstance(env, SB3VecEnv) else env.unwrapped.config


def _one_line(excinfo, *words):
    msg = str(excinfo.value)
    assert "\n" not in msg and all(w in msg for w in words), msg


# --- issue 69: the registry reports the episode length; make adds no limit ----------------
@pytest.mark.parametrize("env_id", list(PRESETS))
def test_the_registry_reports_each_ids_episode_length(env_id):
    assert gym.spec(env_id).max_episode_steps == episode_steps(env_id) == 1000
    assert preset(env_id).max_steps == 1000
    env = gym.make(env_id)
    chain = []
    while isinstance(env, gym.Wrapper):
        chain.append(type(env))
        env = env.env
    assert TimeLimit not in chain  # the env truncates itself: no TimeLimit on top
    venv = gym.make_vec(env_id, num_envs=2).unwrapped
    assert venv.max_episode_steps is None and venv.horizon == 1000
    assert type(venv.spec) is EnvSpec and venv.spec.max_episode_steps == 1000


def test_the_mirrored_step_count_is_envconfigs():
    assert kwargs_steps({}) == EnvConfig().max_steps == 1000
    cfg = EnvConfig(episode_length=0.3, dt=5e-4)
    assert kwargs_steps({"config": cfg, "y_ref": 1.0}) == cfg.max_steps == 600
    assert kwargs_steps({"config": cfg, "dt": 1e-3}) == make_config(cfg, dt=1e-3).max_steps
    assert kwargs_steps({"episode_length": 2.0, "max_episode_steps": 7}) == 7
    assert kwargs_steps({"dt": "fast"}) is None  # not numbers: the env refuses them


def test_a_sync_vector_envs_spec_reports_its_own_episode():
    vec = gym.make_vec("ACLDBeam-v1", num_envs=2, vectorization_mode="sync", episode_length=0.02)
    assert vec.spec.max_episode_steps == 20
    vec.reset(seed=0)
    flags = [vec.step(np.zeros((2, 1), np.float32))[3].all() for _ in range(20)]
    assert flags == [False] * 19 + [True]


def test_made_envs_follow_their_keywords_not_the_registered_count():
    env = gym.make("ACLDBeam-v1", episode_length=1.2)
    assert type(env.unwrapped.spec) is EnvSpec and env.spec.max_episode_steps == 1200
    env.reset(seed=0)
    flags = [env.step(np.zeros(1, np.float32))[3] for _ in range(1200)]
    assert flags == [False] * 1199 + [True]
    again = gym.make(gym.spec("ACLDBeam-v1"), dt=5e-4, episode_length=0.1)
    assert again.spec.max_episode_steps == 200
    assert gym.make_vec("ACLDBeam-v1", num_envs=2, episode_length=0.3).unwrapped.horizon == 300


@pytest.mark.parametrize("env_id", ["ACLDBeam-v1", HARD])
def test_made_episodes_are_the_direct_envs_bit_for_bit(env_id):
    # gym.make and make_vec add nothing to the env of the id's configuration
    cfg = preset(env_id, load_case="random")
    acts = np.random.default_rng(4).uniform(-150, 150, (1003, 2, 1)).astype(np.float32)
    made, direct = gym.make(env_id, load_case="random"), ACLDBeamEnv(config=cfg)
    for env in (made, direct):
        env.reset(seed=3)
    for a in acts[:, 0]:
        one, two = made.step(a), direct.step(a)
        assert one[0].tobytes() == two[0].tobytes() and one[1:4] == two[1:4]
        if one[2] or one[3]:
            assert made.unwrapped.k == 1000 and one[3]
            for env in (made, direct):
                env.reset()
    vec = gym.make_vec(env_id, num_envs=2, load_case="random")
    ref = ACLDBeamVectorEnv(num_envs=2, config=cfg)
    assert vec.reset(seed=8)[0].tobytes() == ref.reset(seed=8)[0].tobytes()
    for a in acts:
        one, two = vec.step(a), ref.step(a)
        for x, y in zip(one[:4], two[:4], strict=True):
            assert x.tobytes() == y.tobytes()


# --- max_episode_steps -------------------------------------------------------------------
@pytest.mark.parametrize("how", ["make", "make_vec", "sb3"])
def test_a_limit_beyond_the_episode_is_refused(how):
    build = _makers()[how]
    with pytest.raises(ValueError, match="^max_episode_steps=5000 exceeds") as e:
        build(max_episode_steps=5000)
    _one_line(e, "1000 steps", "episode_length")
    build(max_episode_steps=1000)  # the episode's own count is fine
    env = build(max_episode_steps=1500, episode_length=2.0)
    if how == "make":
        assert env.spec.max_episode_steps == 1500 and env.unwrapped.max_steps == 2000
    else:
        assert (env.venv if how == "sb3" else env.unwrapped).horizon == 1500


def test_a_shorter_limit_or_none_is_honoured():
    env = gym.make("ACLDBeam-v1", max_episode_steps=7)
    env.reset(seed=0)
    assert [env.step(np.zeros(1, np.float32))[3] for _ in range(7)] == [False] * 6 + [True]
    assert env.spec.max_episode_steps == 7
    env = gym.make("ACLDBeam-v1", max_episode_steps=-1, episode_length=0.01)  # no TimeLimit
    assert env.spec.max_episode_steps == 10
    vec = gym.make_vec("ACLDBeam-v1", num_envs=2, max_episode_steps=7).unwrapped
    assert vec.horizon == 7 and vec.spec.max_episode_steps == 7


# --- env_id ------------------------------------------------------------------------------
@pytest.mark.parametrize("how", ["make", "make_vec", "sb3"])
def test_an_env_id_not_of_this_package_is_refused(how):
    with pytest.raises(ValueError, match="^env_id must be one of this package's ids") as e:
        _makers()[how](env_id="bogus")
    _one_line(e, "'bogus'")
    with pytest.raises(ValueError, match="env_id"):
        EnvConfig(env_id="acld_gym:ACLDBeam-v1")


@pytest.mark.parametrize("how", ["make", "make_vec"])
def test_an_env_id_other_than_the_made_one_is_refused(how):
    with pytest.raises(ValueError, match="^env_id='ACLDBeamLab-v1' is not the id") as e:
        _makers()[how](env_id="ACLDBeamLab-v1")
    _one_line(e, "'ACLDBeam-v1'")
    with pytest.raises(ValueError, match="^env_id='ACLDBeamHard-v1' is not the id"):
        _makers()[how](config=preset(HARD))  # a Hard config made as v1
    made = _makers(HARD)[how](env_id=HARD)
    assert made.unwrapped.config.env_id == HARD


def test_an_id_registered_by_a_user_is_not_one_of_ours_and_keeps_its_env_id():
    gym.register(id="UserBeam-v0", entry_point=ENTRY_POINT, kwargs={"episode_length": 0.05})
    try:
        env = gym.make("UserBeam-v0").unwrapped
        assert env.config.env_id == "ACLDBeam-v1" and env.spec.max_episode_steps == 50
    finally:
        del gym.registry["UserBeam-v0"]


# --- a preset's settings against the user's ------------------------------------------------
@pytest.mark.parametrize("how", ["make", "make_vec", "sb3"])
def test_a_temperature_under_a_preset_range_is_refused(how):
    with pytest.raises(ValueError, match=r"^temperature=35\.0 is not used with temperature_range"):
        _makers(HARD)[how](temperature=35)
    c = _config(_makers(HARD)[how](temperature=35, temperature_range=None))  # honoured
    assert c.temperature == 35.0 and c.temperature_range is None and c.env_id == HARD
    with pytest.raises(ValueError, match="temperature=17"):
        EnvConfig(temperature=17.0, temperature_range=(18.0, 28.0))


@pytest.mark.parametrize("how", ["make", "make_vec", "sb3"])
def test_another_mesh_under_v0s_thesis_bound_is_refused(how):
    v0 = _makers("ACLDBeam-v0")[how]
    tied = r"^mesh='converged' with ACLDBeam-v0's param_noise_max=0\.5"
    with pytest.raises(ValueError, match=tied) as e:
        v0(mesh="converged", param_noise=0.5)
    _one_line(e, "set for mesh='thesis'", f"is {PARAM_NOISE_MAX['converged']}")
    c = _config(v0(mesh="converged", param_noise_max=None, harmonic_modes=None, param_noise=0.1))
    assert c.mesh == "converged" and c.param_noise == 0.1 and c.param_noise_max is None
    with pytest.raises(ValueError, match="param_noise must be at most 0.1"):  # its own bound
        v0(mesh="converged", param_noise_max=None, harmonic_modes=None, param_noise=0.5)


@pytest.mark.parametrize("how", ["make", "make_vec"])
def test_a_config_under_a_presets_settings_is_refused_and_a_matching_one_honoured(how):
    with pytest.raises(ValueError, match=r"^config: ACLDBeamHard-v1's settings would replace") as e:
        _makers(HARD)[how](config=EnvConfig(lam=0.5))
    _one_line(e, "actuator_delay=0", "obs_mode='estimate'", "preset('ACLDBeamHard-v1'")
    cfg = preset(HARD, lam=0.5, load_case=2)
    assert _makers(HARD)[how](config=cfg).unwrapped.config == cfg
    assert _makers(HARD)[how](config=cfg, lam=0.2).unwrapped.config == cfg.replace(lam=0.2)
    # outside the registry, keywords still replace a config's fields (documented)
    assert ACLDBeamEnv(config=cfg, actuator_delay=0).config == cfg.replace(actuator_delay=0)
    # a config that carries the id's settings takes the id it is made as
    lab = _makers("ACLDBeamLab-v1")[how](config=preset(HARD)).unwrapped.config
    assert lab == preset(HARD).replace(env_id="ACLDBeamLab-v1")


#: Values a user might pass beside a preset's settings (each field's own, valid alone).
_USER = {
    "temperature": st.sampled_from([20.0, 24.0, 35.0]),
    "temperature_range": st.sampled_from([None, (18.0, 28.0), (20.0, 30.0)]),
    "mesh": st.sampled_from(["converged", "thesis"]),
    "param_noise_max": st.sampled_from([None, 0.05, 0.5]),
    "harmonic_modes": st.sampled_from([None, (179.0, 1115.0), (177.4, 976.2)]),
    "obs_mode": st.sampled_from(["estimate", "measurement"]),
}


@settings(max_examples=300, deadline=None)
@given(
    env_id=st.sampled_from(list(PRESETS)),
    user=st.fixed_dictionaries({}, optional=_USER),
    config=st.sampled_from([None, "defaults", "own"]),
    name_it=st.booleans(),
)
def test_whatever_is_accepted_is_what_was_asked(env_id, user, config, name_it):
    """gym.make's merge (the id's settings, then the user's keywords) either refuses with a
    ValueError or gives a configuration with every keyword as given, no temperature beside a
    range, no field an id tied to another mesh, and a config= whose fields the id kept."""
    own = {"defaults": EnvConfig(), "own": preset(env_id), None: None}[config]
    fields = PRESETS[env_id]
    if name_it:  # the id's own env_id passed again (any other is refused: see above)
        user = {**user, "env_id": env_id}
    try:
        c = make_config(own, **{**fields, **user})
    except ValueError:
        return
    for key, value in user.items():
        assert getattr(c, key) == value, key
    assert c.temperature_range is None or c.temperature == 20.0
    tied = PRESETS[c.env_id]
    if c.mesh != tied.get("mesh", "converged"):
        assert all(getattr(c, f) != tied[f] for f in MESH_TIED if f in tied)
    if own is not None and "env_id" in fields:
        for f, value in fields.items():  # the env_id is the made id's
            assert f in user or f == "env_id" or getattr(own, f) == value, f


# --- loads the integration cannot resolve --------------------------------------------------
@pytest.mark.parametrize("how", ["make", "make_vec", "sb3"])
def test_a_harmonic_above_the_substep_nyquist_frequency_is_refused(how):
    with pytest.raises(ValueError, match=r"^load_case: Harmonic\.frequency must be below") as e:
        _makers()[how](load_case=ALIASING)
    _one_line(e, "31415.9 rad/s", "dt = 0.001 s")


def test_every_path_to_an_episodes_load_checks_it():
    env = gym.make("ACLDBeam-v1")
    env.reset(seed=0)
    state = env.unwrapped.np_random.bit_generator.state
    for key in ("load", "load_case"):
        with pytest.raises(ValueError, match=rf"^options\['{key}'\]: Harmonic\.frequency"):
            env.reset(seed=1, options={key: ALIASING})
    assert env.unwrapped.np_random.bit_generator.state == state  # refused before seeding
    vec = gym.make_vec("ACLDBeam-v1", num_envs=2)
    with pytest.raises(ValueError, match=r"^options\['load'\]: Harmonic"):
        vec.reset(seed=0, options={"load": ALIASING})
    with pytest.raises(ValueError, match=r"^load_case: Harmonic"):
        vec.unwrapped.load_case = ALIASING
    sb3 = SB3VecEnv(num_envs=2)
    with pytest.raises(ValueError, match=r"^load_case: Harmonic"):
        sb3.set_attr("load_case", ALIASING)
    assert sb3.venv.load_case == 1


def test_the_limit_follows_dt_and_a_resolvable_load_runs():
    fast = TipLoad((Harmonic(0.05, 5e4, 0.0, 0.01),))  # above 1 kHz's limit, below 2 kHz's
    with pytest.raises(ValueError, match="31415.9"):
        gym.make("ACLDBeam-v1", load_case=fast)
    env = gym.make("ACLDBeam-v1", load_case=fast, dt=5e-4, episode_length=0.02)
    env.reset(seed=0)
    ys = [env.step(np.zeros(1, np.float32))[4]["tip_deflection"] for _ in range(40)]
    assert np.all(np.isfinite(ys)) and np.abs(ys).max() < 1e-6  # far above every mode: tiny


@settings(max_examples=200, deadline=None)
@given(
    dt=st.floats(1e-4, 1e-2),
    ratio=st.floats(0.5, 2.0),
)
def test_a_harmonic_is_accepted_exactly_below_the_substep_nyquist_frequency(dt, ratio):
    nyquist = math.pi * LOAD_SUBSTEPS / dt
    load = TipLoad((Harmonic(1.0, ratio * nyquist, 0.0, 1.0),))
    if ratio < 1.0:
        assert check_resolution(load, dt) is load
    else:
        with pytest.raises(ValueError, match="Nyquist"):
            check_resolution(load, dt)


@pytest.mark.parametrize(
    "load, words",
    [
        (TipLoad((Pulse(5e-5, 2e-5, 100.0),)), ("Pulse.duration", "0.0001 s")),
        (TipLoad((Harmonic(1.0, 100.0, 0.0, 2e-5),)), ("Harmonic.duration", "0.0001 s")),
        (TipLoad((Samples(0.0, 1e-5, np.ones(50)),)), ("Samples.step", "0.0001 s")),
    ],
)
def test_components_shorter_than_a_substep_are_refused(load, words):
    with pytest.raises(ValueError, match=r"^load_case: ") as e:
        ACLDBeamVectorEnv(num_envs=2, load_case=load)
    _one_line(e, *words)
    EnvConfig(load_case=load, dt=1e-4)  # a sub-step of 1e-5 s resolves each


def test_random_load_targets_must_stay_below_the_limit():
    with pytest.raises(ValueError, match=r"^harmonic_modes must be below 29919\.9 rad/s"):
        gym.make("ACLDBeam-v1", harmonic_modes=(179.0, 1e6))
    EnvConfig(harmonic_modes=(179.0, 2.9e4))


def test_a_tip_load_subclass_that_overrides_evaluation_is_refused_everywhere():
    class Silent(TipLoad):
        def __call__(self, t):
            return 0.0 * np.asarray(t, dtype=float)

    load = Silent((Pulse(0.0, 1e-3, 1.0),))
    for build in _makers().values():
        with pytest.raises(ValueError, match=r"^load_case: a TipLoad subclass .* __call__"):
            build(load_case=load)
    env = gym.make("ACLDBeam-v1")
    with pytest.raises(ValueError, match=re.escape("options['load']: a TipLoad subclass")):
        env.reset(options={"load": load})


def test_sb3_set_attr_refuses_every_setting_fixed_at_construction():
    sb3 = SB3VecEnv(num_envs=2)
    before = sb3.venv.config
    for name in [f.name for f in dataclasses.fields(EnvConfig) if f.name != "load_case"] + [
        "max_episode_steps",
        "harmonic_modes",
        "horizon",
    ]:
        with pytest.raises(ValueError, match=rf"^SB3VecEnv: {name} is fixed at construction"):
            sb3.set_attr(name, 5000)
    assert sb3.venv.config is before and sb3.venv.max_episode_steps is None
    sb3.set_attr("load_case", 2)  # the one setting meant to change
    assert sb3.venv.load_case == 2
