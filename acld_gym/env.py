"""``ACLDBeam-v1``: the ACLD cantilever as a Gymnasium environment (``ACLDBeam-v0``: the
legacy variant in :mod:`acld_gym.legacy`)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from .checks import (
    ENV_RANGES,
    check_actions,
    check_choice,
    check_episode_size,
    check_real,
    check_seed,
)
from .design import DESIGN_ORDER, Design, design
from .discrete import SampledSystem, discretize
from .fingerprint import observation_fingerprint
from .loads import Harmonic, Pulse, Samples, TipLoad, thesis_load
from .observer import MODEL_STD, DiscreteObserver, discrete_kalman, discrete_thesis
from .params import BeamParameters
from .plant import MESHES, Plant
from .plant import plant as nominal_plant
from .reduction import BASES
from .render import FigureOwner
from .simulate import simulate
from .thesis import V_LIMIT

if os.environ.get("ACLD_GYM_PURE_PYTHON") == "1":  # debugging: numpy steps only
    StepCore = None
else:
    try:
        from ._stepcore import StepCore
    except ImportError:  # built without a C compiler: the numpy reference step serves
        StepCore = None

#: Whether ``ACLDBeamEnv.step`` runs its common path compiled (``acld_gym._stepcore``).
COMPILED_STEP = StepCore is not None

__all__ = ["ACLDBeamEnv", "COMPILED_STEP", "Nominal", "nominal", "random_load", "LOAD_CASES",
           "OBS_MODES", "MESHES", "PARAM_NOISE_MAX", "configure", "check_config", "reset_options",
           "observation_size", "episode_spec",
           "estimate_map", "step_matrix", "output_matrix", "load_schedule", "draw_episode",
           "randomized_plant", "reward_of"]

LOAD_CASES = (1, 2, 3, "random")
#: Default tip-sensor noise std [m]: 0.1 um, the resolution of a laser displacement
#: sensor. (With 1 um the high-gain LQR turns the noise into voltage jitter and the
#: thesis's settling times are not reached.)
SENSOR_NOISE_M = 1e-7
OBS_MODES = ("estimate", "measurement", "full")
OBSERVERS = ("kalman", "thesis")
#: Deflection scale of the observations [m].
Y_SCALE = 1e-3
#: Parameters perturbed by ``param_noise`` (multiplicative, log-normal, per episode).
RANDOMIZED = ("ghm_kappa", "ghm_alpha", "ghm_omega", "ghm_zeta", "vem_density",
              "beam_youngs_modulus", "pzt_youngs_modulus", "d31", "rayleigh_mass",
              "rayleigh_stiffness")
#: Largest accepted ``param_noise`` per mesh (relative std of the log-normal factors,
#: which are truncated at 3 std). Every drawn plant is a physical beam, hence stable;
#: within these bounds the nominal Kalman observer with LQR, SMC and MPC also stays
#: stable on every plant: checked at all 1024 corners of the box of +/-3 std
#: (tests/test_robustness.py). At 0.1 on the thesis mesh 512 corners are unstable.
PARAM_NOISE_MAX = {"converged": 0.1, "thesis": 0.05}
#: Truncation of the log-normal parameter factors, in standard deviations.
PARAM_NOISE_CLIP = 3.0


@dataclass(frozen=True, eq=False)
class Nominal:
    """The nominal design for one control period: what observers and baselines know,
    and the nominal truth plant the env samples. ``xr_scale`` are the fixed observation
    scales: each reduced state's peak magnitude in the passive response to thesis case 1."""

    design: Design
    plant: SampledSystem
    reduced: SampledSystem
    kalman: DiscreteObserver
    thesis: DiscreteObserver
    xr_scale: np.ndarray
    mesh: str
    basis: str

    @property
    def truth(self) -> Plant:
        """The nominal truth plant (continuous, second-order form)."""
        return self.design.truth

    @property
    def output(self) -> np.ndarray:
        """Tip-deflection row of the truth plant's state, y = output @ x [m]."""
        return self.design.plant[3][0]

    @property
    def modes(self) -> np.ndarray:
        """Damped natural frequencies of the nominal truth plant [rad/s], ascending."""
        return self.design.truth.natural_frequencies()


@lru_cache(maxsize=8)
def nominal(dt: float = 1e-3, substeps: int = 10, sensor_std: float = SENSOR_NOISE_M,
            load_std: float = 1.0, mesh: str = "converged", basis: str = "modal",
            model_std: float = MODEL_STD) -> Nominal:
    """Nominal design of the ``mesh`` plant (:data:`acld_gym.plant.MESHES`) sampled at
    ``dt``, with the design order :data:`acld_gym.design.DESIGN_ORDER` and the Kalman
    filter's model-error noise ``model_std`` (cached: the env, its vector version and
    the baselines share it)."""
    if basis not in BASES:
        raise ValueError(f"basis must be one of {list(BASES)}, got {basis!r}")
    if mesh not in MESHES:
        raise ValueError(f"mesh must be one of {list(MESHES)}, got {mesh!r}")
    d = design(nominal_plant(mesh, dt), order=DESIGN_ORDER[mesh], basis=basis)
    A, B, E, Cy = d.plant
    sd = discretize(A, B, E, dt, substeps)
    r = d.reduced
    sr = discretize(r.A, r.B, r.E, dt, substeps)
    kal = discrete_kalman(sr.Ad, sr.Bd, sr.Ed, r.C, load_std=load_std, sensor_std=sensor_std,
                          model_std=model_std)
    cont = d.observer("thesis")
    # Held-input matrix of the thesis gain: int_0^dt e^{As} ds L (columnwise ZOH).
    sl = discretize(A, cont.L, E, dt, 1)
    th = discrete_thesis(sd.Ad, sl.Bd, sd.Bd, Cy, cont)
    res = simulate(A, B, E, Cy, cont, d.passive, thesis_load(1), t_end=0.2, v_max=None)
    scale = np.abs(res.xr).max(axis=0)
    return Nominal(design=d, plant=sd, reduced=sr, kalman=kal, thesis=th, xr_scale=scale,
                   mesh=mesh, basis=basis)


def random_load(rng: np.random.Generator, duration: float, grid: float,
                modes: tuple[float, float] = (179.0, 1115.0)) -> TipLoad:
    """A bounded random tip load drawn from ``rng``.

    Always one to three pulses (amplitude U(-1.5, 1.5) N, width 0.5-3 ms,
    start in the first 70 % of the episode); with probability 1/2 a harmonic
    of amplitude up to 0.08 N within +/-5 % of the plant's first (probability 0.7)
    or second natural frequency ``modes`` [rad/s], 0.05-0.3 s long; with
    probability 1/2 band-limited noise (low-pass random samples every 2 ms, std
    about 0.05 N). Pulse edges lie on ``grid`` [s] (the env's load sub-step), so
    the sampled model integrates them exactly.
    """
    comps: list = []
    for _ in range(int(rng.integers(1, 4))):
        start = np.round(rng.uniform(0.0, 0.7 * duration) / grid) * grid
        width = max(np.round(rng.uniform(5e-4, 3e-3) / grid), 1) * grid
        comps.append(Pulse(float(start), float(width), float(rng.uniform(-1.5, 1.5))))
    if rng.uniform() < 0.5:
        w0 = modes[0] if rng.uniform() < 0.7 else modes[1]
        comps.append(Harmonic(float(rng.uniform(0.0, 0.08)), float(w0 * rng.uniform(0.95, 1.05)),
                              float(rng.uniform(0.0, 0.5 * duration)),
                              float(rng.uniform(0.05, 0.3)), float(rng.uniform(0, 2 * np.pi))))
    if rng.uniform() < 0.5:
        step = max(np.round(2e-3 / grid), 1) * grid
        n = int(duration / step) + 1
        white = rng.normal(0.0, 1.0, n)
        smooth = np.convolve(white, np.ones(4) / 2.0, mode="same")  # ~0.25 kHz low-pass
        comps.append(Samples(0.0, float(step), tuple(0.05 * smooth)))
    return TipLoad(tuple(comps))


class ACLDBeamEnv(FigureOwner, gym.Env):
    """
    ## Description

    Vibration control of a 300 x 15 x 3 mm aluminium cantilever with an active
    constrained layer damping (ACLD) patch (Rodriguez 2006). The agent sets the
    voltage on the piezoelectric constraining layer to suppress the tip
    deflection caused by a tip load. The plant (the "truth model",
    :mod:`acld_gym.plant`) is, by default, the mesh-converged beam: the
    Timoshenko + GHM finite-element model on a 128x refined mesh (2305 DOFs),
    projected onto a 36-state rational Krylov basis that matches its frequency
    responses to 1e-5 up to twice the Nyquist frequency; ``mesh="thesis"`` gives
    the thesis's own 1 + 1 + 3-element model (38 states) instead. It is sampled
    exactly with a zero-order hold on the voltage; the tip load is integrated
    within each period (sub-steps with first-order hold, exact for pulses). The
    observer runs on the nominal 6-state reduced model (the design model), never on
    the (possibly randomized) plant. A step is one fused matrix-vector product
    (:func:`output_matrix`); it runs in C (``acld_gym._stepcore``) when that module
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

    x_r is the state of the 6-state reduced model in its canonical real modal
    form (:func:`acld_gym.reduction.modal_form`): one (cosine, sine)-like pair per
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
    * v0: the thesis's 38-state mesh; the reduced state in the Schur method's
      coordinates, which depend on the CPU's BLAS kernels (:mod:`acld_gym.legacy`).
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 30}

    #: The id this class is registered under (used when it is built without ``gym.make``).
    env_id = "ACLDBeam-v1"
    #: Coordinates of the reduced model (:data:`acld_gym.reduction.BASES`); ACLDBeam-v0's
    #: class keeps the machine-dependent ``"schur"``.
    _basis = "modal"
    #: Harmonic targets of random loads [rad/s]; None: the plant's own first two modes.
    _harmonic_modes: tuple[float, float] | None = None
    #: Model-error noise of the Kalman filter (:func:`acld_gym.observer.discrete_kalman`).
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
    # runs in C (acld_gym._stepcore.StepCore) where it can, else in numpy (_step); the
    # core holds the step count, voltage, last measurement and last output for both.
    _compiled = COMPILED_STEP  # False on an instance (before reset): numpy steps only

    k = property(lambda self: self._core.k, lambda self, val: setattr(self._core, "k", val),
                 doc="Steps taken in the episode.")
    v = property(lambda self: self._core.v, lambda self, val: setattr(self._core, "v", val),
                 doc="Voltage applied in the last step [V].")
    y_meas = property(lambda self: self._core.y_meas,
                      lambda self, val: setattr(self._core, "y_meas", val),
                      doc="Last tip measurement [m].")
    _last = property(lambda self: self._core.last,
                     doc="G z of the last step (:func:`output_matrix`; one buffer).")
    x = property(lambda self: self._z[:self._n], doc="True plant state [q; dq/dt] (a view).")
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
                                 "``param_noise``), a :class:`acld_gym.discrete.SampledSystem`.")

    @property
    def observation_fingerprint(self) -> dict:
        """What the observation depends on (:mod:`acld_gym.fingerprint`)."""
        return observation_fingerprint(self)
    xhat = property(lambda self: self._z[self._n:self._nk], doc="Observer state (a view).")

    def _reset_state(self, load: TipLoad) -> None:
        self.load = load
        n, k = self._plant.Ad.shape[0], self._obs.n
        self._n = n
        self._nk = nk = n + k
        self._z = np.zeros(nk + 3 + 2 * self._plant.substeps)
        self.y_hist = np.zeros(self.obs_hist)
        self.history: list[tuple[float, float, float]] = []
        F, tipf = load_schedule(self.nom.plant, load, 0, self.max_steps)
        self._tipf = np.ascontiguousarray(tipf, dtype=np.float64)
        self._noise = np.zeros(self.max_steps + 1)
        self._inputs = np.hstack([F, self._noise[1:, None]])  # per step: [f0, f1, w']
        self._G = output_matrix(step_matrix(self._plant, self.nom.plant, self._obs), n, k,
                                self.nom.output, self.nom.design.reduced.SL, self._est)
        self._core = self._make_core()

    def _make_core(self):
        """The step's core over this episode's arrays (state: at rest)."""
        if not (self._compiled and COMPILED_STEP):
            return _NumpyCore(self._G.shape[0])
        core = StepCore(G=self._G, z=self._z, inputs=self._inputs, tipf=self._tipf,
                        y_hist=self.y_hist, nk=self._nk, n_x=self._n,
                        n_xr=self.nom.design.reduced.order,
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
            return self._last[-(self._est.shape[1] + 1):].astype(np.float32)
        if self.obs_mode == "measurement":
            return np.append(self.y_hist / Y_SCALE, self.v / self.v_max).astype(np.float32)
        return self.x.astype(np.float32)

    def _info(self, requested: float | None = None) -> dict[str, Any]:
        k, nk = self.k, self._nk
        tip_load = float(self._tipf[k]) if k <= self.max_steps else float(self.load(k * self.dt))
        return {"tip_deflection": float(self._last[nk + 1]), "voltage": self.v,
                "tip_load": tip_load, "time": k * self.dt,
                "xr_true": self._last[nk + 2:nk + 2 + self.nom.design.reduced.order].copy(),
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
        self.y_meas = self._z[self._nk] = w
        self.y_hist[-1] = w
        self._last[self._nk] = w
        self._last[-(self._est.shape[1] + 1):] = w * np.append(self._est[-1], 1.0 / Y_SCALE)
        return self._observation(), self._info()

    def step(self, action):
        result = self._core.step(action)  # the compiled path; None where it does not apply
        return result if result is not None else self._step(action)

    def _step(self, action):
        """The step in numpy: the reference for :class:`acld_gym._stepcore.StepCore`, and
        the path for actions of other types, bad actions, rendering and steps past the
        tabulated episode."""
        if isinstance(self._core, _NotReset):
            raise RuntimeError("ACLDBeamEnv: call reset() before step()")
        v, requested = self._voltage(action)
        c, z, nk = self._core, self._z, self._nk
        k = c.k
        z[nk + 1] = v
        z[nk + 2:] = self._step_inputs(k)
        # 1. plant (ZOH) and 2. observer over one period, 3. the new measurement
        out = np.dot(self._G, z, out=c.last)
        z[:nk + 1] = out[:nk + 1]
        c.k = k = k + 1
        c.v = v
        c.y_meas = float(out[nk])
        y = float(out[nk + 1])
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
        from .render import render_frame

        frame, self._fig = render_frame(self, self._fig)
        if self.render_mode == "human":
            from .render import show

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
    """The state :class:`acld_gym._stepcore.StepCore` keeps, without a compiled step
    (every step goes to ``ACLDBeamEnv._step``)."""

    __slots__ = ("k", "v", "y_meas", "last")

    def __init__(self, m: int):
        self.k, self.v, self.y_meas, self.last = 0, 0.0, 0.0, np.zeros(m)

    def step(self, action) -> None:
        return None


# --- pieces shared by ACLDBeamEnv and ACLDBeamVectorEnv ------------------------
def configure(env, *, load_case, mesh, dt, episode_length, observer, obs_mode, sensor_noise,
              y_ref, lam, param_noise, deflection_limit, render_mode, num_envs: int = 1) -> None:
    """Validate the keyword arguments shared by the single and the vector env
    (``ValueError`` naming a bad one) and set them, with the nominal design, on ``env``."""
    check_config(load_case=load_case, mesh=mesh, dt=dt, episode_length=episode_length,
                 observer=observer, obs_mode=obs_mode, sensor_noise=sensor_noise, y_ref=y_ref,
                 lam=lam, param_noise=param_noise, deflection_limit=deflection_limit,
                 render_mode=render_mode, render_modes=env.metadata["render_modes"],
                 param_noise_max=env._param_noise_max, num_envs=num_envs)
    env.load_case = load_case
    env.mesh = mesh
    env.dt = float(dt)
    env.episode_length = float(episode_length)
    env.observer_kind = observer
    env.obs_mode = obs_mode
    env.sensor_noise = float(sensor_noise)
    env.y_ref = float(y_ref)
    env.lam = float(lam)
    env.param_noise = float(param_noise)
    env.deflection_limit = float(deflection_limit)
    env.render_mode = render_mode
    env.v_max = V_LIMIT
    env.obs_hist = 8
    env.nom = nominal(env.dt, 10, max(env.sensor_noise, 1e-9), mesh=mesh, basis=env._basis,
                      model_std=env._model_std)
    env.harmonic_modes = (env._harmonic_modes if env._harmonic_modes is not None
                          else tuple(float(w) for w in env.nom.modes[:2]))


def check_config(*, load_case, mesh, dt, episode_length, observer, obs_mode, sensor_noise, y_ref,
                 lam, param_noise, deflection_limit, render_mode, render_modes,
                 param_noise_max: float | None = None, num_envs: int = 1) -> None:
    """Validate the environment's keyword arguments (``ValueError`` naming a bad one):
    choices, the ranges of :data:`acld_gym.checks.ENV_RANGES`, the ``param_noise`` bound
    of the mesh and the episode's size (:func:`acld_gym.checks.check_episode_size`)."""
    check_choice("load_case", load_case, LOAD_CASES)
    check_choice("mesh", mesh, MESHES)
    check_choice("observer", observer, OBSERVERS)
    check_choice("obs_mode", obs_mode, OBS_MODES)
    values = {"dt": dt, "episode_length": episode_length, "sensor_noise": sensor_noise,
              "y_ref": y_ref, "lam": lam, "deflection_limit": deflection_limit}
    for name, value in values.items():
        low, high, unit, _ = ENV_RANGES[name]
        check_real(name, value, low, high, unit=unit)
    limit = param_noise_max if param_noise_max is not None else PARAM_NOISE_MAX.get(mesh, 0.0)
    check_real("param_noise", param_noise, 0.0)
    if param_noise > limit:
        raise ValueError(f"param_noise must be at most {limit} for mesh={mesh!r} (relative std; "
                         f"beyond it the nominal observer and baselines are not validated), got "
                         f"{param_noise!r}")
    check_episode_size(float(episode_length), float(dt), num_envs)
    if render_mode is not None and render_mode not in render_modes:
        raise ValueError(f"render_mode must be one of {list(render_modes)} or "
                         f"None, got {render_mode!r}")


def reset_options(options, default_case):
    """The load case of ``reset(options=...)`` (``ValueError`` on anything else)."""
    if options is not None and not isinstance(options, dict):
        raise ValueError(f"options must be a dict or None, got {options!r}")
    options = dict(options or {})
    case = options.pop("load_case", default_case)
    if options:
        raise ValueError(f"options: unknown key(s) {sorted(options)}; expected 'load_case'")
    check_choice("load_case", case, LOAD_CASES)
    return case


def observation_size(nom: Nominal, obs_mode: str, hist: int) -> int:
    return {"estimate": nom.design.reduced.order + 1, "measurement": hist + 1,
            "full": nom.plant.Ad.shape[0]}[obs_mode]


def estimate_map(obs: DiscreteObserver, xr_scale: np.ndarray) -> np.ndarray:
    """Matrix M with ``[xhat, y] @ M`` = the scaled x_r estimate after the measurement
    update, ``T (xhat + L_c (y - C xhat)) / xr_scale``."""
    lc = obs.Lc[:, 0]
    M = np.vstack([(obs.T @ (np.eye(obs.n) - np.outer(lc, obs.C[0]))).T, (obs.T @ lc)[None, :]])
    return M / xr_scale


def step_matrix(plant: SampledSystem, nom_plant: SampledSystem,
                obs: DiscreteObserver) -> np.ndarray:
    """One period of plant and observer as one matrix S:
    ``[x', xhat'] = S [x, xhat, y_prev, V, f0, f1]`` with ``y_prev`` the last
    measurement, ``f0, f1`` the period's load samples (:func:`load_schedule`).
    The plant may be randomized; the observer uses the nominal load weights."""
    n, k, s = plant.Ad.shape[0], obs.n, plant.substeps
    S = np.zeros((n + k, n + k + 2 + 2 * s))
    S[:n, :n] = plant.Ad
    S[:n, n + k + 1] = plant.Bd[:, 0]
    S[:n, n + k + 2:] = np.hstack([plant.W0, plant.W1])
    lp = obs.Lp[:, 0]
    S[n:, n:n + k] = obs.A - np.outer(lp, obs.C[0])
    S[n:, n + k] = lp
    S[n:, n + k + 1] = obs.B[:, 0]
    if obs.fed_load:
        S[n:, n + k + 2:] = np.hstack([nom_plant.W0, nom_plant.W1])
    return S


def output_matrix(S: np.ndarray, n: int, k: int, output: np.ndarray, SL: np.ndarray,
                  est: np.ndarray) -> np.ndarray:
    """The single env's whole step as one matrix G, from :func:`step_matrix` S.

    Input ``z = [x, xhat, y_meas, V, f0, f1, w']`` (S's input and the noise w' of the
    new measurement); output ``G z = [x', xhat', y_meas', y', x_r', e', y_meas' / Y_SCALE]``
    with ``y' = output @ x'`` the true tip deflection, ``y_meas' = y' + w'``,
    ``x_r' = S_L^T x'`` the true reduced state and ``e' = [xhat', y_meas'] M`` the
    scaled estimate (:func:`estimate_map` M). So ``(G z)[:n+k+1]`` is the next state
    and ``(G z)[-7:]`` the ``"estimate"`` observation.
    """
    X = np.hstack([S[:n + k], np.zeros((n + k, 1))])
    y = output @ X[:n]
    y_meas = y.copy()
    y_meas[-1] = 1.0
    e = est[:k].T @ X[n:] + np.outer(est[k], y_meas)
    return np.vstack([X, y_meas, y, SL.T @ X[:n], e, y_meas / Y_SCALE])


def load_schedule(plant: SampledSystem, load: TipLoad, start: int,
                  stop: int) -> tuple[np.ndarray, np.ndarray]:
    """Load samples of periods ``start .. stop-1``: ``(F, tip)`` with F (steps, 2 substeps)
    ``[f0, f1]`` as :meth:`SampledSystem.load_samples` and tip (steps + 1,) the load at
    the period starts ``k dt`` (for ``info``)."""
    k = np.arange(start, stop + 1)
    tt = (k[:-1] * plant.dt)[:, None] + plant.times
    eps = 1e-9 * plant.dt
    F = np.hstack([load(tt[:, :-1] + eps), load(tt[:, 1:] - eps)])
    return F, load(k * plant.dt)


def draw_episode(rng: np.random.Generator, case, nom: Nominal, episode_length: float,
                 param_noise: float,
                 harmonic_modes: tuple[float, float]) -> tuple[TipLoad, SampledSystem]:
    """The load and the (possibly randomized) plant of an episode, drawn from ``rng``
    in a fixed order: load first, then parameters."""
    check_choice("load_case", case, LOAD_CASES)
    plant = nom.plant
    load = (random_load(rng, episode_length, plant.dt / plant.substeps, harmonic_modes)
            if case == "random" else thesis_load(case))
    if param_noise > 0:
        plant = randomized_plant(rng, param_noise, nom)
    return load, plant


def randomized_parameters(rng: np.random.Generator, param_noise: float,
                          params: BeamParameters) -> BeamParameters:
    """``params`` with each of :data:`RANDOMIZED` times :math:`e^z`,
    :math:`z \\sim N(0, \\sigma^2)` truncated to :math:`\\pm 3\\sigma`
    (:data:`PARAM_NOISE_CLIP`); ``sigma = param_noise``."""
    z = np.clip(rng.normal(0.0, param_noise, len(RANDOMIZED)),
                -PARAM_NOISE_CLIP * param_noise, PARAM_NOISE_CLIP * param_noise)
    return replace(params, **{name: getattr(params, name) * float(np.exp(zi))
                              for name, zi in zip(RANDOMIZED, z, strict=True)})


def randomized_plant(rng: np.random.Generator, param_noise: float,
                     nom: Nominal) -> SampledSystem:
    """The nominal truth plant with randomized material parameters
    (:func:`randomized_parameters`), sampled like the nominal one. It is the Galerkin
    projection of the physical beam with those parameters, hence stable
    (:mod:`acld_gym.plant`)."""
    truth = nom.truth
    A, B, E, _ = truth.state_space(randomized_parameters(rng, param_noise, truth.params))
    return discretize(A, B, E, nom.plant.dt, nom.plant.substeps)


def episode_spec(spec, steps: int):
    """``spec`` with ``max_episode_steps`` set to the env's ``steps`` when it has none (the
    env truncates itself there) or a larger one (the env still ends at ``steps``)."""
    if spec is None:
        return None
    limit = spec.max_episode_steps
    if limit is None or limit > steps:
        spec = replace(spec, max_episode_steps=int(steps))
    return spec


def termination(y: float, reward: float, state: np.ndarray, limit: float) -> str | None:
    """Why a step ends the episode: ``"non_finite_state"`` if the new state or the reward
    is not finite (never passed off as a normal step), ``"deflection_limit"`` if
    |y| > ``limit``; else None."""
    if not (math.isfinite(reward) and np.isfinite(state).all()):
        return "non_finite_state"
    if not abs(y) <= limit:
        return "deflection_limit"
    return None


def reward_of(y, v, y_ref: float, lam: float, v_max: float):
    """``-(y / y_ref)^2 - lam (V / v_max)^2`` (scalars or arrays)."""
    return -((y / y_ref) ** 2) - lam * (v / v_max) ** 2
