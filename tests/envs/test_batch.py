"""One step (issue 21): the single env is the N = 1 case of the batched step, the vector env
its N case, and the compiled step runs the same step on the same arrays. On every option the
four paths -- single and vector env, each compiled and in numpy -- give the same episodes
to rounding, through NEXT_STEP autoresets, with the same info keys."""

from __future__ import annotations

import numpy as np
import pytest
from stepping import single_rollout

from acld_gym.envs.beam_env import COMPILED_STEP, ACLDBeamEnv
from acld_gym.envs.presets import PRESETS
from acld_gym.envs.step import INFO_KEYS
from acld_gym.envs.vector_env import ACLDBeamVectorEnv
from acld_gym.physics.loads import (
    Harmonic,
    Pulse,
    Samples,
    TipLoad,
    band_limited_noise,
    sine_sweep,
)

N = 3
STEPS = 130  # 50-step episodes: two autoresets

_rng = np.random.default_rng(0)
CUSTOM = TipLoad(
    (
        Pulse(0.004, 1.3e-3, 0.7),
        Harmonic(0.05, 900.0, 0.0123, 0.02, 0.3),
        Samples(0.0021, 7e-4, tuple(_rng.normal(0.0, 0.1, 60).tolist())),
    )
)

#: Every option of the configuration, each on its own and a few together.
OPTIONS = {
    "case1": dict(load_case=1),
    "case2": dict(load_case=2),
    "case3": dict(load_case=3, sensor_noise=0.0),
    "random": dict(load_case="random"),
    "custom": dict(load_case=CUSTOM),
    "noise-load": dict(load_case=band_limited_noise(np.random.default_rng(1), 0.05, 0.2, 300.0)),
    "sweep": dict(load_case=sine_sweep(0.3, 50.0, 400.0, 0.05)),
    "measurement": dict(load_case="random", obs_mode="measurement", lam=0.1),
    "full": dict(load_case=2, obs_mode="full"),
    "thesis-observer": dict(load_case=1, observer="thesis"),
    "param-noise": dict(load_case="random", param_noise=0.05, obs_mode="full"),
    "thesis-mesh": dict(load_case="random", mesh="thesis", param_noise=0.05),
    "dt": dict(load_case="random", dt=5e-4),
    "limit": dict(load_case=3, deflection_limit=5e-4),  # terminates early, then autoresets
    "reward": dict(load_case=1, y_ref=5e-4, lam=0.3),
    "v0": dict(PRESETS["ACLDBeam-v0"], load_case="random"),
    "delay": dict(load_case="random", actuator_delay=3),
    "commands": dict(load_case="random", actuator_delay=3, observe_commands=True),
    "commands-measurement": dict(
        load_case="random", actuator_delay=2, obs_mode="measurement", observe_commands=True
    ),
    "lag": dict(load_case=2, amplifier_bandwidth=400.0),
    "slew": dict(load_case="random", slew_rate=3e4, obs_mode="measurement"),
    "actuator": dict(
        load_case="random",
        actuator_delay=1,
        amplifier_bandwidth=800.0,
        slew_rate=6e4,
        observer="thesis",
    ),
    "temperature": dict(load_case="random", temperature=24.0),
    "temperature-range": dict(load_case="random", temperature_range=(17.0, 30.0), param_noise=0.03),
    "thesis-actuator": dict(
        load_case=3, mesh="thesis", actuator_delay=2, slew_rate=2e4, temperature=22.0
    ),
}


def _actions(seed=0):
    return np.random.default_rng(seed).uniform(-150, 150, (STEPS, N, 1)).astype(np.float32)


def _vector(kw, compiled, acts, seed=11):
    env = ACLDBeamVectorEnv(num_envs=N, **kw)
    env.compiled_step = compiled
    o, info = env.reset(seed=seed)
    steps = [(o, None, None, None, info)]
    for a in acts:
        steps.append(env.step(a))
    return steps


def _as_vector(step):
    """A single-env rollout's row in the vector env's format."""
    o, r, te, tr, infos = step
    info = {k: np.array([d[k] for d in infos]) for k in INFO_KEYS}
    return o, r, te, tr, info


def _assert_same(a, b, what):
    n_done = 0
    for k, ((ao, ar, ate, atr, ai), (bo, br, bte, btr, bi)) in enumerate(zip(a, b, strict=True)):
        np.testing.assert_allclose(ao, bo, rtol=1e-6, atol=1e-6, err_msg=f"{what} obs {k}")
        if ar is not None:
            np.testing.assert_allclose(ar, br, rtol=1e-9, atol=1e-12, err_msg=f"{what} reward")
            np.testing.assert_array_equal(ate, bte, err_msg=f"{what} terminated {k}")
            np.testing.assert_array_equal(atr, btr, err_msg=f"{what} truncated {k}")
            n_done += int(np.sum(ate | atr))
        for key in INFO_KEYS:
            if key == "terminated_by":
                np.testing.assert_array_equal(ai[key], bi[key], err_msg=what)
                continue
            scale = float(np.max(np.abs(bi[key]), initial=0.0))
            np.testing.assert_allclose(
                np.asarray(ai[key], dtype=float),
                np.asarray(bi[key], dtype=float),
                rtol=1e-9,
                atol=1e-12 * scale + 1e-15,
                err_msg=f"{what} {key} {k}",
            )
    return n_done


@pytest.mark.parametrize("name", list(OPTIONS))
def test_single_vector_and_compiled_steps_agree_on_every_option(name):
    kw = dict(OPTIONS[name])
    kw["episode_length"] = 50 * kw.get("dt", 1e-3)  # 50 steps
    acts = _actions()
    paths = [True, False] if COMPILED_STEP else [False]
    ref = [_as_vector(s) for s in single_rollout(kw, N, acts, compiled=False)]  # single env, numpy
    for compiled in paths:
        if compiled:
            got = [_as_vector(s) for s in single_rollout(kw, N, acts, compiled=True)]
            _assert_same(got, ref, f"{name}: single compiled vs numpy")
        vec = _vector(kw, compiled, acts)
        done = _assert_same(vec, ref, f"{name}: vector (compiled={compiled}) vs single")
        assert done >= 2 * N  # the run crossed the autoresets
        assert set(vec[-1][4]) == set(INFO_KEYS) | {"_" + k for k in INFO_KEYS}
    if name == "limit":
        assert any(np.any(s[2]) for s in ref[1:])  # terminations did happen


def test_reward_terms_add_up_and_info_carries_them():
    env = ACLDBeamEnv(load_case=2, lam=0.2, y_ref=2e-3)
    env.reset(seed=1)
    for v in (0.0, 80.0, -200.0):
        _, r, *_, info = env.step(np.array([v], np.float32))
        assert info["reward_deflection"] == -((info["tip_deflection"] / 2e-3) ** 2)
        assert info["reward_voltage"] == -(0.2 * (info["voltage"] / 120.0) ** 2)
        assert r == info["reward_deflection"] + info["reward_voltage"]
        assert info["requested_voltage"] == v and info["clipped"] == (abs(v) > 120)
