"""ACLDBeam as a native batched :class:`gymnasium.vector.VectorEnv`.

``gym.make_vec("ACLDBeam-v1", num_envs=N)`` builds :class:`ACLDBeamVectorEnv`
(the spec's ``vector_entry_point``; gymnasium picks it by default when the spec
has one, ``vectorization_mode="sync"`` still gives N single envs). All N beams
and observers advance in one matrix product per step: the same batched step
(:mod:`acld_gym.envs.batch`) as :class:`acld_gym.envs.beam_env.ACLDBeamEnv`, which is its
N = 1 case, so per env the semantics are the single env's (equal trajectories up to
floating-point rounding) and the info has the same keys.

Randomness: sub-env i has its own generator, seeded ``seed + i`` by
``reset(seed=seed)`` as gymnasium seeds the sub-envs of a sync vector env, and
draws in the single env's order (load, parameters, sensor noise). The sensor
noise of a whole episode is drawn at its reset (same numbers as the single
env's); after an episode that terminates early the generator is therefore further
along than a single env's.

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

from acld_gym.envs.batch import COMPILED_STEP, WHY, BatchStep
from acld_gym.envs.checks import check_render_mode
from acld_gym.envs.config import (
    ConfigAttributes,
    EnvConfig,
    check_episode_size,
    make_config,
)
from acld_gym.envs.conflicts import check_case, check_limit, made_spec
from acld_gym.envs.episode import draw_episode, draw_noise, reset_options
from acld_gym.envs.render import FigureOwner, render_frame
from acld_gym.envs.step import INFO_KEYS
from acld_gym.physics.actuator import V_LIMIT
from acld_gym.physics.loads import case_load, thesis_load
from acld_gym.util.validate import check_int, check_seed

__all__ = ["ACLDBeamVectorEnv", "INFO_KEYS"]


class ACLDBeamVectorEnv(ConfigAttributes, FigureOwner, VectorEnv):
    """N independent ACLD beams (see :class:`acld_gym.envs.beam_env.ACLDBeamEnv` for the
    physics, spaces, reward and the configuration: ``config=`` or its fields as keywords).

    ``max_episode_steps`` truncates episodes earlier than their ``episode_length / dt``
    steps (as ``TimeLimit`` does for the single env; a later limit is refused).
    ``info`` holds the single env's keys (:data:`acld_gym.envs.step.INFO_KEYS`) as arrays,
    with their ``_key`` masks. ``render()`` draws sub-env 0 (``render_mode="rgb_array"``).
    """

    metadata = {
        "render_modes": ["rgb_array"],
        "render_fps": 30,
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    #: Step in C where it can (``COMPILED_STEP``); set False on an instance to force the
    #: numpy reference step from the next reset on (benchmarks and tests compare the two).
    compiled_step = COMPILED_STEP

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int | None = None,
        config: EnvConfig | None = None,
        render_mode: str | None = None,
        **kwargs,
    ):
        num_envs = check_int("num_envs", num_envs, 1)
        self.config = c = make_config(config, **kwargs)
        check_episode_size(c.episode_length, c.dt, num_envs)
        check_render_mode(render_mode, self.metadata["render_modes"])
        steps = c.max_steps
        if max_episode_steps is not None:
            steps = check_limit(max_episode_steps, steps)
        self.render_mode = render_mode
        self.num_envs = num_envs
        self.max_episode_steps = max_episode_steps
        self.horizon = steps
        self.nom = c.nominal()
        self.harmonic_modes = c.harmonic_targets(self.nom)
        self._batch = BatchStep(c, num_envs, steps, self.compiled_step)
        n_obs = self._batch.n_obs
        self.single_action_space = spaces.Box(-V_LIMIT, V_LIMIT, (1,), np.float32)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.single_observation_space = spaces.Box(-np.inf, np.inf, (n_obs,), np.float32)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._default_case = c.load_case
        self._prev_done = np.zeros(num_envs, dtype=bool)
        self._rngs: list[np.random.Generator] = [
            seeding.np_random(None)[0] for _ in range(num_envs)
        ]
        load = case_load(c.load_case) or thesis_load(1)
        self._batch.start_episodes(
            np.arange(num_envs),
            [load] * num_envs,
            [None] * num_envs,
            np.zeros((num_envs, steps + 1)),
        )
        self._fig = None
        self._needs_reset = True

    @property
    def load_case(self):
        """The load case of the next resets (settable: SB3's ``set_attr``)."""
        return self._default_case

    @load_case.setter
    def load_case(self, value) -> None:
        self._default_case = check_case(value, self.dt)

    @property
    def batch(self) -> BatchStep:
        """The batched step of the sub-envs (:class:`acld_gym.envs.batch.BatchStep`)."""
        return self._batch

    @property
    def x(self) -> np.ndarray:
        """The sub-envs' true plant states [q; dq/dt] (a view, one row each)."""
        return self._batch.Z[:, self._batch.layout.x]

    @property
    def needs_reset(self) -> bool:
        """True until the first ``reset()``."""
        return self._needs_reset

    @property
    def spec(self):
        """The registration spec with ``max_episode_steps`` the episode's step count
        (see :func:`acld_gym.envs.conflicts.made_spec`)."""
        return getattr(self, "_spec", None)

    @spec.setter
    def spec(self, value) -> None:
        self._spec = made_spec(value, self.config, self.horizon)

    @property
    def loads(self) -> list:
        """The tip load of each sub-env's episode."""
        return list(self._batch.loads)

    # --- episodes -------------------------------------------------------------------------
    def _start(self, rows: np.ndarray, case) -> None:
        """New episodes of the sub-envs ``rows``, each drawn from its own generator (same
        draws as the single env's)."""
        c, nom, noise = self.config, self.nom, self._batch.noise
        loads, plants = [], []
        for i in rows.tolist():
            rng = self._rngs[i]
            load, plant = draw_episode(rng, case, nom, c, self.harmonic_modes)
            loads.append(load)
            plants.append(plant)
            if c.sensor_noise:
                draw_noise(rng, c.sensor_noise, out=noise[i])
        if not c.sensor_noise:
            noise[rows] = 0.0
        self._batch.start_episodes(rows, loads, plants)

    def _reset_infos(self) -> dict[str, Any]:
        """The info of a reset of every sub-env (:data:`INFO_KEYS`, their masks)."""
        N, b = self.num_envs, self._batch
        ones = np.ones(N, dtype=bool)
        vals = (
            np.zeros(N),
            np.zeros(N),
            np.zeros(N),
            np.zeros(N, dtype=bool),
            b.tip_loads(),
            np.zeros(N),
            np.zeros((N, self.nom.design.reduced.order)),
            WHY[np.zeros(N, int)],
            np.zeros(N),
            np.zeros(N),
        )
        info: dict[str, Any] = {}
        for key, val in zip(INFO_KEYS, vals, strict=True):
            info[key] = val
            info["_" + key] = ones
        b.scale_info(info)
        return info

    # --- Gymnasium API --------------------------------------------------------------------
    def reset(self, *, seed: int | list[int | None] | None = None, options: dict | None = None):
        N = self.num_envs
        case = reset_options(options, self._default_case, self.dt)  # checked before seeding
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
        if self._batch.compiled != (self.compiled_step and COMPILED_STEP):
            self._batch = BatchStep(self.config, N, self.horizon, self.compiled_step)
        self._start(np.arange(N), case)
        self._prev_done[:] = False
        self._needs_reset = False
        return self._batch.observations(), self._reset_infos()

    def step(self, actions):
        if self._needs_reset:
            raise RuntimeError("ACLDBeamVectorEnv: call reset() before step()")
        obs, reward, terminated, truncated, info = self._batch.vector_step(actions)
        reset = self._prev_done
        if reset.any():  # NEXT_STEP autoreset: these sub-envs ignore their action
            rows = np.flatnonzero(reset)
            self._start(rows, self._default_case)
            self._patch_reset(rows, obs, reward, terminated, truncated, info)
        self._prev_done = terminated | truncated
        return obs, reward, terminated, truncated, info

    def _patch_reset(self, rows, obs, reward, terminated, truncated, info) -> None:
        """The results of the sub-envs ``rows`` just reset: their reset observation and info,
        reward 0, both flags False."""
        b = self._batch
        obs[rows] = b.observations(rows)
        reward[rows] = 0.0
        terminated[rows] = truncated[rows] = False
        for key in (
            "tip_deflection",
            "voltage",
            "requested_voltage",
            "clipped",
            "time",
            "xr_true",
            "reward_deflection",
            "reward_voltage",
        ):
            info[key][rows] = 0
        info["tip_load"][rows] = b.tip_loads(rows)
        info["terminated_by"][rows] = None
        if "reward_scale" in info:  # the new episode's scale
            info["reward_scale"][rows] = b.reward_scale[rows]

    def reset_done(self, indices) -> np.ndarray:
        """Reset the sub-envs ``indices`` now (each from its own generator, with the env's
        load case) and return the whole batch's observation: the same-step autoreset of
        SB3 (:class:`acld_gym.envs.sb3.SB3VecEnv`) instead of the NEXT_STEP one."""
        idx = np.atleast_1d(np.asarray(indices, dtype=np.intp))
        if idx.size and (idx.min() < 0 or idx.max() >= self.num_envs):
            raise ValueError(f"indices must be in [0, {self.num_envs}), got {idx.tolist()}")
        self._start(idx, self._default_case)
        self._prev_done[idx] = False
        return self._batch.observations()

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; pass render_mode= to make_vec()")
            return None
        frame, self._fig = render_frame(_EnvView(self, 0), self._fig)
        return frame

    def close_extras(self, **kwargs):
        self._close_figure()


class _EnvView:
    """Sub-env i seen as a single env by :func:`acld_gym.envs.render.render_frame`."""

    def __init__(self, venv: ACLDBeamVectorEnv, i: int):
        b = venv._batch
        self.nom = venv.nom
        self.render_mode = venv.render_mode
        self.x = b.Z[i, b.layout.x]
        self.v = float(b.Z[i, b.layout.voltage])
        self.k = int(b.k[i])
        self.dt = venv.dt
        self.load = b.loads[i]
        self.v_max = venv.v_max
        self.deflection_limit = venv.deflection_limit
        self.history: list = []
