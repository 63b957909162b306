"""``ACLDBeam-v1``: the ACLD cantilever as a Gymnasium environment (``ACLDBeam-v0``: the
legacy variant in :mod:`acld_gym.envs.legacy`).

The class composes the layers below it: :mod:`acld_gym.envs.episode` draws the load and
the plant, :mod:`acld_gym.envs.step` is the algebra of one step, and
:mod:`acld_gym.envs.checks` validates the arguments. Its ``step`` advances plant and
observer, computes the reward and checks the limits, with no physics inline."""

from __future__ import annotations

import math
import os
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from acld_gym.design.observer import MODEL_STD
from acld_gym.envs.checks import check_actions, check_episode_size, configure, episode_spec
from acld_gym.envs.episode import OBS_MODES, SENSOR_NOISE_M, draw_episode, reset_options
from acld_gym.envs.fingerprint import observation_fingerprint
from acld_gym.envs.render import FigureOwner
from acld_gym.envs.step import (
    Y_SCALE,
    StepLayout,
    estimate_map,
    load_schedule,
    observation_size,
    output_matrix,
    reward_of,
    step_matrix,
    termination,
)
from acld_gym.physics.loads import TipLoad, thesis_load
from acld_gym.util.validate import check_seed

if os.environ.get("ACLD_GYM_PURE_PYTHON") == "1":  # debugging: numpy steps only
    StepCore = None
else:
    try:
        from ._stepcore import StepCore
    except ImportError:  # built without a C compiler: the numpy reference step serves
        StepCore = None

#: Whether ``ACLDBeamEnv.step`` runs its common path compiled (``acld_gym.envs._stepcore``).
COMPILED_STEP = StepCore is not None

__all__ = ["ACLDBeamEnv", "COMPILED_STEP"]


class ACLDBeamEnv(FigureOwner, gym.Env):
    """
    ## Description

    Vibration control of a 300 x 15 x 3 mm aluminium cantilever with an active
    constrained layer damping (ACLD) patch (Rodriguez 2006). The agent sets the
    voltage on the piezoelectric constraining layer to suppress the tip
    deflection caused by a tip load. The plant (the "truth model",
    :mod:`acld_gym.physics.truth`) is, by default, the mesh-converged beam: the
    Timoshenko + GHM finite-element model on a 128x refined mesh (2305 DOFs),
    projected onto a 36-state rational Krylov basis that matches its frequency
    responses to 1e-5 up to twice the Nyquist frequency; ``mesh="thesis"`` gives
    the thesis's own 1 + 1 + 3-element model (38 states) instead. It is sampled
    exactly with a zero-order hold on the voltage; the tip load is integrated
    within each period (sub-steps with first-order hold, exact for pulses). The
    observer runs on the nominal reduced model (the design model: 8 states on the
    converged plant, 6 on the thesis mesh), never on
    the (possibly randomized) plant. A step is one fused matrix-vector product
    (:func:`output_matrix`); it runs in C (``acld_gym.envs._stepcore``) when that module
    was built (``COMPILED_STEP``), else in numpy, with the same results.

    ## Action Space

    ``Box(-120, 120, (1,), float32)``: piezo voltage [V], held for one period.
    Out-of-range actions are clipped to +/-120 V and reported in
    ``info["clipped"]``; NaN or inf raise ``ValueError`` and leave the state
    untouched. (Train with ``gymnasium.wrappers.RescaleAction`` for [-1, 1].)

    ## Observation Space

    ``Box(-inf, inf, (n,), float32)``; ``obs_mode`` selects:

    | obs_mode | n | content | scale |
    |---|---|---|---|
    | ``"estimate"`` (default) | 9 (7) | x_r estimate (8; thesis mesh: 6), tip | below; y / 1 mm |
    | ``"measurement"`` | 9 | last 8 tip measurements, last voltage | y / 1 mm; V / 120 V |
    | ``"full"`` | 36 (38) | true plant state [q; dq/dt] (privileged) | see below |

    x_r is the state of the reduced design model in its canonical real modal
    form (:func:`acld_gym.design.reduction.modal_form`): one (cosine, sine)-like pair per
    mode (modes 1-4 in order; 1-3 on the thesis mesh), the same on every machine. Each component is
    divided by its peak magnitude in the passive response to thesis load case 1
    (``Nominal.xr_scale``), so a 1 N x 1 ms pulse gives values of order one (mode 4,
    above the Nyquist frequency, is seen by the 1 kHz Kalman filter at about a tenth).
    ``"full"``: for ``mesh="converged"`` q are the 18 mass-normalized Ritz
    coordinates of the plant [kg^0.5 m] and their rates; for ``mesh="thesis"`` the
    19 FE DOFs (m, rad) and their rates.

    ## Rewards

    ``r = -(y / y_ref)^2 - lam * (V / 120)^2`` per step, with ``y`` the true
    tip deflection [m] at the end of the step and ``V`` the applied voltage.

    ## Starting State

    The beam at rest (all plant states zero), the observer at zero. The load of
    the episode is set by ``load_case`` (or ``reset(options={"load_case": ...})``).

    ## Episode End

    * ``terminated``: |tip deflection| > ``deflection_limit`` (20 mm by
      default, beyond which the linear model is not valid), or a non-finite number
      in the new state or reward; ``info["terminated_by"]`` says which
      (``"deflection_limit"``, ``"non_finite_state"``; None otherwise).
    * ``truncated``: after ``episode_length`` seconds, ``round(episode_length / dt)``
      steps (1 s = 1000 steps by default). ``gym.make`` adds no other limit, and
      ``env.spec.max_episode_steps`` is that step count; ``max_episode_steps=n`` can
      only shorten the episode (a ``TimeLimit`` of n steps).
    * Limits: at most 1,000,000 steps per episode (``checks.MAX_EPISODE_STEPS``) and
      4,000,000 tabulated steps over a vector env's sub-envs (``MAX_TABLE_STEPS``): the
      load and noise of an episode are tabulated at reset (about 350 bytes per step of
      a single env, 350 MB at the limit; 170 bytes per vector sub-env step), so a
      longer episode is refused at construction with a ``ValueError`` instead of
      exhausting memory.

    ## Arguments

    | kwarg | default | meaning |
    |---|---|---|
    | ``load_case`` | 1 | 1, 2, 3 (thesis ch. 5) or ``"random"`` (:func:`random_load`) |
    | ``mesh`` | ``"converged"`` | truth plant: ``"converged"`` or ``"thesis"`` (38 states) |
    | ``dt`` | 1e-3 | control period [s] |
    | ``episode_length`` | 1.0 | episode duration [s] |
    | ``observer`` | ``"kalman"`` | ``"kalman"`` (reduced model, not fed the load) or |
    | | | ``"thesis"`` (full order, fed the load) |
    | ``obs_mode`` | ``"estimate"`` | see Observation Space |
    | ``sensor_noise`` | 1e-7 | tip-sensor noise std [m] (seeded; 0 for none) |
    | ``y_ref`` | 1e-3 | deflection scale of the reward [m] |
    | ``lam`` | 0.01 | voltage weight of the reward |
    | ``param_noise`` | 0.0 | relative std of per-episode parameter randomization, at |
    | | | most 0.1 (``"converged"``) or 0.05 (``"thesis"``); log-normal factors |
    | | | truncated at 3 std |
    | ``deflection_limit`` | 0.02 | termination limit [m] |
    | ``render_mode`` | None | ``"rgb_array"`` or ``"human"`` |

    Load case 3 is the thesis's resonant harmonic, 0.1 sin(179 t) N for 5.5 cycles,
    on every mesh: the thesis tuned it to its model's first resonance (178.6 rad/s);
    the converged beam's is 177.4 rad/s, and over the 0.193 s of the load the 1.6 rad/s
    detuning adds up to 0.31 rad of phase, so the load still pumps the first mode
    (README, "Thesis mesh vs converged plant"). Random loads aim their harmonics at
    the plant's own modes.

    ## Version History

    * v1: the truth plant is the mesh-converged beam (``mesh="converged"``; the thesis
      mesh is ``mesh="thesis"``); the reduced-state estimate is in canonical
      coordinates (real modal form), identical on every machine; random loads aim at
      the plant's own first two modes; the design model has 8 states on the converged
      plant (modes 1-4; 6 on the thesis mesh) and the Kalman filter a model-error noise
      (``model_std`` 0.1), so the baselines stay stable on every randomized plant;
      ``param_noise`` is bounded (0.1; 0.05 on the thesis mesh) and its factors
      truncated at 3 std.
    * v0: the thesis configuration (:mod:`acld_gym.envs.legacy`): the thesis's 38-state
      mesh, its 6-state design model and observers, the same dynamics, reward, spaces
      and episode. It differs from v1 with ``mesh="thesis"`` in three settings only:
      random-load harmonics at 179 and 1115 rad/s (v1: the plant's own 178.64 and
      1115.40), a Kalman filter driven by the load alone (``model_std=0``; v1: 0.1) and
      ``param_noise`` up to 0.5 (v1: 0.05). Since acld-gym 0.3.0 its observation is in
      the same canonical modal basis as v1's, identical on every machine; before, it was
      the Schur method's own coordinates, whose signs changed with the CPU's BLAS kernels
      (up to a sign flip of whole components), so an agent trained on one machine acted
      on other coordinates on another.
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 30}

    #: The id this class is registered under (used when it is built without ``gym.make``).
    env_id = "ACLDBeam-v1"
    #: Harmonic targets of random loads [rad/s]; None: the plant's own first two modes.
    _harmonic_modes: tuple[float, float] | None = None
    #: Model-error noise of the Kalman filter (:func:`acld_gym.design.observer.discrete_kalman`).
    _model_std = MODEL_STD
    #: Bound of ``param_noise`` (None: :data:`PARAM_NOISE_MAX` of the mesh).
    _param_noise_max: float | None = None

    def __init__(self, load_case: int | str = 1, mesh: str = "converged", dt: float = 1e-3,
                 episode_length: float = 1.0, observer: str = "kalman",
                 obs_mode: str = "estimate", sensor_noise: float = SENSOR_NOISE_M,
                 y_ref: float = 1e-3, lam: float = 0.01, param_noise: float = 0.0,
                 deflection_limit: float = 0.02, render_mode: str | None = None):
        configure(self, load_case=load_case, mesh=mesh, dt=dt, episode_length=episode_length,
                  observer=observer, obs_mode=obs_mode, sensor_noise=sensor_noise,
                  y_ref=y_ref, lam=lam, param_noise=param_noise,
                  deflection_limit=deflection_limit, render_mode=render_mode)
        self.max_steps = check_episode_size(self.episode_length, self.dt)
        n_obs = observation_size(self.nom, obs_mode, self.obs_hist)
        self.action_space = spaces.Box(-self.v_max, self.v_max, (1,), np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, (n_obs,), np.float32)
        self._plant = self.nom.plant
        self._obs = self.nom.thesis if observer == "thesis" else self.nom.kalman
        self._est = estimate_map(self._obs, self.nom.xr_scale)
        self._fig = None
        self._reset_state(thesis_load(1) if load_case == "random" else thesis_load(load_case))
        self._core = _NotReset(self._core)  # stepping before reset() raises

    # --- composition of a step ----------------------------------------------
    # The state lives in one buffer z = [x, xhat, y_meas, V, f0, f1, w'] (x and xhat
    # are views into it). One product G z (output_matrix) advances plant and observer
    # and gives the new measurement, the observation and the info's numbers. The step
    # runs in C (acld_gym.envs._stepcore.StepCore) where it can, else in numpy (_step); the
    # core holds the step count, voltage, last measurement and last output for both.
    #: Step in C where it can (``COMPILED_STEP``); set False on an instance to force the
    #: numpy reference step from the next reset on (benchmarks and tests compare the two).
    compiled_step = COMPILED_STEP

    k = property(lambda self: self._core.k, lambda self, val: setattr(self._core, "k", val),
                 doc="Steps taken in the episode.")
    v = property(lambda self: self._core.v, lambda self, val: setattr(self._core, "v", val),
                 doc="Voltage applied in the last step [V].")
    y_meas = property(lambda self: self._core.y_meas,
                      lambda self, val: setattr(self._core, "y_meas", val),
                      doc="Last tip measurement [m].")
    _last = property(lambda self: self._core.last,
                     doc="G z of the last step (:func:`output_matrix`; one buffer).")
    x = property(lambda self: self._z[self._layout.x],
                 doc="True plant state [q; dq/dt] (a view).")
    xhat = property(lambda self: self._z[self._layout.xhat], doc="Observer state (a view).")
    @property
    def spec(self):
        """The registration spec (set by ``gym.make``), with ``max_episode_steps`` the
        episode's own length, ``episode_length / dt`` steps, unless a shorter limit was
        asked for."""
        return getattr(self, "_spec", None)

    @spec.setter
    def spec(self, value) -> None:
        self._spec = episode_spec(value, self.max_steps)

    episode_plant = property(lambda self: self._plant,
                             doc="The sampled plant of this episode (randomized with "
                                 "``param_noise``), a "
                                 ":class:`acld_gym.design.discrete.SampledSystem`.")

    @property
    def observation_fingerprint(self) -> dict:
        """What the observation depends on (:mod:`acld_gym.envs.fingerprint`)."""
        return observation_fingerprint(self)

    def _reset_state(self, load: TipLoad) -> None:
        self.load = load
        self._layout = lay = StepLayout(n=self._plant.Ad.shape[0], k=self._obs.n,
                                        r=self.nom.design.reduced.order,
                                        substeps=self._plant.substeps)
        self._z = np.zeros(lay.z_size)
        self.y_hist = np.zeros(self.obs_hist)
        self.history: list[tuple[float, float, float]] = []
        F, tipf = load_schedule(self.nom.plant, load, 0, self.max_steps)
        self._tipf = np.ascontiguousarray(tipf, dtype=np.float64)
        self._noise = np.zeros(self.max_steps + 1)
        self._inputs = np.hstack([F, self._noise[1:, None]])  # per step: [f0, f1, w']
        self._G = output_matrix(step_matrix(self._plant, self.nom.plant, self._obs), lay,
                                self.nom.output, self.nom.design.reduced.SL, self._est)
        self._core = self._make_core()

    def _make_core(self):
        """The step's core over this episode's arrays (state: at rest)."""
        if not (self.compiled_step and COMPILED_STEP):
            return _NumpyCore(self._G.shape[0])
        core = StepCore(G=self._G, z=self._z, inputs=self._inputs, tipf=self._tipf,
                        y_hist=self.y_hist, **self._layout.core_kwargs(),
                        obs_mode=OBS_MODES.index(self.obs_mode),
                        n_obs=self.observation_space.shape[0], dt=self.dt, y_ref=self.y_ref,
                        lam=self.lam, v_max=self.v_max, limit=self.deflection_limit,
                        y_scale=Y_SCALE)
        core.active = self.render_mode is None  # rendering steps in numpy (draws history)
        return core

    def __getstate__(self):
        state = super().__getstate__()
        c = self._core
        state["_core"] = (c.k, c.v, c.y_meas, c.last)  # the C core does not pickle
        return state

    def __setstate__(self, state):
        k, v, y_meas, last = state.pop("_core")
        self.__dict__.update(state)
        self._core = self._make_core()
        self.k, self.v, self.y_meas = k, v, y_meas
        self._last[:] = last

    def _draw_noise(self) -> None:
        """The episode's sensor noise, drawn at reset (the vector env draws the same)."""
        if self.sensor_noise:
            self._noise = self.np_random.normal(0.0, self.sensor_noise, self.max_steps + 1)
            self._inputs[:, -1] = self._noise[1:]

    def _voltage(self, action) -> tuple[float, float]:
        """(applied, requested) voltage; ``ValueError`` (state untouched) on bad input."""
        if (type(action) is np.ndarray and action.shape == (1,)
                and action.dtype.kind == "f"):  # fast path (SB3, policies)
            requested = float(action[0])
            if math.isfinite(requested):
                return min(max(requested, -self.v_max), self.v_max), requested
        req, v = check_actions(action, 1, self.v_max)
        return float(v[0]), float(req[0])

    def _step_inputs(self, k: int) -> np.ndarray:
        """``[f0, f1, w']`` of period k: tabulated for the episode, computed beyond it."""
        if k < self.max_steps:
            return self._inputs[k]
        f = load_schedule(self.nom.plant, self.load, k, k + 1)[0][0]
        w = self.np_random.normal(0.0, self.sensor_noise) if self.sensor_noise else 0.0
        return np.append(f, w)

    def _observation(self) -> np.ndarray:
        if self.obs_mode == "estimate":
            return self._last[self._layout.out_estimate].astype(np.float32)
        if self.obs_mode == "measurement":
            return np.append(self.y_hist / Y_SCALE, self.v / self.v_max).astype(np.float32)
        return self.x.astype(np.float32)

    def _info(self, requested: float | None = None) -> dict[str, Any]:
        k, lay = self.k, self._layout
        tip_load = float(self._tipf[k]) if k <= self.max_steps else float(self.load(k * self.dt))
        return {"tip_deflection": float(self._last[lay.out_y]), "voltage": self.v,
                "tip_load": tip_load, "time": k * self.dt,
                "xr_true": self._last[lay.out_xr].copy(),
                "clipped": requested is not None and requested != self.v,
                "requested_voltage": self.v if requested is None else requested,
                "terminated_by": None}

    # --- Gymnasium API -------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        case = reset_options(options, self.load_case)  # validated before seeding:
        super().reset(seed=check_seed(seed))  # a rejected reset leaves the RNG as it was
        load, self._plant = draw_episode(self.np_random, case, self.nom, self.episode_length,
                                         self.param_noise, self.harmonic_modes)
        self._reset_state(load)
        self._draw_noise()
        w = float(self._noise[0])  # the beam starts at rest: the first measurement is noise
        lay = self._layout
        self.y_meas = self._z[lay.y_meas] = w
        self.y_hist[-1] = w
        self._last[lay.y_meas] = w
        self._last[lay.out_estimate] = w * np.append(self._est[-1], 1.0 / Y_SCALE)
        return self._observation(), self._info()

    def step(self, action):
        result = self._core.step(action)  # the compiled path; None where it does not apply
        return result if result is not None else self._step(action)

    def _step(self, action):
        """The step in numpy: the reference for :class:`acld_gym.envs._stepcore.StepCore`, and
        the path for actions of other types, bad actions, rendering and steps past the
        tabulated episode."""
        if isinstance(self._core, _NotReset):
            raise RuntimeError("ACLDBeamEnv: call reset() before step()")
        v, requested = self._voltage(action)
        c, z, lay = self._core, self._z, self._layout
        k = c.k
        z[lay.voltage] = v
        z[lay.inputs] = self._step_inputs(k)
        # 1. plant (ZOH) and 2. observer over one period, 3. the new measurement
        out = np.dot(self._G, z, out=c.last)
        z[lay.state] = out[lay.state]
        c.k = k = k + 1
        c.v = v
        c.y_meas = float(out[lay.y_meas])
        y = float(out[lay.out_y])
        if self.obs_mode == "measurement":
            self.y_hist[:-1] = self.y_hist[1:]
            self.y_hist[-1] = c.y_meas
        reward = reward_of(y, v, self.y_ref, self.lam, self.v_max)  # 4. on the true deflection
        why = termination(y, reward, out, self.deflection_limit)  # 5. limits
        terminated = why is not None
        truncated = k >= self.max_steps
        if self.render_mode is not None:  # the history is only drawn, never observed
            self.history.append((k * self.dt, y, v))
            if self.render_mode == "human":
                self.render()
        info = self._info(requested)
        info["terminated_by"] = why
        return self._observation(), reward, terminated, truncated, info

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; pass render_mode= to make()")
            return None
        from acld_gym.envs.render import render_frame

        frame, self._fig = render_frame(self, self._fig)
        if self.render_mode == "human":
            from acld_gym.envs.render import show

            show(self._fig)
            return None
        return frame

    def close(self):
        self._close_figure()


class _NotReset:
    """Stands in for the step's core until the first ``reset()`` (Gymnasium's order)."""

    def __init__(self, core):
        self._inner = core

    def __getattr__(self, name):
        return getattr(self._inner, name)

    def step(self, action):
        raise RuntimeError("ACLDBeamEnv: call reset() before step()")


class _NumpyCore:
    """The state :class:`acld_gym.envs._stepcore.StepCore` keeps, without a compiled step
    (every step goes to ``ACLDBeamEnv._step``)."""

    __slots__ = ("k", "v", "y_meas", "last")

    def __init__(self, m: int):
        self.k, self.v, self.y_meas, self.last = 0, 0.0, 0.0, np.zeros(m)

    def step(self, action) -> None:
        return None
