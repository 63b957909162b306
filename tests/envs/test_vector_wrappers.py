"""acld_gym.wrappers.vector: each vector wrapper gives, sub-env by sub-env, what the
single-env wrapper gives a single env with the same seed (observations, rewards, flags and
info, over autoresets that follow terminations and truncations), through ``gym.make_vec``
(native, sync, async) and through the SB3 adapter; bad arguments get one line naming them."""

from __future__ import annotations

import functools

import gymnasium as gym
import numpy as np
import pytest
from stepping import drive

import acld_gym  # noqa: F401  (registers the ids)
from acld_gym import wrappers
from acld_gym.envs.batch import COMPILED_STEP
from acld_gym.envs.sb3 import SB3VecEnv
from acld_gym.envs.vector_env import ACLDBeamVectorEnv
from acld_gym.wrappers import vector

N = 3
STEPS = 120  # 50-step episodes (0.05 s): every sub-env ends at least twice
ENV_KW = {"episode_length": 0.05, "load_case": "random", "deflection_limit": 1e-3}
_RNG = np.random.default_rng(3)
#: Per id: the env's keywords and the wrappers, innermost first (name, keywords).
CASES = {
    "ACLDBeam-v1": (
        {"reward_scale": "passive", "observe_reward_scale": True},
        [
            ("UnitAction", {"headroom": 3.0}),
            ("ObserveModes", {"modes": 2}),
            ("WhitenObservation", {"transform": _RNG.normal(size=(5, 5)), "passthrough": 1}),
        ],
    ),
    "ACLDBeamHard-v1": (  # obs_mode="measurement": 8 tip samples and the last command
        {},
        [
            ("UnitAction", {"headroom": 2.0}),
            ("WhitenObservation", {"transform": _RNG.normal(size=(9, 9))}),
        ],
    ),
}
ACTIONS = np.random.default_rng(0).uniform(-1.2, 1.2, (STEPS, N, 1)).astype(np.float32)
#: Native and single envs take the same compiled step: bit-equal. The numpy step of a batch
#: may round differently (tests/envs/test_vector_env.py's tolerance).
EXACT = COMPILED_STEP


def _wrap(env, stack, module):
    for name, kw in stack:
        env = getattr(module, name)(env, **kw)
    return env


def _single_envs(env_id):
    kw, stack = CASES[env_id]
    return [_wrap(gym.make(env_id, **ENV_KW, **kw), stack, wrappers) for _ in range(N)]


def _stack(rows):
    return tuple(np.array(x) for x in zip(*rows, strict=True))


def _single_next_step(env_id, seed):
    """N wrapped single envs driven as a NEXT_STEP vector env drives its sub-envs."""
    steps = drive(_single_envs(env_id), ACTIONS, seed)
    obs, _, _, _, infos = steps[0]
    return [(obs, infos), *steps[1:]]


def _same(got, want, exact=True, rtol=0.0):
    """Equal bit for bit (``exact`` and no ``rtol``), else within ``rtol`` (the numpy
    step's 1e-6 where ``exact`` is False)."""
    if exact and not rtol:
        np.testing.assert_array_equal(got, want)
    else:
        np.testing.assert_allclose(got, want, rtol=rtol or 1e-6, atol=0 if exact else 1e-6)


def _native_rtol(env_id) -> float:
    """The native env's reward scale c (``reward_scale="passive"``) is computed for the
    batch's loads at once and may differ from the single env's in the last bits (seen:
    1 ulp); the rewards divided by it and ``info["reward_scale"]`` then agree to 1e-12,
    the observation (log c in float32) exactly. 0 (bit for bit) otherwise."""
    return 1e-12 if "reward_scale" in CASES[env_id][0] else 0.0


def _check_info(vinfo, sinfos, exact, rtol=0.0):
    keys = set(sinfos[0])
    assert {k for k in vinfo if not k.startswith("_")} == keys
    for key in keys:
        want = [d[key] for d in sinfos]
        if key == "terminated_by":
            assert list(vinfo[key]) == want
        else:
            got = np.stack(vinfo[key]).astype(np.float64)
            _same(got, np.array(want, np.float64), exact, rtol)
        assert vinfo["_" + key].all()


def _check_vector(envs, env_id, exact, rtol=0.0):
    want = _single_next_step(env_id, seed=11)
    obs, info = envs.reset(seed=11)
    _same(obs, want[0][0], exact)
    _check_info(info, want[0][1], exact, rtol)
    assert envs.observation_space.contains(obs)
    ends = np.zeros(2, int)
    for a, (so, sr, ste, stru, sinfo) in zip(ACTIONS, want[1:], strict=True):
        obs, r, te, tr, info = envs.step(a)
        _same(obs, so, exact)
        _same(r, sr, exact, rtol)
        np.testing.assert_array_equal(te, ste)
        np.testing.assert_array_equal(tr, stru)
        _check_info(info, sinfo, exact, rtol)
        ends += [te.sum(), tr.sum()]
    assert ends.min() >= 1  # both kinds of end, each followed by an autoreset
    envs.close()


@pytest.mark.parametrize("env_id", list(CASES))
def test_native_vector_wrappers_step_like_the_single_wrappers(env_id):
    kw, stack = CASES[env_id]
    envs = _wrap(gym.make_vec(env_id, num_envs=N, **ENV_KW, **kw), stack, vector)
    assert type(envs.unwrapped) is ACLDBeamVectorEnv
    single = _single_envs(env_id)[0]
    assert envs.single_observation_space == single.observation_space
    assert envs.single_action_space == single.action_space
    assert envs.action_space.shape == (N, 1)
    _check_vector(envs, env_id, EXACT, _native_rtol(env_id))


@pytest.mark.parametrize("env_id", list(CASES))
def test_sync_vector_wrappers_step_like_the_single_wrappers(env_id):
    """On a sync vector env of single envs the wrapped env is the single envs in the
    single-env wrappers, bit for bit (the shared maps work row by row)."""
    kw, stack = CASES[env_id]
    envs = _wrap(
        gym.make_vec(env_id, num_envs=N, vectorization_mode="sync", **ENV_KW, **kw), stack, vector
    )
    _check_vector(envs, env_id, exact=True)


def test_async_vector_wrappers_find_the_sub_envs_configuration():
    """ObserveModes reads the sub-envs' configuration through ``get_attr`` on an async
    vector env; the wrapped env steps like the single wrappers."""
    env_id = "ACLDBeam-v1"
    kw, stack = CASES[env_id]
    envs = gym.make_vec(env_id, num_envs=N, vectorization_mode="async", **ENV_KW, **kw)
    try:
        envs = _wrap(envs, stack, vector)
        assert envs.single_observation_space.shape == (6,)
        _check_vector(envs, env_id, exact=True)
    finally:
        envs.close()


def _single_same_step(env_id, seed):
    """N wrapped single envs driven as SB3 drives its sub-envs: reset at once after an
    end, the final observation kept."""
    envs = _single_envs(env_id)
    first = np.array([e.reset(seed=seed + i)[0] for i, e in enumerate(envs)])
    steps = []
    for a in ACTIONS:
        rows = []
        for i, e in enumerate(envs):
            o, r, te, tr, info = e.step(a[i])
            info = dict(info)
            if te or tr:
                info["terminal_observation"] = o
                info["TimeLimit.truncated"] = bool(tr and not te)
                o, _ = e.reset()
            rows.append((o, r, te or tr, info))
        o, r, d, info = zip(*rows, strict=True)
        steps.append((np.array(o), np.array(r, np.float32), np.array(d), list(info)))
    return first, steps


def _sb3_adapters(env_id):
    kw, stack = CASES[env_id]
    built = SB3VecEnv(
        num_envs=N,
        **{**gym.spec(env_id).kwargs, **ENV_KW, **kw},
        wrappers=[functools.partial(getattr(vector, name), **w) for name, w in stack],
    )
    adapted = SB3VecEnv(venv=_wrap(gym.make_vec(env_id, num_envs=N, **ENV_KW, **kw), stack, vector))
    return built, adapted


@pytest.mark.parametrize("env_id", list(CASES))
def test_sb3_adapter_takes_the_vector_wrappers(env_id):
    """``SB3VecEnv(..., wrappers=[...])`` and ``SB3VecEnv(venv=wrapped make_vec env)``: the
    wrapped spaces, and per sub-env the single wrapped env's steps under SB3's same-step
    autoreset (the reset observation and ``terminal_observation`` wrapped as well)."""
    first, want = _single_same_step(env_id, seed=11)
    single = _single_envs(env_id)[0]
    rtol = _native_rtol(env_id)
    for venv in _sb3_adapters(env_id):
        assert venv.observation_space == single.observation_space
        assert venv.action_space == single.action_space
        assert venv.env_is_wrapped(vector.UnitAction) == [True] * N
        assert venv.env_is_wrapped(gym.Wrapper) == [False] * N
        venv.seed(11)
        _same(venv.reset(), first, EXACT)
        ends = 0
        for a, (so, sr, sd, sinfos) in zip(ACTIONS, want, strict=True):
            venv.step_async(a)
            obs, r, d, infos = venv.step_wait()
            _same(obs, so, EXACT)
            _same(r, sr, EXACT, rtol)
            np.testing.assert_array_equal(d, sd)
            for got, sinfo in zip(infos, sinfos, strict=True):
                assert set(got) == set(sinfo)
                for key, value in sinfo.items():
                    if key in ("terminated_by", "TimeLimit.truncated", "clipped"):
                        assert got[key] == value, key
                    else:
                        g, v = np.asarray(got[key], float), np.asarray(value, float)
                        _same(g, v, EXACT, rtol)
            ends += d.sum()
        assert ends >= 2 * N
        venv.close()


def test_sb3_adapter_without_observation_wrappers_resets_to_the_raw_observation():
    """Only an action wrapper: the reset rows are the native env's own observation."""
    venv = SB3VecEnv(num_envs=2, episode_length=0.005, wrappers=[vector.UnitAction])
    plain = SB3VecEnv(num_envs=2, episode_length=0.005)
    venv.seed(2)
    plain.seed(2)
    _same(venv.reset(), plain.reset())
    for k in range(12):
        a = np.full((2, 1), 0.1 * (k % 3), np.float32)
        o1, r1, d1, _ = venv.step(a)
        o2, r2, d2, _ = plain.step(120.0 * a.astype(np.float64))
        _same(o1, o2)
        _same(r1, r2)
        _same(d1, d2)


def _one_line(excinfo):
    assert "\n" not in str(excinfo.value)


@pytest.mark.parametrize(
    "make, match",
    [
        (lambda: vector.UnitAction(gym.make("ACLDBeam-v1")), r"^env: the vector UnitAction wraps"),
        (
            lambda: vector.ObserveModes(gym.make("ACLDBeam-v1")),
            r"^env: the vector ObserveModes wraps",
        ),
        (lambda: vector.UnitAction(gym.make_vec("ACLDBeam-v1", 2), headroom=0.5), "^headroom"),
        (lambda: vector.ObserveModes(gym.make_vec("ACLDBeamHard-v1", 2)), "obs_mode='estimate'"),
        (lambda: vector.ObserveModes(gym.make_vec("ACLDBeam-v1", 2), 5), r"^modes must be in"),
        (lambda: vector.ObserveModes(gym.make_vec("ACLDBeam-v1", 2), 2.0), "^modes must be an"),
        (
            lambda: vector.ObserveModes(vector.ObserveModes(gym.make_vec("ACLDBeam-v1", 2), 3)),
            r"^env: ObserveModes needs the ACLDBeam env's own observation of 9 entries, got "
            r"shape \(7,\)",
        ),
        (
            lambda: vector.WhitenObservation(gym.make_vec("ACLDBeam-v1", 2), np.eye(8)),
            r"^transform must be a finite \(9, 9\)",
        ),
        (
            lambda: vector.WhitenObservation(gym.make_vec("ACLDBeam-v1", 2), np.eye(9), 9),
            r"^passthrough must be an integer in \[0, 9\)",
        ),
    ],
)
def test_vector_wrappers_refuse_bad_arguments_in_one_line(make, match):
    with pytest.raises(ValueError, match=match) as excinfo:
        make()
    _one_line(excinfo)


def test_sync_vector_env_of_differing_sub_envs_is_refused_by_observe_modes():
    envs = gym.vector.SyncVectorEnv(
        [lambda: gym.make("ACLDBeam-v1"), lambda: gym.make("ACLDBeam-v1", sensor_noise=0.0)]
    )
    with pytest.raises(ValueError, match="^env: the sub-envs' configurations differ") as exc:
        vector.ObserveModes(envs)
    _one_line(exc)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"wrappers": [wrappers.UnitAction]}, r"^wrappers: UnitAction is a single-env wrapper"),
        (
            {"wrappers": [functools.partial(wrappers.ObserveModes, modes=2)]},
            r"^wrappers: ObserveModes is a single-env wrapper",
        ),
        ({"wrappers": vector.UnitAction}, r"^wrappers: expected a list of vector wrappers"),
        ({"wrappers": ["UnitAction"]}, r"^wrappers: expected callables"),
        ({"wrappers": [lambda e: e.unwrapped.nom]}, r"^wrappers: <lambda> returned"),
        (
            {"venv": gym.make_vec("ACLDBeam-v1", 2, vectorization_mode="sync")},
            r"^venv: expected an ACLDBeamVectorEnv",
        ),
        (
            {"venv": gym.wrappers.vector.RecordEpisodeStatistics(gym.make_vec("ACLDBeam-v1", 2))},
            r"^venv: SB3VecEnv takes action, observation and reward wrappers, got "
            r"RecordEpisodeStatistics",
        ),
    ],
)
def test_sb3_adapter_refuses_bad_wrappers_in_one_line(kwargs, match):
    with pytest.raises(ValueError, match=match) as excinfo:
        SB3VecEnv(num_envs=2, **kwargs)
    _one_line(excinfo)


def test_sb3_adapter_passes_gymnasiums_own_wrappers():
    """Gymnasium's vector action wrappers compose with the package's: RescaleAction to
    [0, 1] over UnitAction is the same env as UnitAction with a = 2 b - 1."""
    outer = SB3VecEnv(
        num_envs=2,
        episode_length=0.02,
        wrappers=[
            vector.UnitAction,
            functools.partial(
                gym.wrappers.vector.RescaleAction,
                min_action=np.zeros(1, np.float32),
                max_action=np.ones(1, np.float32),
            ),
        ],
    )
    inner = SB3VecEnv(num_envs=2, episode_length=0.02, wrappers=[vector.UnitAction])
    outer.seed(5)
    inner.seed(5)
    _same(outer.reset(), inner.reset())
    b = np.random.default_rng(1).uniform(0, 1, (30, 2, 1)).astype(np.float32)
    for x in b:
        o1, r1, *_ = outer.step(x)
        o2, r2, *_ = inner.step(2.0 * x - 1.0)
        np.testing.assert_allclose(o1, o2, rtol=1e-5, atol=1e-6)
