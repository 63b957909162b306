"""``ACLDBeam-v0`` as a native batched :class:`gymnasium.vector.VectorEnv`.

``gym.make_vec("ACLDBeam-v0", num_envs=N)`` builds :class:`ACLDBeamVectorEnv`
(the spec's ``vector_entry_point``; gymnasium picks it by default when the spec
has one, ``vectorization_mode="sync"`` still gives N single envs). All N beams
and observers advance in one matrix product per step; per env the semantics
are those of :class:`acld_gym.envs.beam_env.ACLDBeamEnv` (same shared building blocks,
equal trajectories up to floating-point rounding).

Randomness: sub-env i has its own generator, seeded ``seed + i`` by
``reset(seed=seed)`` as gymnasium seeds the sub-envs of a sync vector env, and
draws in the single env's order (load, parameters, sensor noise). The sensor
noise of a whole episode is drawn at its reset (same numbers as the single
env's per-step draws); after an episode that terminates early the generator
is therefore further along than a single env's.

Autoreset is ``NEXT_STEP`` (like ``CartPoleVectorEnv``): the step after a
sub-env terminated or truncated resets it, ignores its action and returns its
reset observation with reward 0 and both flags False.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from acld_gym.design.observer import MODEL_STD
from acld_gym.envs.checks import check_actions, configure, episode_spec
from acld_gym.envs.episode import SENSOR_NOISE_M, draw_episode, reset_options
from acld_gym.envs.render import FigureOwner
from acld_gym.envs.step import (
    Y_SCALE,
    StepLayout,
    estimate_map,
    load_schedule,
    observation_size,
    reward_of,
    step_matrix,
)
from acld_gym.physics.loads import thesis_load
from acld_gym.util.validate import check_int, check_seed

__all__ = ["ACLDBeamVectorEnv"]

INFO_KEYS = ("tip_deflection", "voltage", "tip_load", "time", "clipped", "terminated_by")


class ACLDBeamVectorEnv(FigureOwner, VectorEnv):
    """N independent ACLD beams (see :class:`acld_gym.envs.beam_env.ACLDBeamEnv` for the
    physics, spaces, reward and keyword arguments).

    ``max_episode_steps`` truncates episodes (as ``TimeLimit`` does for the single
    env); the episode also ends after ``episode_length / dt`` steps.
    ``info`` holds arrays ``tip_deflection``, ``voltage``, ``tip_load``, ``time``,
    ``clipped`` and their ``_key`` masks. ``render()`` draws sub-env 0
    (``render_mode="rgb_array"``).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30,
                "autoreset_mode": AutoresetMode.NEXT_STEP}

    env_id = "ACLDBeam-v1"  # see ACLDBeamEnv
    _harmonic_modes: tuple[float, float] | None = None
    _model_std = MODEL_STD
    _param_noise_max: float | None = None

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = None,
                 load_case: int | str = 1, mesh: str = "converged", dt: float = 1e-3,
                 episode_length: float = 1.0,
                 observer: str = "kalman", obs_mode: str = "estimate",
                 sensor_noise: float = SENSOR_NOISE_M, y_ref: float = 1e-3, lam: float = 0.01,
                 param_noise: float = 0.0, deflection_limit: float = 0.02,
                 render_mode: str | None = None):
        num_envs = check_int("num_envs", num_envs, 1)
        configure(self, num_envs=num_envs, load_case=load_case, mesh=mesh, dt=dt,
                  episode_length=episode_length,
                  observer=observer, obs_mode=obs_mode, sensor_noise=sensor_noise,
                  y_ref=y_ref, lam=lam, param_noise=param_noise,
                  deflection_limit=deflection_limit, render_mode=render_mode)
        steps = int(round(self.episode_length / self.dt))
        if max_episode_steps is not None:
            steps = min(steps, check_int("max_episode_steps", max_episode_steps, 1))
        self.num_envs = int(num_envs)
        self.max_episode_steps = max_episode_steps
        self.horizon = steps
        self._obs = self.nom.thesis if observer == "thesis" else self.nom.kalman
        self._est = estimate_map(self._obs, self.nom.xr_scale)
        self._out = self.nom.output  # tip deflection = plant state @ _out
        n_obs = observation_size(self.nom, obs_mode, self.obs_hist)
        self.single_action_space = spaces.Box(-self.v_max, self.v_max, (1,), np.float32)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.single_observation_space = spaces.Box(-np.inf, np.inf, (n_obs,), np.float32)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)

        N = self.num_envs
        self._layout = lay = StepLayout(n=self.nom.plant.Ad.shape[0], k=self._obs.n,
                                        r=self.nom.design.reduced.order,
                                        substeps=self.nom.plant.substeps)
        self._S_nom = step_matrix(self.nom.plant, self.nom.plant, self._obs)
        self._ST = np.ascontiguousarray(self._S_nom.T)
        # Per-env step matrices only with parameter noise (batched einsum).
        self._S = (np.repeat(self._S_nom[None], N, axis=0) if self.param_noise > 0 else None)
        # Z: the layout's z without the noise slot; the step is Z[:, x + xhat] = Z @ S.T.
        self._Z = np.zeros((N, lay.noise))
        self._adv = slice(0, lay.k + lay.n)  # what S advances (y_meas is set separately)
        # Load tables: rows 0..2 thesis cases 1..3, rows 3.. one per sub-env (random loads).
        self._pool_F = np.zeros((3, steps, 2 * self.nom.plant.substeps))
        self._pool_tip = np.zeros((3, steps + 1))
        for c in (1, 2, 3):
            self._pool_F[c - 1], self._pool_tip[c - 1] = load_schedule(
                self.nom.plant, thesis_load(c), 0, steps)
        if load_case == "random":
            self._grow_pool()
        self._slot = np.zeros(N, dtype=np.intp)
        self._steps = np.zeros(N, dtype=np.intp)
        self._noise = np.zeros((N, steps + 1))
        self._y_hist = np.zeros((N, self.obs_hist))
        self._clipped = np.zeros(N, dtype=bool)
        self._why = np.full(N, None, dtype=object)  # info["terminated_by"]
        self._prev_done = np.zeros(N, dtype=bool)
        self._idx = np.arange(N)
        self._rngs: list[np.random.Generator] = [seeding.np_random(None)[0] for _ in range(N)]
        self._loads: list = [thesis_load(1)] * N
        self._fig = None
        self._needs_reset = True

    @property
    def spec(self):
        """The registration spec with ``max_episode_steps`` the episode's step count
        (see :func:`acld_gym.envs.checks.episode_spec`)."""
        return getattr(self, "_spec", None)

    @spec.setter
    def spec(self, value) -> None:
        self._spec = episode_spec(value, self.horizon)

    # --- helpers -------------------------------------------------------------
    def _grow_pool(self) -> None:
        if self._pool_F.shape[0] == 3:
            N = self.num_envs
            self._pool_F = np.concatenate(
                [self._pool_F, np.zeros((N,) + self._pool_F.shape[1:])])
            self._pool_tip = np.concatenate(
                [self._pool_tip, np.zeros((N, self._pool_tip.shape[1]))])

    def _reset_env(self, i: int, case) -> None:
        """Reset sub-env i from its own generator (same draws as the single env)."""
        rng = self._rngs[i]
        load, plant = draw_episode(rng, case, self.nom, self.episode_length, self.param_noise,
                                   self.harmonic_modes)
        self._loads[i] = load
        if case == "random":
            self._grow_pool()
            slot = 3 + i
            self._pool_F[slot], self._pool_tip[slot] = load_schedule(
                self.nom.plant, load, 0, self.horizon)
        else:
            slot = case - 1
        self._slot[i] = slot
        if self._S is not None:
            self._S[i] = step_matrix(plant, self.nom.plant, self._obs)
        self._steps[i] = 0
        if self.sensor_noise:
            self._noise[i] = rng.normal(0.0, self.sensor_noise, self.horizon + 1)
        self._Z[i] = 0.0
        y = self._noise[i, 0]
        self._Z[i, self._layout.y_meas] = y
        self._y_hist[i] = 0.0
        self._y_hist[i, -1] = y
        self._clipped[i] = False
        self._why[i] = None

    def _observations(self) -> np.ndarray:
        Z, lay = self._Z, self._layout
        y = Z[:, lay.y_meas]
        if self.obs_mode == "estimate":
            out = np.empty((self.num_envs, self._est.shape[1] + 1))
            np.matmul(Z[:, lay.xhat.start:lay.y_meas + 1], self._est, out=out[:, :-1])
            out[:, -1] = y / Y_SCALE
        elif self.obs_mode == "measurement":
            out = np.empty((self.num_envs, self.obs_hist + 1))
            out[:, :-1] = self._y_hist / Y_SCALE
            out[:, -1] = Z[:, lay.voltage] / self.v_max
        else:
            out = Z[:, lay.x]
        return out.astype(np.float32)

    def _infos(self) -> dict[str, Any]:
        N = self.num_envs
        ones = np.ones(N, dtype=bool)
        vals = {"tip_deflection": self._Z[:, self._layout.x] @ self._out,
                "voltage": self._Z[:, self._layout.voltage].copy(),
                "tip_load": self._pool_tip[self._slot, self._steps],
                "time": self._steps * self.dt,
                "clipped": self._clipped.copy(),
                "terminated_by": self._why.copy()}
        info: dict[str, Any] = {}
        for key in INFO_KEYS:
            info[key] = vals[key]
            info["_" + key] = ones
        return info

    # --- Gymnasium API -------------------------------------------------------
    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict | None = None):
        N = self.num_envs
        case = reset_options(options, self.load_case)  # validated before any seeding
        if seed is None or isinstance(seed, (list, tuple, np.ndarray)):
            seeds = None if seed is None else [check_seed(s) for s in seed]
            if seeds is not None and len(seeds) != N:
                raise ValueError(f"seed: expected an int or {N} seeds, got {len(seeds)}")
            first = None
        else:
            first = check_seed(seed)
            seeds = [first + i for i in range(N)]
        super().reset(seed=first)
        if seeds is not None:
            self._rngs = [seeding.np_random(s)[0] for s in seeds]
        for i in range(N):
            self._reset_env(i, case)
        self._prev_done[:] = False
        self._needs_reset = False
        return self._observations(), self._infos()

    def step(self, actions):
        if self._needs_reset:
            raise RuntimeError("ACLDBeamVectorEnv: call reset() before step()")
        requested, v = check_actions(actions, self.num_envs, self.v_max, vector=True)
        Z, lay, idx = self._Z, self._layout, self._idx
        reset = self._prev_done
        Z[:, lay.voltage] = v
        Z[:, lay.loads] = self._pool_F[self._slot, np.minimum(self._steps, self.horizon - 1)]
        if self._S is None:
            Z[:, self._adv] = Z @ self._ST
        else:
            Z[:, self._adv] = np.einsum("nij,nj->ni", self._S, Z)
        self._steps += 1
        y_true = Z[:, lay.x] @ self._out
        y = y_true + self._noise[idx, np.minimum(self._steps, self.horizon)]
        Z[:, lay.y_meas] = y
        self._y_hist[:, :-1] = self._y_hist[:, 1:]
        self._y_hist[:, -1] = y
        self._clipped = requested != v
        rewards = reward_of(y_true, v, self.y_ref, self.lam, self.v_max)
        truncated = self._steps >= self.horizon
        if reset.any():  # NEXT_STEP autoreset: these sub-envs ignore their action
            for i in np.flatnonzero(reset):
                self._reset_env(int(i), self.load_case)
            rewards[reset] = 0.0
            truncated[reset] = False
        obs = self._observations()
        # Limits: the deflection, and any non-finite reward or observation (a NaN in the
        # plant reaches the tip, hence the reward, within a step) -- never a normal step.
        finite = np.isfinite(rewards) & np.isfinite(obs).all(axis=1)
        over = ~(np.abs(y_true) <= self.deflection_limit) & ~reset
        terminated = over | ~finite
        self._why[:] = None
        self._why[over] = "deflection_limit"
        self._why[~finite] = "non_finite_state"
        self._prev_done = terminated | truncated
        return obs, rewards, terminated, truncated, self._infos()

    def reset_done(self, indices) -> np.ndarray:
        """Reset the sub-envs ``indices`` now (each from its own generator, with the env's
        load case) and return the whole batch's observation: the same-step autoreset of
        SB3 (:class:`acld_gym.sb3.SB3VecEnv`) instead of the NEXT_STEP one."""
        idx = np.atleast_1d(np.asarray(indices, dtype=np.intp))
        if idx.size and (idx.min() < 0 or idx.max() >= self.num_envs):
            raise ValueError(f"indices must be in [0, {self.num_envs}), got {idx.tolist()}")
        for i in idx:
            self._reset_env(int(i), self.load_case)
        self._prev_done[idx] = False
        return self._observations()

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; pass render_mode= to "
                            "make_vec()")
            return None
        from acld_gym.envs.render import render_frame

        frame, self._fig = render_frame(_EnvView(self, 0), self._fig)
        return frame

    def close_extras(self, **kwargs):
        self._close_figure()


class _EnvView:
    """Sub-env i seen as a single env by :func:`acld_gym.envs.render.render_frame`."""

    def __init__(self, venv: ACLDBeamVectorEnv, i: int):
        self.nom = venv.nom
        self.render_mode = venv.render_mode
        self.x = venv._Z[i, venv._layout.x]
        self.v = float(venv._Z[i, venv._layout.voltage])
        self.k = int(venv._steps[i])
        self.dt = venv.dt
        self.load = venv._loads[i]
        self.v_max = venv.v_max
        self.deflection_limit = venv.deflection_limit
        self.history: list = []


