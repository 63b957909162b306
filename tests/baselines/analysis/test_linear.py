"""The exact small-signal loop (baselines.analysis.linear): the law read from predict, the loop
against the env's own response, invariance to the plant's coordinates, and the margins."""

from dataclasses import replace
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from baselines.analysis.linear import (
    LinearLaw,
    ObserverLoop,
    frequency_response,
    margins,
    small_signal_law,
)
from baselines.policies import LQRPolicy, SMCPolicy
from baselines.robustness import closed_loop_matrix
from train.agent import TrainedAgent

#: Agents with known faults (described in the README of tests/data/agents).
FIXTURES = Path(__file__).resolve().parents[2] / "data" / "agents"


class PredictOnly:
    """A policy seen through predict alone (its declared gain hidden)."""

    def __init__(self, policy):
        self._p = policy

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        return self._p.predict(obs, state, episode_start, deterministic)


def _pulse_response(loop, law, steps, amplitude=1.0):
    """The exact loop's tip after a load pulse of ``amplitude`` over the first period,
    c A_cl^k e (k = 0..steps-1)."""
    A, (_, _, _, e), c = loop.closed_loop(law), loop.open_loop(law), loop.tip_row()
    x, out = amplitude * e, np.empty(steps)
    for k in range(steps):
        out[k] = c @ x
        x = A @ x
    return out


@pytest.fixture(scope="module")
def loop():
    env = gym.make("ACLDBeam-v1")
    env.reset(seed=0)
    return ObserverLoop.from_env(env)


@pytest.mark.parametrize("cls", [LQRPolicy, SMCPolicy])
def test_differences_of_predict_give_the_declared_gain(cls):
    pol = cls()
    declared, _ = small_signal_law(pol, 9, 120.0)
    measured, why = small_signal_law(PredictOnly(pol), 9, 120.0)
    assert measured is not None, why
    np.testing.assert_allclose(
        measured.gain, declared.gain, rtol=1e-5, atol=1e-6 * np.abs(declared.gain).max()
    )
    assert declared.gain[8] == 0 and declared.offset == 0  # the tip entry is not used


def test_nonlinear_and_saturated_policies_are_refused():
    sac = TrainedAgent.load(FIXTURES / "sac_0.2")  # [z/|z|, log|z|] features, tanh
    law, why = small_signal_law(sac, 9, 120.0)
    assert law is None and "linear" in why
    stuck = TrainedAgent.load(FIXTURES / "ppo_dagger")  # -120 V at rest
    law, why = small_signal_law(stuck, 9, 120.0)
    assert law is None and "limit at rest" in why

    class Relay(PredictOnly):
        def predict(self, obs, state=None, episode_start=None, deterministic=True):
            o = np.atleast_2d(obs)
            return 10.0 * np.sign(o[:, :1] + 1e-7), state

    assert small_signal_law(Relay(None), 9, 120.0)[0] is None


def test_a_policy_with_a_state_has_no_static_law():
    """MeasurementFeedback runs its own observer (a dynamic law): no gain on the observation."""
    env = gym.make("ACLDBeam-v1", obs_mode="measurement")
    law, why = small_signal_law(LQRPolicy.for_env(env), 9, 120.0)
    assert law is None and "state" in why


def test_the_exact_loop_is_the_envs_loop(rig, loop):
    """The tip's response to a small pulse through the env equals c A_cl^k e."""
    pol = LQRPolicy()
    law, _ = small_signal_law(pol, 9, 120.0)
    f = np.zeros(1500)
    f[0] = 0.05
    h = (rig.run(pol, f).y[1:] - rig.run(pol, np.zeros(1500)).y[1:]) / 0.05
    exact = _pulse_response(loop, law, 1500)
    assert np.linalg.norm(h - exact) / np.linalg.norm(exact) < 2e-4  # the basis's noise


def test_loop_matches_the_robustness_study(loop):
    pol = LQRPolicy()
    law, _ = small_signal_law(pol, 9, 120.0)
    nom = pol.nom
    ref = np.linalg.eigvals(
        closed_loop_matrix(nom.plant, nom.output, nom.kalman, pol.small_signal_gain())
    )
    got = np.linalg.eigvals(loop.closed_loop(law))
    np.testing.assert_allclose(np.sort_complex(got), np.sort_complex(ref), atol=1e-12)


def test_modes_and_margins_do_not_depend_on_the_plants_coordinates(loop, passive):
    _, edges = passive
    law, _ = small_signal_law(LQRPolicy(), 9, 120.0)
    rng = np.random.default_rng(2)
    n = loop.plant.Ad.shape[0]
    T = np.linalg.qr(rng.normal(size=(n, n)))[0] * rng.choice([-1.0, 1.0], n)
    p = loop.plant
    moved = replace(
        loop,
        plant=replace(p, Ad=T.T @ p.Ad @ T, Bd=T.T @ p.Bd, W0=T.T @ p.W0, W1=T.T @ p.W1),
        output=loop.output @ T,
    )
    for a, b in zip(loop.modes(law, edges, 2000), moved.modes(law, edges, 2000), strict=True):
        # rel 1e-9: an eigenvalue of the rotated loop moves by round-off times its condition
        # (1.4e-10 relative for mode 3 with OpenBLAS's Nehalem kernels, 2653.6897212 rad/s)
        assert a.frequency_rad_s == pytest.approx(b.frequency_rad_s, rel=1e-9)
        assert a.damping_ratio == pytest.approx(b.damping_ratio, rel=1e-7)
    m1, m2 = margins(loop, law), margins(moved, law)
    for key in ("gain_margin_db", "phase_margin_deg", "stability_margin"):
        assert m1[key] == pytest.approx(m2[key], rel=1e-6)


@pytest.mark.parametrize("cls", [LQRPolicy, SMCPolicy])
def test_the_gain_margin_is_where_the_loop_goes_unstable(loop, cls):
    law, _ = small_signal_law(cls(), 9, 120.0)
    m = margins(loop, law)
    assert m["closed_loop_stable"] and 0 < m["gain_margin_db"] < 20
    k = 10 ** (m["gain_margin_db"] / 20)
    at = LinearLaw(gain=k * law.gain, offset=0.0)
    below = LinearLaw(gain=0.97 * k * law.gain, offset=0.0)
    assert loop.spectral_radius(at) == pytest.approx(1.0, abs=2e-4)
    assert (
        loop.spectral_radius(below)
        < 1.0
        < loop.spectral_radius(LinearLaw(gain=1.03 * k * law.gain, offset=0.0))
    )


def test_the_phase_margin_is_read_at_a_gain_crossover(loop):
    law, _ = small_signal_law(LQRPolicy(), 9, 120.0)
    m = margins(loop, law)
    A, b, cv, _ = loop.open_loop(law)
    L = -frequency_response(A, b, cv, np.array([m["phase_margin_rad_s"]]), loop.plant.dt)[0]
    assert abs(L) == pytest.approx(1.0, rel=1e-3)
    assert np.degrees(abs(np.angle(-L))) == pytest.approx(m["phase_margin_deg"], abs=0.1)


def test_a_zero_law_leaves_the_passive_beam(loop):
    w = np.geomspace(50, 3000, 200)
    zero = LinearLaw(gain=np.zeros(9), offset=0.0)
    np.testing.assert_allclose(loop.compliance(zero, w), loop.compliance(None, w), rtol=1e-9)
    assert loop.spectral_radius(zero) < 1


def _small_pulse_run(pol_cls=LQRPolicy, steps=1500, **options):
    """The env's tip after a 1 mN x 1 ms pulse under a linear policy, without sensor noise
    (a custom load, acld_gym.physics.loads), and the exact loop's prediction c A_cl^k e."""
    from acld_gym.envs import ACLDBeamEnv, preset
    from acld_gym.physics.loads import thesis_load
    from baselines.evaluate import rollout

    env = ACLDBeamEnv(
        config=preset(
            "ACLDBeam-v1",
            sensor_noise=0.0,
            episode_length=steps * 1e-3,
            load_case=thesis_load(1).scaled(1e-3),
            **options,
        )
    )
    pol = pol_cls.for_env(env)
    ep = rollout(pol, env, seed=0)
    loop = ObserverLoop.from_env(env)
    law, why = small_signal_law(pol, 9, 120.0)
    assert law is not None, why
    return ep, _pulse_response(loop, law, steps, 1e-3), loop, law


def test_the_exact_loop_holds_the_actuators_delay_and_lag():
    """Two periods of delay and a 300 Hz amplifier (whose lag matters at 1 kHz): the loop's
    shift register and the lagged plant give the env's response to round-off."""
    ep, exact, loop, law = _small_pulse_run(actuator_delay=2, amplifier_bandwidth=300.0)
    assert loop.delay == 2 and loop.plant.Ad.shape[0] == 37  # the patch voltage, a state
    assert np.abs(ep.voltage).max() < 120.0  # linear throughout
    assert np.linalg.norm(ep.y - exact) / np.linalg.norm(exact) < 1e-6
    # the same loop without its delay misses the env's response: the delay is really in it
    other = _pulse_response(replace(loop, delay=0), law, exact.size, 1e-3)
    assert np.linalg.norm(ep.y - other) / np.linalg.norm(exact) > 1e-2


def test_the_lab_rigs_delay_makes_the_nominal_lqr_unstable():
    """ACLDBeamLab-v1's one period of delay: the exact loop of the nominal LQR has a pole
    outside the unit circle, and the env's response to a small pulse grows as it predicts
    until the voltage saturates."""
    from acld_gym.envs.presets import LAB

    lab = {k: v for k, v in LAB.items() if k != "sensor_noise"}
    ep, exact, loop, law = _small_pulse_run(steps=600, **lab)
    rho = loop.spectral_radius(law)
    assert rho > 1.01 and not margins(loop, law)["closed_loop_stable"]
    linear = int(np.argmax(np.abs(ep.voltage) >= 120.0))  # the first saturated period
    assert 200 < linear < 600
    np.testing.assert_allclose(
        ep.y[:linear], exact[:linear], atol=1e-6 * np.abs(exact[:linear]).max()
    )
    assert np.abs(ep.y[linear - 50 : linear]).max() > 10 * np.abs(ep.y[:50]).max()  # it grows
