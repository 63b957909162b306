"""The engineer's design model: the commands in flight are an exact shift; the designs do
not depend on the model's coordinates."""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from acld_gym.design.discrete import SampledSystem, impulse_response
from acld_gym.physics.loads import TipLoad
from baselines.engineer import ActuatorMPCPolicy, DelayLQGPolicy, rig_model
from baselines.engineer.model import shift_system


def env_impulse(level_env, env_id, steps, **kwargs):
    """The env's tip response [m] to a 1 V command at the first step, no load, no noise."""
    env = level_env(env_id, sensor_noise=0.0, **kwargs)
    env.reset(seed=0, options={"load": TipLoad()})
    y = []
    for k in range(steps):
        _, _, _, _, info = env.step(np.array([1.0 if k == 0 else 0.0], np.float32))
        y.append(info["tip_deflection"])
    return np.array(y)


def test_env_delay_is_a_shift(level_env):
    """The lab rig's response is its undelayed response d = 1 period later (the scale the
    augmented model is checked against)."""
    late = env_impulse(level_env, "ACLDBeamLab-v1", 15)
    now = env_impulse(level_env, "ACLDBeamLab-v1", 15, actuator_delay=0)
    assert late[0] == 0.0 and np.abs(now).max() > 1e-9
    np.testing.assert_allclose(late[1:], now[:-1], rtol=1e-12, atol=1e-20)


def test_augmented_impulse_is_the_delayed_response(level_env):
    """The augmented model's impulse response is the plant part's shifted by exactly d
    samples, as the env's delayed response is its undelayed one; and it follows the env's
    (the reduced against the truth model: the same few per cent at every delay, while a
    response one period off misses by far more)."""
    y0 = env_impulse(level_env, "ACLDBeamLab-v1", 20, actuator_delay=0)
    env = level_env("ACLDBeamLab-v1", actuator_delay=0).unwrapped
    h0 = impulse_response(
        rig_model(env.nom, env.config).plant, rig_model(env.nom, env.config).c, 20
    )
    base = np.abs(h0 - y0).max() / np.abs(y0).max()
    assert base < 0.2, base
    for d in (1, 3):
        env = level_env("ACLDBeamLab-v1", actuator_delay=d).unwrapped
        m = rig_model(env.nom, env.config)
        assert m.delay == d
        A, b = m.augmented()
        h = impulse_response((A, b), m.augmented_output(), 20)
        assert np.all(h[:d] == 0.0)
        np.testing.assert_allclose(h[d:], h0[: 20 - d], rtol=1e-12, atol=0)
        # the tip after step k (info) is h[k]: the model's delay is the env's
        y = env_impulse(level_env, "ACLDBeamLab-v1", 20, actuator_delay=d)
        assert np.all(y[:d] == 0.0)
        np.testing.assert_allclose(y[d:], y0[: 20 - d], rtol=1e-12, atol=1e-25)
        err = np.abs(h - y).max() / np.abs(y).max()
        assert err == pytest.approx(base, rel=1e-9)
        off = np.abs(np.r_[0.0, h[:-1]] - y).max() / np.abs(y).max()
        assert off > 3 * base, (off, base)


def test_shift_system_without_delay_is_the_plant():
    rng = np.random.default_rng(1)
    Ap, bp = rng.normal(size=(3, 3)), rng.normal(size=3)
    A, b = shift_system(Ap, bp, 0)
    np.testing.assert_array_equal(A, Ap)
    np.testing.assert_array_equal(b[:, 0], bp)


def _transformed(model, perm, signs):
    """The model in the coordinates x = T x', T a signed permutation of the plant part."""
    n = model.n_plant
    T = np.zeros((n, n))
    T[perm, np.arange(n)] = signs  # x[perm[j]] = signs[j] x'[j]
    Ti = T.T  # orthogonal
    p = model.plant
    plant = SampledSystem(Ti @ p.Ad @ T, Ti @ p.Bd, Ti @ p.W0, Ti @ p.W1, p.dt)
    return dataclasses.replace(model, plant=plant, c=model.c @ T, scale=np.abs(Ti) @ model.scale)


def _markov(policy, m=30):
    Ac, bc, cc, dc = policy.controller()
    out, v = [dc], bc
    for _ in range(m):
        out.append(cc @ v)
        v = Ac @ v
    return np.array(out)


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_designs_invariant_to_the_model_coordinates(level_env, seed):
    """A signed permutation of the plant's states (another machine's eigenvector signs and
    order) gives the same law: the same gain in the new coordinates, the same controller
    from the measurement to the command."""
    env = level_env("ACLDBeamHard-v1").unwrapped
    nom, config = env.nom, env.config
    base = rig_model(nom, config)
    rng = np.random.default_rng(seed)
    perm = rng.permutation(base.n_plant)
    signs = rng.choice([-1.0, 1.0], base.n_plant)
    other = _transformed(base, perm, signs)
    for cls in (DelayLQGPolicy, ActuatorMPCPolicy):
        a, b = cls(nom, config), cls(nom, config, model=other)
        ka, kb = a.small_signal_gain(), b.small_signal_gain()
        n = base.n_plant
        np.testing.assert_allclose(kb[:n], ka[perm] * signs, rtol=1e-6, atol=1e-9 * abs(ka).max())
        np.testing.assert_allclose(kb[n:], ka[n:], rtol=1e-6)
        ma, mb = _markov(a), _markov(b)
        np.testing.assert_allclose(mb, ma, rtol=1e-6, atol=1e-8 * np.abs(ma).max())


def test_reward_weights_are_the_env_step_cost(level_env):
    """Without delay and lag, z'Qz + 2 z'N u + R u^2 is the env's step cost
    (y_{k+1}/y_ref)^2 + lam (u/120)^2 for any state and command."""
    env = level_env("ACLDBeam-v1").unwrapped
    m = rig_model(env.nom, env.config)
    A, b = m.augmented()
    Q, R, N = m.reward_weights()
    rng = np.random.default_rng(0)
    for _ in range(5):
        z, u = rng.normal(size=m.n) * m.scale, rng.uniform(-120, 120)
        y = m.augmented_output() @ (A @ z + b[:, 0] * u)
        want = (y / m.y_ref) ** 2 + m.lam * (u / 120.0) ** 2
        got = z @ Q @ z + 2 * (z @ N[:, 0]) * u + R[0, 0] * u**2
        assert got == pytest.approx(want, rel=1e-9)


def test_kalman_gain_is_the_package_filter(level_env):
    """The scaled solve gives the package's (unscaled) steady-state Kalman filter for the
    same noise model on v1's design model."""
    from acld_gym.design.observer import discrete_kalman

    env = level_env("ACLDBeam-v1").unwrapped
    pol = DelayLQGPolicy(env.nom, env.config, model_std=0.1, load_std=1.0)
    sr = env.nom.reduced
    ref = discrete_kalman(
        sr.Ad, sr.Bd, sr.Ed, env.nom.design.reduced.C, 1.0, env.config.sensor_noise, 0.1
    )
    np.testing.assert_allclose(pol.M, ref.Lc[:, 0], rtol=1e-6)


def test_lqr_gain_with_cross_term_is_the_package_lqr(level_env):
    """The scaled solve with the reward's cross term gives the package's discrete LQR of
    the equivalent problem without it (A - b R^-1 N', Q - N R^-1 N'), plus R^-1 N'."""
    from acld_gym.design.feedback import discrete_lqr_gain

    env = level_env("ACLDBeam-v1").unwrapped
    pol = DelayLQGPolicy(env.nom, env.config)
    m = pol.model
    A, b = m.augmented()
    Q, R, N = m.reward_weights()
    F = np.linalg.solve(R, N.T)
    K0, _ = discrete_lqr_gain(A - b @ F, b, Q - N @ F, R)
    np.testing.assert_allclose(pol.K, (K0 + F)[0], rtol=1e-5)


@pytest.mark.parametrize("env_id", ["ACLDBeam-v1", "ACLDBeamLab-v1", "ACLDBeamHard-v1"])
def test_mpc_with_its_tail_is_the_lqg_about_rest(level_env, env_id):
    """Unconstrained, the MPC with the LQR's cost-to-go as its tail is the infinite-horizon
    law: its gain on the augmented estimate (the delay by prediction) is the LQG's on the
    augmented model (the shift register) -- two routes to one law."""
    env = level_env(env_id).unwrapped
    for w in (0.3, 1.0):
        lqg = DelayLQGPolicy(env.nom, env.config, weight=w)
        mpc = ActuatorMPCPolicy(env.nom, env.config, weight=w, horizon=20)
        k = lqg.small_signal_gain()
        np.testing.assert_allclose(mpc.small_signal_gain(), k, rtol=1e-6, atol=1e-9 * abs(k).max())
    short = ActuatorMPCPolicy(env.nom, env.config, horizon=20, terminal=False)  # w = 1
    assert np.abs(short.small_signal_gain() - k).max() > 1e-3 * np.abs(k).max()
