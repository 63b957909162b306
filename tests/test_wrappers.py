"""acld_gym.wrappers: Gymnasium's checker passes, and the maps are exact (and the same for
the single and the vector wrappers: tests/envs/test_vector_wrappers.py steps them)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from hypothesis import given, settings
from hypothesis import strategies as st

import acld_gym  # noqa: F401
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.step import estimate_slots
from acld_gym.wrappers import ObserveModes, UnitAction, WhitenObservation, whitening
from acld_gym.wrappers.transforms import LinearMap, ModeSlots, UnitMap


def test_unit_action_round_trip_is_exact():
    env = UnitAction(ACLDBeamEnv(load_case=1))
    assert env.action_space == gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
    rng = np.random.default_rng(0)
    a = np.concatenate([rng.uniform(-1, 1, 100_000), [-1.0, 1.0, 0.0, 1e-30, -(2.0**-24)]])
    a = a.astype(np.float32)
    volts = env.action(a)
    assert volts.dtype == np.float64 and np.abs(volts).max() <= 120.0
    assert np.array_equal(env.reverse_action(volts), a)
    assert np.array_equal(volts, 120.0 * a.astype(np.float64))


def test_unit_action_steps_like_volts():
    plain, unit = ACLDBeamEnv(load_case=2), UnitAction(ACLDBeamEnv(load_case=2))
    plain.reset(seed=1)
    unit.reset(seed=1)
    for a in (0.25, -1.0, 0.7):
        a32 = np.array([a], np.float32)
        o1, r1, *_, i1 = plain.step(120.0 * a32.astype(np.float64))  # volts, in float64
        o2, r2, *_, i2 = unit.step(a32)
        assert np.array_equal(o1, o2) and r1 == r2 and i1["voltage"] == i2["voltage"]
    _, _, _, _, info = unit.step(np.array([1.5], np.float32))  # beyond: clipped, reported
    assert info["clipped"] and info["voltage"] == 120.0


def test_unit_action_headroom_round_trip_and_limit():
    env = UnitAction(ACLDBeamEnv(load_case=1), headroom=3)
    assert env.headroom == 3.0 and env.action_space == gym.spaces.Box(-1, 1, (1,), np.float32)
    a = np.random.default_rng(5).uniform(-1, 1, 100_000).astype(np.float32)
    volts = env.action(a)  # 360 V = 45 2^3: exact in float64 both ways
    assert np.array_equal(volts, 360.0 * a.astype(np.float64))
    assert np.array_equal(env.reverse_action(volts), a)
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.array([0.25], np.float32))  # 90 V: inside the limit
    assert info["voltage"] == 90.0 and not info["clipped"]
    _, _, _, _, info = env.step(np.array([-0.5], np.float32))  # -180 V: clipped, reported
    assert info["voltage"] == -120.0 and info["clipped"]
    check_env(
        UnitAction(ACLDBeamEnv(load_case=1, episode_length=0.05), headroom=2.5),
        skip_render_check=True,
    )


@pytest.mark.parametrize("bad", [0.5, 0.0, -2.0, 101.0, float("nan"), True, "3", None])
def test_unit_action_rejects_a_bad_headroom(bad):
    with pytest.raises(ValueError, match=r"headroom must be a number in \[1, 100\]"):
        UnitAction(ACLDBeamEnv(load_case=1), headroom=bad)


def test_observe_modes_keeps_the_first_modes_and_the_tip():
    """Slots of modes 1..m and the tip, exactly; log c passes through; check_env is clean."""
    plain = ACLDBeamEnv(load_case=2)
    env = ObserveModes(ACLDBeamEnv(load_case=2), modes=2)
    assert env.observation_space.shape == (5,)
    z, _ = plain.reset(seed=4)
    u, _ = env.reset(seed=4)
    assert np.array_equal(u, z[[0, 1, 2, 3, 8]])
    for a in (30.0, -120.0):
        z, *_ = plain.step(np.array([a], np.float32))
        u, *_ = env.step(np.array([a], np.float32))
        assert np.array_equal(u, z[[0, 1, 2, 3, 8]])
    scaled = ObserveModes(
        ACLDBeamEnv(load_case="random", reward_scale="passive", observe_reward_scale=True), modes=1
    )
    u, info = scaled.reset(seed=0)
    assert u.shape == (4,) and np.isclose(u[-1], np.log(info["reward_scale"]), rtol=1e-6)
    assert np.array_equal(ObserveModes(ACLDBeamEnv(load_case=1), 4).slots, np.arange(9))
    assert np.array_equal(
        ObserveModes(ACLDBeamEnv(load_case=1, mesh="thesis"), 3).slots, np.arange(7)
    )
    check_env(ObserveModes(ACLDBeamEnv(load_case=1, episode_length=0.05)), skip_render_check=True)


@pytest.mark.parametrize(
    "kwargs, modes, match",
    [
        ({}, 0, r"modes must be in \[1, 4\]"),
        ({}, 5, r"modes must be in \[1, 4\]"),
        ({}, 2.0, "modes must be an integer"),
        ({"obs_mode": "measurement"}, 2, "obs_mode"),
    ],
)
def test_observe_modes_rejects_bad_input(kwargs, modes, match):
    with pytest.raises(ValueError, match=match):
        ObserveModes(ACLDBeamEnv(load_case=1, **kwargs), modes)


def test_observe_modes_rejects_an_observation_already_changed():
    """The slots come from the env's layout, so an observation an inner wrapper reshaped
    is refused by name, not sliced blindly."""
    inner = ObserveModes(ACLDBeamEnv(load_case=1), 3)
    with pytest.raises(
        ValueError,
        match=r"env: ObserveModes needs the ACLDBeam env's own "
        r"observation of 9 entries, got shape \(7,\)",
    ):
        ObserveModes(inner, 2)


def test_estimate_slots_is_the_layout():
    assert estimate_slots(8, 2).tolist() == [0, 1, 2, 3, 8]
    assert estimate_slots(6, 3).tolist() == [0, 1, 2, 3, 4, 5, 6]
    with pytest.raises(ValueError, match="modes must be in"):
        estimate_slots(8, 0)


def test_whiten_observation_keeps_passthrough_and_checks():
    env = ACLDBeamEnv(
        load_case="random", episode_length=0.05, reward_scale="passive", observe_reward_scale=True
    )
    rng = np.random.default_rng(2)
    T = whitening(rng.normal(size=(500, 9)))
    w = WhitenObservation(env, T, passthrough=1)
    check_env(UnitAction(w), skip_render_check=True)
    z, _ = env.reset(seed=3)
    u, _ = w.reset(seed=3)
    assert np.allclose(u[:9], z[:9].astype(np.float64) @ T, rtol=1e-6) and u[9] == z[9]
    with pytest.raises(ValueError, match=r"transform must be a finite \(9, 9\)"):
        WhitenObservation(env, np.eye(10), passthrough=1)
    with pytest.raises(ValueError, match="passthrough must be an integer"):
        WhitenObservation(env, T, passthrough=10)


def test_whitening_makes_the_second_moment_isotropic():
    rng = np.random.default_rng(4)
    A = rng.normal(size=(6, 6))
    u = rng.normal(size=(20000, 6)) @ A
    T = whitening(u, ridge=0.0)
    m = (u @ T).T @ (u @ T) / len(u)
    assert np.allclose(m, np.eye(6), atol=1e-9)
    with pytest.raises(ValueError, match="directions must be a finite"):
        whitening(np.array([np.nan, 1.0])[None])


def test_wrapped_made_envs_keep_a_recreatable_spec():
    """Like Gymnasium's own wrappers, each records its arguments in ``env.spec``, so
    ``gym.make(env.spec)`` rebuilds the same wrapped env (and ``check_env`` runs on a made
    env): the same observations for the same seed and actions."""
    T = np.diag(np.arange(1.0, 6.0))
    made = WhitenObservation(
        ObserveModes(
            UnitAction(gym.make("ACLDBeam-v1", load_case=2, episode_length=0.05), headroom=2.0),
            modes=2,
        ),
        T,
    )
    names = [(w.name, w.kwargs) for w in made.spec.additional_wrappers]
    assert [n for n, _ in names] == ["UnitAction", "ObserveModes", "WhitenObservation"]
    assert names[0][1] == {"headroom": 2.0} and names[1][1] == {"modes": 2}
    again = gym.make(made.spec)
    u, _ = made.reset(seed=3)
    v, _ = again.reset(seed=3)
    assert np.array_equal(u, v)
    for a in (0.3, -1.0):
        u, *_ = made.step(np.array([a], np.float32))
        v, *_ = again.step(np.array([a], np.float32))
        assert np.array_equal(u, v)
    check_env(
        ObserveModes(UnitAction(gym.make("ACLDBeam-v1", episode_length=0.05)), modes=1),
        skip_render_check=True,
    )


@settings(max_examples=60, deadline=None)
@given(
    st.integers(1, 12),
    st.integers(0, 3),
    st.integers(1, 70),
    st.integers(0, 2**32 - 1),
)
def test_the_shared_maps_map_a_batch_row_by_row_exactly(d, passthrough, rows, seed):
    """The maps of the single and the vector wrappers (acld_gym.wrappers.transforms): a row
    of a batch maps bit for bit as the row alone, whatever the batch's size (the linear map
    sums in a fixed order, not by BLAS), so a vector env's sub-env sees what a single
    env sees."""
    rng = np.random.default_rng(seed)
    n = d + passthrough
    T = rng.normal(size=(d, d)) * 10.0 ** rng.integers(-3, 4, size=(d, d))
    z = (rng.normal(size=(rows, n)) * 10.0 ** rng.integers(-6, 3, size=(rows, n))).astype(
        np.float32
    )
    maps = [
        LinearMap((n,), T, passthrough),
        UnitMap(gym.spaces.Box(-120, 120, (1,), np.float32), 1.0 + rng.integers(0, 5)),
    ]
    for f, x in ((maps[0], z), (maps[0].mix, z), (maps[1], z[:, :1])):
        batch = f(x)
        assert batch.shape[:-1] == x.shape[:-1]
        for i in range(rows):
            assert np.array_equal(batch[i], f(x[i]))  # float64 before the cast, too
    want = np.concatenate([z[:, :d].astype(np.float64) @ T, z[:, d:]], axis=1)
    np.testing.assert_allclose(maps[0](z), want.astype(np.float32), rtol=1e-5, atol=1e-30)
    slots = ModeSlots(ACLDBeamEnv(load_case=1).config, (9,), 1 + seed % 4)
    big = rng.normal(size=(rows, 9)).astype(np.float32)
    assert np.array_equal(slots(big), big[:, slots.slots])


def test_single_and_vector_wrappers_share_one_map():
    """One implementation of each transform: the single-env and the vector wrapper hold
    the same map class, built from the same arguments."""
    from acld_gym.wrappers import vector

    T = np.eye(5)
    single = WhitenObservation(ObserveModes(UnitAction(ACLDBeamEnv(), 2.0), 2), T)
    envs = vector.WhitenObservation(
        vector.ObserveModes(vector.UnitAction(gym.make_vec("ACLDBeam-v1", 2), 2.0), 2), T
    )
    s, v = single, envs
    for cls in (LinearMap, ModeSlots, UnitMap):
        assert type(s.map) is type(v.map) is cls
        s, v = s.env, v.env
    assert single.env.slots.tolist() == envs.env.slots.tolist() == [0, 1, 2, 3, 8]
    assert single.env.env.headroom == envs.env.env.headroom == 2.0


@pytest.mark.parametrize(
    "wrap",
    [
        UnitAction,
        ObserveModes,
        lambda env: WhitenObservation(env, np.eye(9)),
    ],
)
def test_single_env_wrappers_name_their_vector_version(wrap):
    """A vector env given to a single-env wrapper: one line pointing at the vector
    version (acld_gym.wrappers.vector), not gymnasium's assertion."""
    with pytest.raises(
        ValueError,
        match=r"^env: \w+ wraps a single env; for a vector env use "
        r"acld_gym\.wrappers\.vector\.\w+$",
    ):
        wrap(gym.make_vec("ACLDBeam-v1", num_envs=2))
    with pytest.raises(ValueError, match=r"^env: \w+ wraps a gymnasium.Env, got str$"):
        wrap("ACLDBeam-v1")
