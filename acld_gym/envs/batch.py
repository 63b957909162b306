"""The one step of ACLDBeam: N beams and their observers advanced together.

:class:`BatchStep` holds the state of N envs in one buffer (rows of ``Z``, slots of
:class:`acld_gym.envs.step.StepLayout`) and advances them all with one product by the
fused matrix (:func:`acld_gym.envs.step.output_matrix`): the single env is its N = 1 case,
the vector env its N = num_envs case. :meth:`BatchStep.advance` is the step in numpy (the
reference); the compiled step (``acld_gym.envs._stepcore.BatchCore``,
:attr:`BatchStep.core`) runs the same step on the same arrays, with the reward and the
termination mirrored from :mod:`acld_gym.envs.step`. Both return the same :class:`StepResult`.

Loads: the compiled step evaluates each env's encoded load (:mod:`acld_gym.envs.loadcode`)
at every step; the numpy step reads the episode's load samples from a table filled at reset
(:func:`acld_gym.envs.step.load_schedule`, when there is no compiled step), or computes
them per step. The sensor noise of an episode is tabulated at reset for both.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from acld_gym.design.discrete import SampledSystem
from acld_gym.envs.checks import check_actions
from acld_gym.envs.compiled import COMPILED_STEP, BatchCore
from acld_gym.envs.config import EnvConfig
from acld_gym.envs.episode import fixed_plant, passive_plant
from acld_gym.envs.loadcode import LoadCodes
from acld_gym.envs.scale import LQRCost, PassiveCost
from acld_gym.envs.step import (
    INFO_KEYS,
    OBS_HIST,
    TERMINATED_BY,
    Y_SCALE,
    StepLayout,
    appended_size,
    estimate_map,
    load_schedule,
    observation_size,
    observed_commands,
    output_matrix,
    rest_output,
    reward_terms,
    termination_codes,
)
from acld_gym.physics.actuator import V_LIMIT
from acld_gym.physics.loads import TipLoad

__all__ = ["BatchStep", "StepResult", "COMPILED_STEP", "WHY"]

#: ``info["terminated_by"]`` by code, as an object array (index it with the codes).
WHY = np.array(TERMINATED_BY, dtype=object)


def _dgemm():
    """scipy's BLAS ``dgemm`` as a capsule for the compiled step (None if unavailable)."""
    try:
        from scipy.linalg.cython_blas import __pyx_capi__  # guarded: None if unavailable
    except ImportError:  # pragma: no cover - scipy is a dependency
        return None
    return __pyx_capi__.get("dgemm")


class StepResult(NamedTuple):
    """One step of N envs: the observations (N, n_obs) float32, the reward and its two terms
    (:func:`acld_gym.envs.step.reward_terms`), the termination codes
    (:data:`acld_gym.envs.step.TERMINATED_BY`), whether the episode's steps are used up, the
    true tip deflection [m], the patch voltage [V] and the tip load [N] at the end of the
    step and the true reduced state (N, r)."""

    obs: np.ndarray
    reward: np.ndarray
    reward_deflection: np.ndarray
    reward_voltage: np.ndarray
    code: np.ndarray
    truncated: np.ndarray
    y: np.ndarray
    voltage: np.ndarray
    tip_load: np.ndarray
    xr: np.ndarray


class BatchStep:
    """The state and the step of N envs of one configuration (module docstring).

    Parameters
    ----------
    config : the envs' configuration (:class:`acld_gym.envs.config.EnvConfig`).
    num_envs : N.
    steps : steps per episode (``config.max_steps``, or fewer for a vector env's
        ``max_episode_steps``).
    compiled : step in C where it was built (:data:`COMPILED_STEP`).
    """

    def __init__(self, config: EnvConfig, num_envs: int, steps: int, compiled: bool = True):
        self.config = c = config
        self.nom = nom = c.nominal()
        self.num_envs = N = int(num_envs)
        self.steps = int(steps)
        self.observer = obs = nom.observer(c.observer)
        self.est = estimate_map(obs, nom.xr_scale)
        self.layout = lay = StepLayout.of(c, nom, obs)
        #: The observation's size: the design's plus the appended entries (the commands in
        #: flight, then log c: :func:`acld_gym.envs.step.appended_size`), the slots of Z of
        #: those commands, and whether a step's result changes after the product (the gate).
        self.n_obs = observation_size(nom, c.obs_mode) + appended_size(c)
        self.command_slots = slice(lay.buffer.start, lay.buffer.start + observed_commands(c))
        self.appends = appended_size(c) > 0 or c.reward_scale is not None
        #: The reward scale c of each env's episode (:mod:`acld_gym.envs.scale`; ones
        #: unless ``reward_scale``): every reward is divided by it.
        self.reward_scale = np.ones(N)
        #: The reward scale's cost on a list of loads (None without ``reward_scale``).
        self.scale_cost = (
            PassiveCost(passive_plant(nom, c), nom.output, self.steps, c.y_ref)
            if c.reward_scale == "passive"
            else LQRCost(c, self.steps, BatchStep)
            if c.reward_scale == "lqr"
            else None
        )
        #: The configuration's plant (the nominal one, shifted to its temperature, with its
        #: amplifier); an episode's own when drawn (param_noise, temperature_range).
        self.base_plant = fixed_plant(nom, c)
        #: G^T of the base plant (shared) and, with per-episode plants, per env (N, nz, m).
        self.GT = np.ascontiguousarray(self.fused_matrix(self.base_plant).T)
        self.GT_env = np.repeat(self.GT[None], N, axis=0) if c.randomized else None
        self.Z = np.zeros((N, lay.z_size))
        self.OUT = np.zeros((N, lay.out_size))
        self.k = np.zeros(N, dtype=np.int64)
        self.noise = np.zeros((N, self.steps + 1))
        self.y_hist = np.zeros((N, OBS_HIST))
        self.loads: list[TipLoad | None] = [None] * N
        self.plants: list[SampledSystem] = [self.base_plant] * N
        self.codes = LoadCodes(N)
        self.times = np.ascontiguousarray(nom.plant.times)
        self.compiled = bool(compiled and COMPILED_STEP)
        # The numpy step's load table (without a compiled step): per env (steps, 2 s) samples
        # and (steps + 1) tip loads.
        self.tables = (
            None
            if self.compiled
            else (np.zeros((N, self.steps, 2 * lay.substeps)), np.zeros((N, self.steps + 1)))
        )
        self.core = None
        self._make_core()

    # --- construction ---------------------------------------------------------------------
    def fused_matrix(self, plant: SampledSystem) -> np.ndarray:
        """The whole step's matrix G for ``plant`` (the observer keeps the nominal design)."""
        return output_matrix(
            plant,
            self.nom.plant,
            self.observer,
            self.layout,
            self.nom.output,
            self.nom.design.reduced.SL,
            self.est,
        )

    def _make_core(self) -> None:
        if not self.compiled:
            self.core = None
            return
        c = self.config
        self._codes_version = self.codes.version
        self.core = BatchCore(
            GT=self.GT if self.GT_env is None else self.GT_env,
            Z=self.Z,
            OUT=self.OUT,
            k=self.k,
            noise=self.noise,
            y_hist=self.y_hist,
            comp=self.codes.comp,
            ncomp=self.codes.ncomp,
            pool=self.codes.pool,
            times=self.times,
            **self.layout.core_kwargs(),
            obs_mode=("estimate", "measurement", "full").index(c.obs_mode),
            n_obs=self.n_obs - appended_size(c),
            dt=c.dt,
            y_ref=c.y_ref,
            lam=c.lam,
            v_max=V_LIMIT,
            limit=c.deflection_limit,
            y_scale=Y_SCALE,
            slew_step=c.slew_step or 0.0,
            dgemm=_dgemm(),
        )

    def __getstate__(self):
        state = self.__dict__.copy()
        state["core"] = None  # the compiled core does not pickle; rebuilt over the arrays
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._make_core()

    # --- episodes -------------------------------------------------------------------------
    def start_episodes(self, rows, loads, plants, noise: np.ndarray | None = None) -> None:
        """Start new episodes of the envs ``rows``: at rest, with the tip loads ``loads``,
        the sampled plants ``plants`` (None: :attr:`base_plant`; else drawn) and the sensor
        noise ``noise`` (len(rows), steps + 1) [m] (its first value is the first
        measurement; None: already in :attr:`noise`'s rows)."""
        rows = np.asarray(rows, dtype=np.intp)
        lay, nom = self.layout, self.nom
        for j, i in enumerate(rows.tolist()):
            load, plant = loads[j], plants[j]
            plant = self.base_plant if plant is None else plant
            self.loads[i] = load
            if self.compiled:
                self.codes.set(i, load)
            else:
                self.tables[0][i], self.tables[1][i] = load_schedule(nom.plant, load, 0, self.steps)
            if self.GT_env is not None:
                self.GT_env[i] = (
                    self.fused_matrix(plant).T if plant is not self.base_plant else self.GT
                )
            self.plants[i] = plant
        if self.scale_cost is not None:
            self.reward_scale[rows] = self.scale_cost([loads[j] for j in range(len(rows))])
        if self.compiled and self.codes.version != self._codes_version:
            self.core.set_loads(self.codes.comp, self.codes.ncomp, self.codes.pool)
            self._codes_version = self.codes.version
        if noise is not None:
            self.noise[rows] = noise
        w = self.noise[rows, 0]
        self.Z[rows] = 0.0
        self.Z[rows, lay.y_meas] = w
        self.y_hist[rows] = 0.0
        self.y_hist[rows, -1] = w
        self.k[rows] = 0
        self.OUT[rows] = rest_output(lay, self.est, 1.0)[None] * w[:, None]

    # --- the step -------------------------------------------------------------------------
    def vector_step(self, actions):
        """Gymnasium's vector 5-tuple of a step of every env with ``actions`` (N,) or (N, 1)
        [V], ``info`` with the keys of :data:`acld_gym.envs.step.INFO_KEYS` and their masks:
        compiled if it can, else :meth:`advance`. Bad actions raise ``ValueError`` before
        anything changes (:func:`acld_gym.envs.checks.check_actions`)."""
        core = self.core
        if core is not None:
            res = core.step(actions)  # None unless finite float32/float64 of the right shape
            if res is not None:
                return self.scaled(res)
        requested, v = check_actions(actions, self.num_envs, V_LIMIT, vector=True)
        if core is not None:  # the checked, clipped voltages step compiled
            res = core.step(v)
            res[4]["requested_voltage"] = requested
            res[4]["clipped"] = requested != v
            return self.scaled(res)
        r = self.advance(v)
        values = (
            r.y,
            r.voltage,
            requested,
            requested != v,
            r.tip_load,
            self.k * self.config.dt,
            r.xr,
            WHY[r.code],
            r.reward_deflection,
            r.reward_voltage,
        )
        ones = np.ones(self.num_envs, dtype=bool)
        info = {}
        for key, val in zip(INFO_KEYS, values, strict=True):
            info[key] = val
            info["_" + key] = ones
        self.scale_info(info)
        return r.obs, r.reward, r.code != 0, r.truncated, info

    # --- the appended entries and the reward scale (acld_gym.envs.scale) -------------------
    def scaled(self, res):
        """A compiled vector step's 5-tuple with the options applied (:meth:`_append`, the
        reward divided by :attr:`reward_scale`, its info)."""
        if not self.appends:
            return res
        obs, reward, terminated, truncated, info = res
        self.scale_info(info)
        return self._append(obs), reward / self.reward_scale, terminated, truncated, info

    def scaled_one(self, res):
        """:meth:`scaled` for the compiled ``step_one`` of env 0 (None stays None)."""
        if res is None or not self.appends:
            return res
        obs, reward, terminated, truncated, info = res
        s = float(self.reward_scale[0])
        if self.scale_cost is not None:
            info["reward_scale"] = s
        return self._append(obs[None], [0])[0], reward / s, terminated, truncated, info

    def scale_info(self, info: dict, rows=None) -> None:
        """Add ``info["reward_scale"]`` and its mask (``rows``, default all) to a vector info."""
        if self.scale_cost is not None:
            s = self.reward_scale if rows is None else self.reward_scale[rows]
            info["reward_scale"] = s.copy()
            info["_reward_scale"] = np.ones(s.shape, dtype=bool)

    def _append(self, obs: np.ndarray, rows=None) -> np.ndarray:
        """The observations ``obs`` of ``rows`` (default all) with the appended entries."""
        rows = slice(None) if rows is None else rows
        slots = self.command_slots
        extra = [self.Z[rows, slots] / V_LIMIT] if slots.stop > slots.start else []
        if self.config.observe_reward_scale:
            extra.append(np.log(self.reward_scale[rows])[:, None])
        return np.concatenate([obs, *extra], axis=-1, dtype=np.float32) if extra else obs

    def advance(self, v: np.ndarray, inputs: np.ndarray | None = None) -> StepResult:
        """The step in numpy (the reference of the compiled one): voltages ``v`` (N,) [V]
        and, if given, the period's inputs ``[f0, f1, w']`` (N, 2 s + 1) instead of the
        episode's (a single env past its tabulated episode)."""
        Z, lay, c = self.Z, self.layout, self.config
        Z[:, lay.voltage] = v
        Z[:, lay.inputs] = self._inputs() if inputs is None else inputs
        if lay.slew:  # the amplifier moves from its last output towards the command, at most
            held = Z[:, lay.held]  # slew_step per period
            Z[:, lay.amplifier] = held + np.clip(
                Z[:, lay.command] - held, -c.slew_step, c.slew_step
            )
        if self.GT_env is None:
            np.matmul(Z, self.GT, out=self.OUT)
        else:
            np.matmul(Z[:, None, :], self.GT_env, out=self.OUT[:, None, :])
        Z[:, lay.state] = self.OUT[:, lay.state]
        self.k += 1
        if self.config.obs_mode == "measurement":
            self.y_hist[:, :-1] = self.y_hist[:, 1:]
            self.y_hist[:, -1] = self.OUT[:, lay.y_meas]
        y = self.OUT[:, lay.out_y].copy()
        volts = v if lay.out_voltage is None else self.OUT[:, lay.out_voltage].copy()
        reward, r_y, r_v = reward_terms(y, volts, c.y_ref, c.lam, V_LIMIT)
        if self.scale_cost is not None:
            reward = reward / self.reward_scale
        return StepResult(
            obs=self.observations(),
            reward=reward,
            reward_deflection=r_y,
            reward_voltage=r_v,
            code=termination_codes(y, reward, self.OUT, c.deflection_limit),
            truncated=self.k >= self.steps,
            y=y,
            voltage=volts,
            tip_load=self.tip_loads(),
            xr=self.OUT[:, lay.out_xr].copy(),
        )

    def _inputs(self) -> np.ndarray:
        """``[f0, f1, w']`` of every env's current period (loads from the table, or computed)."""
        idx, k, s = np.arange(self.num_envs), self.k, self.layout.substeps
        out = np.empty((self.num_envs, 2 * s + 1))
        if self.tables is not None:
            out[:, :-1] = self.tables[0][idx, np.minimum(k, self.steps - 1)]
        else:
            for i in range(self.num_envs):
                out[i, :-1] = load_schedule(
                    self.nom.plant, self.loads[i], int(k[i]), int(k[i]) + 1
                )[0][0]
        out[:, -1] = self.noise[idx, np.minimum(k + 1, self.steps)]
        return out

    # --- what the envs read ---------------------------------------------------------------
    def observations(self, rows=None) -> np.ndarray:
        """The observations of ``rows`` (default all) from the current state, float32."""
        rows = slice(None) if rows is None else rows
        lay, mode = self.layout, self.config.obs_mode
        if mode == "estimate":
            out = self.OUT[rows, lay.out_estimate]
        elif mode == "measurement":
            out = np.concatenate(
                [self.y_hist[rows] / Y_SCALE, self.Z[rows, lay.voltage, None] / V_LIMIT], axis=-1
            )
        else:
            out = self.Z[rows, lay.x]
        return self._append(out.astype(np.float32), rows)

    def tip_loads(self, rows=None) -> np.ndarray:
        """The tip load [N] of ``rows`` (default all) at their current time ``k dt``."""
        rows = np.arange(self.num_envs) if rows is None else np.asarray(rows, dtype=np.intp)
        if self.core is not None:
            return self.core.tip_loads(rows)
        k = self.k[rows]
        if self.tables is not None and np.all(k <= self.steps):
            return self.tables[1][rows, k]
        return np.array(
            [
                float(self.loads[i](k_i * self.config.dt))
                for i, k_i in zip(rows.tolist(), k.tolist(), strict=True)
            ]
        )
