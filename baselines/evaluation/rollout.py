"""One episode of a policy, and its row of metrics: the primitives under
:mod:`baselines.evaluate`, :mod:`baselines.evaluation.score` and ``train.compare``.

:func:`rollout` runs any object with stable-baselines3's ``predict`` through an env,
deterministically. A policy may also have ``start_episode(env)``: :func:`rollout` calls it
right after ``env.reset``, with the env, before the first ``predict``. That hook is for the
*oracles* only (:mod:`baselines.oracle`): references that are told what no deployable
policy knows -- the episode's own plant and actuator, or (for the bound's replay) its whole
load -- and say so in their name. A deployable policy acts on its observations alone.
:func:`bound_episode` is the clairvoyant bound of the env's current episode and
:func:`metrics_row` an episode's metrics (peak, settling, ISE, effort).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass

import numpy as np

from acld_gym.design.discrete import impulse_response
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.fingerprint import fingerprint_differences, observation_fingerprint
from acld_gym.envs.step import reward_of
from acld_gym.thesis.metrics import max_abs, peak, settling_time
from acld_gym.util.blas import one_blas_thread

from ..analysis.effort import effort, settled_from

__all__ = [
    "Episode",
    "EvalRow",
    "check_compatible",
    "rollout",
    "bound_episode",
    "bound_solution",
    "metrics_row",
]


@dataclass(frozen=True)
class Episode:
    """Per-step record of one episode: t [s], y [m], voltage [V], reward."""

    t: np.ndarray
    y: np.ndarray
    voltage: np.ndarray
    reward: np.ndarray
    seconds_per_step: float


@dataclass(frozen=True)
class EvalRow:
    case: int | str
    policy: str
    peak_mm: float
    settling_s: float
    ise: float
    max_voltage_V: float
    # ``return`` is a keyword; stored as ``ret`` and written as "return".
    ret: float
    ms_per_step: float
    # Effort (baselines.analysis.effort); the settled-window ones are NaN without a
    # settled window (random loads).
    rms_voltage_V: float = math.nan
    reactive_power_var: float = math.nan
    total_variation_V_per_s: float = math.nan
    limit_fraction: float = math.nan
    residual_tip_rms_m: float = math.nan

    def as_dict(self) -> dict:
        d = asdict(self)
        d["return"] = d.pop("ret")
        return {
            k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()
        }


def check_compatible(policy, env) -> None:
    """``ValueError`` if ``policy`` records an observation fingerprint that ``env``'s
    observation does not match (:mod:`acld_gym.envs.fingerprint`)."""
    expected = getattr(policy, "observation_fingerprint", None)
    if expected is None:
        return
    diff = fingerprint_differences(expected, observation_fingerprint(env))
    if diff:
        name = getattr(policy, "name", type(policy).__name__)
        raise ValueError(
            f"policy {name!r} was built for another observation than this env's: " + "; ".join(diff)
        )


def rollout(policy, env: ACLDBeamEnv, seed: int = 0, options: dict | None = None) -> Episode:
    """Run one deterministic episode of ``policy`` (SB3 ``predict``) in ``env``."""
    check_compatible(policy, env)
    obs, _ = env.reset(seed=seed, options=options)
    start_episode = getattr(policy, "start_episode", None)
    if start_episode is not None:  # an oracle (module docstring)
        start_episode(env)
    t, y, v, r = [], [], [], []
    spent = 0.0
    done = False
    state, start = None, np.ones(1, dtype=bool)  # SB3's recurrent-policy protocol
    while not done:
        t0 = time.perf_counter()
        action, state = policy.predict(obs, state=state, episode_start=start, deterministic=True)
        start = np.zeros(1, dtype=bool)
        spent += time.perf_counter() - t0
        obs, reward, term, trunc, info = env.step(action)
        t.append(info["time"])
        y.append(info["tip_deflection"])
        v.append(info["voltage"])
        r.append(reward)
        done = term or trunc
    return Episode(np.array(t), np.array(y), np.array(v), np.array(r), spent / len(t))


def bound_solution(env: ACLDBeamEnv):
    """The clairvoyant bound of ``env``'s current episode
    (:class:`baselines.bound.BoundSolution`: the amplifier's outputs, the commands
    ``actuator_delay`` periods late, and the tip), and the seconds it took to solve."""
    from ..bound import clairvoyant_bound  # scipy.optimize (~0.25 s): only the bound needs it

    env = env.unwrapped
    plant, c = env.episode_plant, env.config
    tip = np.zeros(plant.Ad.shape[0])
    tip[: env.nom.output.size] = env.nom.output
    t0 = time.perf_counter()
    with one_blas_thread():  # small dense problems (acld_gym.util.blas)
        sol = clairvoyant_bound(
            plant, tip, env.load, env.max_steps, delay=c.actuator_delay, slew_step=c.slew_step
        )
    return sol, time.perf_counter() - t0


def bound_episode(env: ACLDBeamEnv) -> Episode:
    """The clairvoyant bound for ``env``'s current load and plant (the episode's own:
    randomized with ``param_noise``, at its temperature, with its amplifier's lag), with the
    env's actuator inside: the delay shifts the impulse response, the lag is part of the
    sampled plant, the slew limit is a constraint (:func:`baselines.bound.clairvoyant_bound`).
    Its voltages are the patch's (the amplifier's output through the lag)."""
    sol, spent = bound_solution(env)
    env = env.unwrapped
    plant, n = env.episode_plant, env.max_steps
    volts = sol.voltage
    if env.config.amplifier_bandwidth is not None:
        patch = np.zeros(plant.Ad.shape[0])
        patch[env.nom.output.size] = 1.0  # the patch voltage, a state of the lagged plant
        volts = np.convolve(impulse_response(plant, patch, n), sol.voltage)[:n]
    t = np.arange(1, n + 1) * env.dt
    reward = reward_of(sol.y, volts, env.y_ref, env.lam, env.v_max)
    return Episode(t, sol.y, volts, reward, spent / n)


def metrics_row(case, name: str, ep: Episode) -> EvalRow:
    dt = float(ep.t[1] - ep.t[0]) if ep.t.size > 1 else float(ep.t[0])
    e = effort(ep.voltage, ep.y, dt, settled_from(case))
    return EvalRow(
        case=case,
        policy=name,
        peak_mm=peak(ep.y) * 1e3,
        settling_s=settling_time(ep.t, ep.y),
        ise=float(np.sum(ep.y**2) * dt),
        max_voltage_V=max_abs(ep.voltage),
        ret=float(np.sum(ep.reward)),
        ms_per_step=1e3 * ep.seconds_per_step,
        rms_voltage_V=e.rms_voltage_V,
        reactive_power_var=e.reactive_power_var,
        total_variation_V_per_s=e.total_variation_V_per_s,
        limit_fraction=e.limit_fraction,
        residual_tip_rms_m=e.residual_tip_rms_m,
    )
