"""SB3VecEnv takes a level id (issue 69): ``SB3VecEnv(n, env_id=ID, **kw)`` is the env of
``gym.make_vec(ID, num_envs=n, **kw)``, step for step on every registered id; a level id
where the count goes, and ``env_id`` beside ``venv``/``config``, are refused in one line."""

import gymnasium as gym
import numpy as np
import pytest

import acld_gym  # noqa: F401  (registers the ids)
from acld_gym.envs.presets import PRESETS, preset
from acld_gym.envs.sb3 import SB3VecEnv

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # v0: "out of date"

N = 8
LAB = "ACLDBeamLab-v1"


def _steps(venv, seed: int, n_steps: int = 5):
    """Observations after a seeded reset and ``n_steps`` steps of fixed random volts, with
    the rewards and dones."""
    venv.seed(seed)
    out = [venv.reset()]
    actions = np.random.default_rng(seed).uniform(-120, 120, (n_steps, venv.num_envs, 1))
    for a in actions.astype(np.float32):
        obs, rew, done, _ = venv.step(a)
        out += [obs, rew, done]
    return out


@pytest.mark.parametrize("env_id", sorted(PRESETS))
def test_env_id_steps_as_make_vec_of_the_id(env_id):
    by_id = SB3VecEnv(N, env_id=env_id)
    adapted = SB3VecEnv(venv=gym.make_vec(env_id, num_envs=N))
    assert by_id.num_envs == N and by_id.venv.config == adapted.venv.config
    assert by_id.venv.config == preset(env_id) and by_id.venv.spec.id == env_id
    assert by_id.observation_space == adapted.observation_space
    for x, y in zip(_steps(by_id, 3), _steps(adapted, 3), strict=True):
        np.testing.assert_array_equal(x, y)
    if env_id != "ACLDBeam-v1":  # the level, not v1's defaults under its name
        assert by_id.venv.config != SB3VecEnv(N).venv.config


def test_env_id_keywords_go_on_top_of_the_level():
    kw = {"load_case": "random", "episode_length": 0.2, "reward_scale": "passive"}
    by_id = SB3VecEnv(2, env_id=LAB, **kw)
    made = gym.make_vec(LAB, num_envs=2, **kw)
    assert by_id.venv.config == made.config == preset(LAB, **kw)
    assert by_id.venv.horizon == 200 and SB3VecEnv(env_id=LAB).num_envs == 1
    assert SB3VecEnv(num_envs=3, env_id=LAB).num_envs == 3  # the count as a keyword too
    with pytest.raises(ValueError, match="^temperature=35.0 is not used"):  # the id's checks
        SB3VecEnv(2, env_id="ACLDBeamHard-v1", temperature=35)


def _one_line(excinfo, *words):
    msg = str(excinfo.value)
    assert "\n" not in msg and all(w in msg for w in words), msg


@pytest.mark.parametrize(
    "call",
    [
        lambda: SB3VecEnv(LAB, num_envs=8),  # the call
        lambda: SB3VecEnv(LAB),
        lambda: SB3VecEnv(num_envs=LAB),
    ],
)
def test_a_level_id_where_the_count_goes_is_refused(call):
    with pytest.raises(ValueError, match="^num_envs: expected the number of sub-envs") as e:
        call()
    _one_line(e, repr(LAB), "env_id=")


def test_env_id_beside_venv_or_config_and_bad_counts_are_refused():
    with pytest.raises(ValueError, match="^pass either env_id= or venv=, not both") as e:
        SB3VecEnv(env_id=LAB, venv=gym.make_vec(LAB, num_envs=2))
    _one_line(e)
    with pytest.raises(ValueError, match="^pass either env_id= or config=, not both") as e:
        SB3VecEnv(2, env_id=LAB, config=preset(LAB))
    _one_line(e, f"preset({LAB!r}")
    with pytest.raises(ValueError, match="^env_id must be one of this package's ids") as e:
        SB3VecEnv(2, env_id="acld_gym:ACLDBeam-v1")
    _one_line(e)
    with pytest.raises(ValueError, match=r"^num_envs: given twice \(3 and num_envs=3\)"):
        SB3VecEnv(3, num_envs=3)
    with pytest.raises(ValueError, match="^num_envs must be"):
        SB3VecEnv(0, env_id=LAB)
    with pytest.raises(ValueError, match="^vectorization_mode: not an env keyword"):
        SB3VecEnv(2, env_id=LAB, vectorization_mode="sync")
