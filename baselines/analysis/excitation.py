r"""Any tip load through the env, by superposing copies of the env's own load pulse.

:class:`PulseSuperposition` drives a policy through the env's public ``reset`` and ``step``
under any load that is held constant over each control period, with the env's sensor noise
cancelled from what the policy sees. The env also takes custom loads itself
(``reset(options={"load": TipLoad})``, :mod:`acld_gym.physics.loads`), but then the policy
sees the load's response with the env's sensor noise on it, and the env's noise level is
not free to change: it sets the Kalman filter (``sensor_noise=0`` gives another observer,
which agents trained on the default refuse, and another loop). The superposition keeps the
env's configuration and removes the noise.

**Why it is exact.** From rest, everything the env computes -- plant, observer,
observation, tip -- is linear and time-invariant in the voltages, the load and the sensor
noise; only the policy is not. Load case 1 is a 1 N pulse over the first period (dt =
1 ms), and a seed fixes the noise of an episode whatever the actions. A passive episode
(V = 0) of case 1 with seed s observes :math:`G^s_k = g_k + n^s_k` (the unit pulse's
response plus the seed's noise response) and has the true, noise-free tip
:math:`\gamma_k`. An episode of case 1 with the same seed under voltages V observes
:math:`o_k = g_k + n^s_k + o^V_k`, so

.. math::

    o_k - G^s_k + \sum_{m<k} f_m \bar G_{k-m} = o^V_k + o^f_k
    + \sum_{m<k} f_m \bar n_{k-m}, \qquad \bar G = \tfrac1M \sum_{j<M} G^{s+j},

is the observation of the same voltages under the load f (held :math:`f_m` over period
m) instead of the pulse, with the episode's own noise cancelled exactly. The policy is
given that observation at every step, and the env steps with its voltage (clipped and
held as always); the tip is :math:`y_k - \gamma_k + \sum_{m<k} f_m \gamma_{k-m}`. The
env's own pulse and noise never reach the policy. What remains is the last sum: the
unit-pulse response :math:`\bar G` is the mean of M passive episodes (``basis_seeds``), so
it carries the sensor noise divided by :math:`\sqrt M`, and the policy sees that noise
convolved with the load, :math:`\sum_m f_m \bar w_{k-m}`: for the identification's pulse
of a few centinewtons and M = 64, a sensor noise of a few 1e-10 m instead of the env's
1e-7 m. Without a load (f = 0) the run is exactly noise-free.

The env keeps its configured sensor noise on purpose: it designs its Kalman filter for
that noise level (``sensor_noise=0`` gives another observer, which agents trained on the
default refuse, and another loop). The observation is rounded to the env's float32 as the
env does.

Requirements (checked): the env starts at rest, and its control period equals the case-1
pulse (1 ms). The reconstructed tip must stay within the env's ``deflection_limit``, where
the env would have ended the episode.
"""

from __future__ import annotations

from dataclasses import dataclass

import gymnasium as gym
import numpy as np
from scipy.signal import fftconvolve

import acld_gym  # noqa: F401  (registers the env ids)
from acld_gym.physics.loads import thesis_load
from acld_gym.util.validate import check_int, check_seed
from baselines.evaluation.rollout import check_compatible

__all__ = ["Response", "PulseSuperposition", "causal_convolution"]


@dataclass(frozen=True)
class Response:
    """A run under a per-period load: ``load[k]`` [N] over period k, ``voltage[k]`` [V]
    applied over it (``requested[k]`` the policy's), ``y[k]`` [m] the tip at t = k dt
    (``y[0] = 0``, at rest)."""

    load: np.ndarray
    y: np.ndarray
    voltage: np.ndarray
    requested: np.ndarray
    dt: float

    @property
    def t(self) -> np.ndarray:
        """Times of ``y`` [s]."""
        return np.arange(self.y.size) * self.dt


def causal_convolution(load: np.ndarray, g: np.ndarray) -> np.ndarray:
    """``out[k] = sum_{m<k} load[m] g[k-m]`` for k = 0..N (``g`` has N + 1 rows, ``g[0]``
    unused): the response to ``load`` from a unit-pulse response ``g`` (1-D or rows)."""
    load = np.asarray(load, dtype=float)
    g = np.asarray(g, dtype=float)
    n = load.size
    g1 = g[1 : n + 1]
    full = fftconvolve(load.reshape((n,) + (1,) * (g.ndim - 1)), g1, axes=0)[:n]
    return np.concatenate([np.zeros((1,) + g.shape[1:]), full], axis=0)


class PulseSuperposition:
    """Per-period tip loads through the env ``env_id`` (module docstring).

    Parameters
    ----------
    env_id : str
        A registered ACLDBeam id.
    n_steps : int
        The longest run [control periods], the length of the unit-pulse responses.
    seed : int
        Reset seed of every run (with ``param_noise`` or ``temperature_range``, it draws the
        plant).
    basis_seeds : int
        M, the passive episodes (seeds ``seed .. seed + M - 1``) averaged into the unit-pulse
        response; 1 where each episode draws its plant (``param_noise``,
        ``temperature_range``: the seeds would draw other plants).
    **env_kwargs
        Further env arguments (``load_case`` and ``episode_length`` are set here).
    """

    def __init__(
        self,
        env_id: str = acld_gym.ENV_ID,
        n_steps: int = 2000,
        seed: int = 0,
        basis_seeds: int = 64,
        **env_kwargs,
    ):
        self.n_steps = check_int("n_steps", n_steps, 2, 1_000_000)
        self.seed = check_seed(seed)
        if self.seed is None:
            raise ValueError("seed must be an integer, got None")
        m = check_int("basis_seeds", basis_seeds, 1, 10_000)
        for key in ("load_case", "episode_length"):
            if key in env_kwargs:
                raise ValueError(f"env_kwargs: {key!r} is set by PulseSuperposition")
        probe = gym.make(env_id, **env_kwargs)
        self.dt = float(probe.unwrapped.dt)
        probe.close()
        pulse = thesis_load(1).components[0]
        if abs(pulse.duration - self.dt) > 1e-12 * self.dt:
            raise ValueError(
                f"env_kwargs: the excitation needs dt equal to load case 1's "
                f"pulse ({pulse.duration:g} s), got dt = {self.dt:g} s"
            )
        self.env = gym.make(
            env_id, load_case=1, episode_length=self.n_steps * self.dt, **env_kwargs
        )
        self.limit = float(self.env.unwrapped.deflection_limit)
        self._zero = np.zeros(self.env.action_space.shape, self.env.action_space.dtype)
        self.own_obs, self.g_y = self._unit_pulse(self.seed)
        total = self.own_obs.copy()
        for j in range(1, m):
            obs, y = self._unit_pulse(self.seed + j)
            if not np.array_equal(y, self.g_y):
                raise ValueError(
                    f"basis_seeds: seed {self.seed + j} draws another plant "
                    f"(param_noise, temperature_range); use basis_seeds=1"
                )
            total += obs
        self.basis_seeds = m
        #: The unit pulse's observation response, averaged over the basis seeds.
        self.g_obs = total / m

    def _unit_pulse(self, seed: int) -> tuple[np.ndarray, np.ndarray]:
        """Observation (with the seed's noise) and true tip of a passive episode of case 1:
        the unit-pulse responses."""
        obs, info = self.env.reset(seed=seed)
        if info["tip_deflection"] != 0:
            raise ValueError("env: the excitation needs an env that starts at rest")
        g = np.empty((self.n_steps + 1, obs.size))
        y = np.zeros(self.n_steps + 1)
        g[0] = obs
        for k in range(self.n_steps):
            obs, _, term, _, info = self.env.step(self._zero)
            if term:
                raise RuntimeError(
                    f"env: the passive episode ended at step {k + 1} ({info['terminated_by']})"
                )
            g[k + 1], y[k + 1] = obs, info["tip_deflection"]
        return g, y

    def _check_load(self, load) -> np.ndarray:
        f = np.asarray(load, dtype=float)
        if f.ndim != 1 or not 1 <= f.size <= self.n_steps or not np.all(np.isfinite(f)):
            raise ValueError(
                f"load must be 1 to {self.n_steps} finite values [N], one per "
                f"period, got shape {f.shape}"
            )
        return f

    def _checked(self, f: np.ndarray, y: np.ndarray, v: np.ndarray, req: np.ndarray) -> Response:
        k = int(np.argmax(np.abs(y) > self.limit))
        if abs(y[k]) > self.limit:
            raise ValueError(
                f"load: the tip reaches {abs(y[k]) * 1e3:.3g} mm at "
                f"t = {k * self.dt:.4g} s, beyond the env's deflection limit "
                f"({self.limit * 1e3:g} mm); reduce the load"
            )
        return Response(load=f, y=y, voltage=v, requested=req, dt=self.dt)

    def passive(self, load) -> Response:
        """The passive beam (V = 0) under ``load`` (from the unit-pulse response alone)."""
        f = self._check_load(load)
        zeros = np.zeros(f.size)
        return self._checked(f, causal_convolution(f, self.g_y), zeros, zeros)

    def run(self, policy, load) -> Response:
        """``policy`` (SB3 ``predict``, deterministic; a policy with a state, such as
        :class:`baselines.policies.MeasurementFeedback`, gets it back each step as from
        :func:`baselines.evaluation.rollout.rollout`) in the loop under ``load`` (as many periods as
        it has values, at most ``n_steps``)."""
        f = self._check_load(load)
        check_compatible(policy, self.env)
        own, gy = self.own_obs, self.g_y
        of, yf = causal_convolution(f, self.g_obs), causal_convolution(f, gy)
        n = f.size
        y, v, req = np.zeros(n + 1), np.empty(n), np.empty(n)
        obs, _ = self.env.reset(seed=self.seed)
        if hasattr(policy, "start_episode"):  # an oracle (evaluation.rollout.rollout)
            policy.start_episode(self.env)
        dtype = obs.dtype
        state, start = None, np.ones(1, dtype=bool)  # SB3's recurrent-policy protocol
        for k in range(n):
            o = (obs - own[k] + of[k]).astype(dtype)
            action, state = policy.predict(o, state=state, episode_start=start, deterministic=True)
            start = np.zeros(1, dtype=bool)
            obs, _, term, _, info = self.env.step(action)
            if term:
                raise RuntimeError(
                    f"env: the episode ended at step {k + 1} ({info['terminated_by']})"
                )
            y[k + 1] = info["tip_deflection"] - gy[k + 1] + yf[k + 1]
            v[k], req[k] = info["voltage"], info["requested_voltage"]
        return self._checked(f, y, v, req)
