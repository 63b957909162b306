"""Custom loads in the env (issue 21): a ``TipLoad`` wherever a load case is named, as
``load_case=`` or ``reset(options={"load": ...})``; checked against the thesis's load case
and against linearity."""

from __future__ import annotations

import numpy as np
import pytest

from acld_gym.envs.beam_env import COMPILED_STEP, ACLDBeamEnv
from acld_gym.envs.vector_env import ACLDBeamVectorEnv
from acld_gym.physics.loads import (
    Harmonic,
    Pulse,
    Samples,
    TipLoad,
    half_sine_shock,
    random_load,
    recorded_load,
)

PATHS = [True, False] if COMPILED_STEP else [False]


def _run(env, acts, seed=0, options=None):
    obs, info = env.reset(seed=seed, options=options)
    out = [(obs, 0.0, info)]
    for a in acts:
        obs, r, _, _, info = env.step(a)
        out.append((obs, r, info))
    return out


@pytest.mark.parametrize("compiled", PATHS)
def test_a_custom_1N_1ms_pulse_is_load_case_1_exactly(compiled):
    acts = np.random.default_rng(0).uniform(-150, 150, (400, 1)).astype(np.float32)
    pulse = TipLoad((Pulse(0.0, 1e-3, 1.0),))
    envs = []
    for kw in (dict(load_case=1), dict(load_case=pulse), dict(load_case=2)):
        env = ACLDBeamEnv(**kw)
        env.compiled_step = compiled
        envs.append(env)
    case1 = _run(envs[0], acts)
    for got in (_run(envs[1], acts), _run(envs[2], acts, options={"load": pulse})):
        for (o1, r1, i1), (o2, r2, i2) in zip(case1, got, strict=True):
            assert o1.tobytes() == o2.tobytes() and r1 == r2  # bit for bit
            for key, value in i1.items():
                assert np.array_equal(value, i2[key]), key
    vec = ACLDBeamVectorEnv(num_envs=2, load_case=pulse)
    vec.compiled_step = compiled
    obs, _ = vec.reset(seed=0)
    assert obs[0].tobytes() == case1[0][0].tobytes()
    for k, a in enumerate(acts[:100]):
        obs, r, *_ = vec.step(np.repeat(a[None], 2, axis=0))
        np.testing.assert_allclose(obs[0], case1[k + 1][0], rtol=1e-6, atol=1e-7)


LOADS = {
    "pulses": TipLoad((Pulse(0.002, 3e-3, 0.8), Pulse(0.05, 1e-3, -1.2))),
    "harmonic": TipLoad((Harmonic(0.1, 400.0, 0.0, 0.15, 0.4),)),
    "shock": half_sine_shock(1.5, 2e-3, start=0.003),
    "recorded": recorded_load(np.random.default_rng(2).normal(0.0, 0.2, 300), 7e-4),
    "random": random_load(np.random.default_rng(5), 1.0, 1e-4, (177.4, 976.2)),
    "mixed": TipLoad((Pulse(0.0, 1e-3, 1.0), Samples(0.0, 2e-3, tuple(np.linspace(0, 1, 80))))),
}


@pytest.mark.parametrize("compiled", PATHS)
@pytest.mark.parametrize("name", list(LOADS))
def test_half_the_load_gives_half_the_response(name, compiled):
    # The plant is linear and starts at rest: without sensor noise and voltage, the tip
    # deflection is linear in the load.
    load = LOADS[name]
    zero = np.zeros(1, np.float32)
    y = {}
    for factor in (1.0, 0.5):
        env = ACLDBeamEnv(load_case=load.scaled(factor), sensor_noise=0.0)
        env.compiled_step = compiled
        y[factor] = np.array([info["tip_deflection"] for *_, info in _run(env, [zero] * 300)])
    assert np.abs(y[1.0]).max() > 1e-6  # the load does move the tip
    np.testing.assert_allclose(y[0.5], 0.5 * y[1.0], rtol=1e-9, atol=1e-12 * np.abs(y[1.0]).max())


def test_custom_loads_reach_the_vector_env_per_episode():
    load = LOADS["shock"]
    vec = ACLDBeamVectorEnv(num_envs=3, load_case=1, episode_length=0.02)
    vec.reset(seed=0, options={"load": load})
    assert vec.loads == [load] * 3
    for _ in range(21):  # an autoreset: back to the env's own load case
        vec.step(np.zeros(3))
    assert vec.loads == [vec.loads[0]] * 3 and vec.loads[0] != load
