"""``ACLDBeam``: the ACLD cantilever as a Gymnasium environment, one class for every
registered id (``ACLDBeam-v1``, ``ACLDBeam-v0`` and the presets are configurations,
:mod:`acld_gym.envs.presets`).

The class composes the layers below it: :mod:`acld_gym.envs.config` validates the
configuration, :mod:`acld_gym.envs.episode` draws the load and the plant, and
:mod:`acld_gym.envs.batch` is the step -- the single env is its N = 1 case, compiled where
it was built (:mod:`acld_gym.envs.single_step`: its state, reset info and 5-tuple read from
the batch).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from acld_gym.envs.batch import COMPILED_STEP, BatchStep
from acld_gym.envs.checks import check_actions, check_render_mode
from acld_gym.envs.config import ConfigAttributes, EnvConfig, make_config
from acld_gym.envs.conflicts import made_spec
from acld_gym.envs.episode import draw_episode, draw_noise, reset_options
from acld_gym.envs.fingerprint import observation_fingerprint
from acld_gym.envs.render import FigureOwner, render_frame, show
from acld_gym.envs.single_step import BatchView, fast_step, not_reset, reset_info, single
from acld_gym.envs.step import load_schedule
from acld_gym.physics.actuator import V_LIMIT
from acld_gym.physics.loads import case_load, thesis_load
from acld_gym.util.validate import check_seed

__all__ = ["ACLDBeamEnv", "COMPILED_STEP"]


class ACLDBeamEnv(BatchView, ConfigAttributes, FigureOwner, gym.Env):
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
    converged plant, 6 on the thesis mesh; :mod:`acld_gym.design.nominal`), never on
    the (possibly randomized) plant. A step is one fused matrix-vector product
    (:func:`acld_gym.envs.step.output_matrix`), the N = 1 case of the batched step
    (:mod:`acld_gym.envs.batch`); it runs in C (``acld_gym.envs._stepcore``) when that
    module was built (``COMPILED_STEP``), else in numpy, with the same results.

    The configuration is one :class:`acld_gym.envs.config.EnvConfig` (``config=``, or its
    fields as keyword arguments, which replace the config's; see Arguments).

    ## Action Space

    ``Box(-120, 120, (1,), float32)``: the commanded piezo voltage [V], held for one period.
    Out-of-range actions are clipped to +/-120 V and reported in
    ``info["clipped"]``; NaN or inf raise ``ValueError`` and leave the state
    untouched. (Train in [-1, 1] with :class:`acld_gym.wrappers.UnitAction`; what any RL
    library should add: the training guide, ``docs/training.md``.) By default
    the command is the patch voltage; with the actuator options it reaches the patch
    ``actuator_delay`` periods later, through an amplifier that moves at most
    ``slew_rate`` and lags with ``amplifier_bandwidth`` (``info["voltage"]`` is the patch
    voltage at the end of the step, ``info["requested_voltage"]`` the action).

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
    (``NominalDesign.xr_scale``), so a 1 N x 1 ms pulse gives values of order one (mode 4,
    above the Nyquist frequency, is seen by the 1 kHz Kalman filter at about a tenth).
    ``"full"``: for ``mesh="converged"`` q are the 18 mass-normalized Ritz
    coordinates of the plant [kg^0.5 m] and their rates; for ``mesh="thesis"`` the
    19 FE DOFs (m, rad) and their rates.

    ## Rewards

    ``r = -(y / y_ref)^2 - lam * (V / 120)^2`` per step, with ``y`` the true
    tip deflection [m] at the end of the step and ``V`` the patch voltage at the end of
    the step (``info["voltage"]``: the clipped action unless the actuator options are set).
    The two terms are ``info["reward_deflection"]`` and ``info["reward_voltage"]``.
    With ``reward_scale="passive"`` or ``"lqr"`` (training aids, off by default) the reward
    is divided by the episode's passive, or LQR's, cost c, ``info["reward_scale"]``; the
    terms stay unscaled.

    ## Starting State

    The beam at rest (all plant states zero), the observer at zero. The load of
    the episode is set by ``load_case`` (or ``reset(options={"load_case": ...})``, or a
    :class:`acld_gym.physics.loads.TipLoad` as ``reset(options={"load": ...})``).

    ## Episode End

    * ``terminated``: |tip deflection| > ``deflection_limit`` (20 mm by
      default, beyond which the linear model is not valid), or a non-finite number
      in the new state or reward; ``info["terminated_by"]`` says which
      (``"deflection_limit"``, ``"non_finite_state"``; None otherwise).
    * ``truncated``: after ``episode_length`` seconds, ``round(episode_length / dt)``
      steps (1000 by default, ``gym.spec(id).max_episode_steps``; a made env's count is
      ``env.spec.max_episode_steps``); ``gym.make`` adds no limit of its own, and its
      ``max_episode_steps=n`` only shortens the episode (a longer n is refused).
    * Limits: at most 1,000,000 steps per episode (``config.MAX_EPISODE_STEPS``) and
      4,000,000 tabulated steps over a vector env's sub-envs (``MAX_TABLE_STEPS``): the
      sensor noise of an episode is tabulated at reset (8 bytes per step; without the
      compiled step the loads too, 170 bytes per step), so a longer episode is refused at
      construction with a ``ValueError`` instead of exhausting memory.

    ## Arguments

    ``config`` (an ``EnvConfig``, default ``ACLDBeam-v1``'s), ``render_mode``
    (``"rgb_array"``, ``"human"`` or None) and the config's fields as keywords:

    | field | default | meaning |
    |---|---|---|
    | ``load_case`` | 1 | 1, 2, 3 (thesis ch. 5), ``"random"`` (new random load per episode) or a |
    | | | ``TipLoad`` (pulses, harmonics, ``Samples``; :mod:`acld_gym.physics.loads`) |
    | ``mesh`` | ``"converged"`` | truth plant: ``"converged"`` or ``"thesis"`` (38 states) |
    | ``dt`` | 1e-3 | control period [s], in [1e-4, 1e-2] |
    | ``episode_length`` | 1.0 | episode duration [s], in [1e-4, 1e3] |
    | ``observer`` | ``"kalman"`` | ``"kalman"`` (reduced model, not fed the load) or |
    | | | ``"thesis"`` (full order, fed the load) |
    | ``obs_mode`` | ``"estimate"`` | see Observation Space |
    | ``sensor_noise`` | 1e-7 | tip-sensor noise std [m] in [0, 1e-3] (seeded; 0 for none) |
    | ``y_ref`` | 1e-3 | deflection scale of the reward [m], in [1e-9, 1] |
    | ``lam`` | 0.01 | voltage weight of the reward, in [0, 1e6] |
    | ``param_noise`` | 0.0 | relative std of per-episode parameter randomization, at |
    | | | most ``param_noise_max``; log-normal factors truncated at 3 std |
    | ``deflection_limit`` | 0.02 | termination limit [m], in [1e-6, 1] |
    | ``harmonic_modes`` | None | random-load harmonic targets [rad/s]; None: the plant's |
    | | | own first two damped modes |
    | ``model_std`` | 0.1 | model-error noise of the Kalman filter (relative) |
    | ``param_noise_max`` | None | bound of ``param_noise``; None: 0.1 (``"converged"``) |
    | | | or 0.05 (``"thesis"``), within which the baselines are certified stable |
    | ``actuator_delay`` | 0 | latency from the action to the amplifier [control periods], |
    | | | in [0, 100]: the command of step k drives the patch in step k + delay |
    | ``amplifier_bandwidth`` | None | [Hz] in [1, 1e6]: a first-order lag from the |
    | | | amplifier's input to the patch voltage, sampled exactly (in the fused matrix; the |
    | | | patch voltage becomes a plant state); None: ideal |
    | ``slew_rate`` | None | [V/s] in [1, 1e9]: the amplifier's output moves at most |
    | | | ``slew_rate * dt`` per period (its current limit on the patch's 22.7 nF, |
    | | | ``acld_gym.physics.actuator``; a +/-150 V bender driver, 95 mA: 4.2e6 V/s); None |
    | ``temperature`` | 20 | viscoelastic layer [°C] in [16.5, 40]: its GHM modulus follows |
    | | | time-temperature superposition (WLF, ``acld_gym.physics.temperature``); 20 °C is |
    | | | where the thesis's GHM parameters hold, so the default plant is v1's |
    | ``temperature_range`` | None | (low, high) [°C]: a temperature per episode, uniform |
    | ``reward_scale`` | None | ``"passive"``: each reward of an episode divided by c, the |
    | | | passive beam's mean step cost on the episode's load (``info["reward_scale"]``; |
    | | | ``acld_gym.envs.scale``); the passive policy's return is then exactly -T. |
    | | | ``"lqr"``: divided by LQR's mean step cost on the load (a noise-free episode |
    | | | of this configuration under the thesis's LQR law): the return is -T times |
    | | | the episode's cost relative to LQR's |
    | ``observe_reward_scale`` | False | append log c to the observation as its last entry |
    | | | (privileged, for a critic; n + 1 entries); needs ``reward_scale`` |
    | ``observe_commands`` | False | append the commands still in flight, the oldest first, |
    | | | in units of 120 V, before any log c: ``actuator_delay`` entries (one fewer with |
    | | | ``obs_mode="measurement"``, which ends with the newest; none without a delay). |
    | | | What a delay-aware controller knows: the thesis's observer does not |
    | ``env_id`` | ``"ACLDBeam-v1"`` | the registered id of the configuration (fingerprint) |

    The actuator chain, per period: the action is clipped (the command, which the
    observer and the ``"measurement"`` observation see), waits ``actuator_delay`` periods,
    drives the amplifier, whose output moves towards it by at most ``slew_rate * dt`` and
    is held over the period (zero-order hold), and reaches the patch through the lag. The
    design model, the observer and the baselines stay nominal: they know none of these
    options, nor the temperature (model mismatch, like ``param_noise``).

    Load case 3 is the thesis's resonant harmonic, 0.1 sin(179 t) N for 5.5 cycles,
    on every mesh: the thesis tuned it to its model's first resonance (178.6 rad/s);
    the converged beam's is 177.4 rad/s, and over the 0.193 s of the load the 1.6 rad/s
    detuning adds up to 0.31 rad of phase, so the load still pumps the first mode
    (the mesh study, ``docs/mesh.md``). Random loads aim their harmonics at
    the plant's own modes.

    ## Version History

    * ACLDBeamLab-v1 (new in acld-gym 0.3.0): v1 with a laboratory rig's actuator and
      sensor -- ``actuator_delay=1`` (computation delay), ``slew_rate=4.18e6`` V/s (a
      +/-150 V bender driver's 95 mA on the patch's 22.7 nF), ``amplifier_bandwidth=60e3``
      Hz, ``sensor_noise=1.8e-7`` m (a 14-bit laser sensor's quantization);
      :mod:`acld_gym.envs.presets` has the sources. Reference table: ``docs/variants.md``.
    * ACLDBeamHard-v1 (new in 0.3.0): the lab rig, the polymer's temperature drawn per
      episode in 18-28 °C, ``param_noise=0.05`` and ``obs_mode="measurement"``.
    * v1: the truth plant is the mesh-converged beam (``mesh="converged"``; the thesis
      mesh is ``mesh="thesis"``); the reduced-state estimate is in canonical
      coordinates (real modal form), identical on every machine; random loads aim at
      the plant's own first two modes; the design model has 8 states on the converged
      plant (modes 1-4; 6 on the thesis mesh) and the Kalman filter a model-error noise
      (``model_std`` 0.1), so the baselines stay stable on every randomized plant;
      ``param_noise`` is bounded (0.1; 0.05 on the thesis mesh) and its factors
      truncated at 3 std. Since acld-gym 0.3.0 the info also has ``requested_voltage``
      and the reward's terms in the vector env too, custom loads (``TipLoad``) are
      accepted, and the actuator (``actuator_delay``, ``amplifier_bandwidth``,
      ``slew_rate``), temperature (``temperature``, ``temperature_range``) and reward
      scale (``reward_scale``, ``observe_reward_scale``) options exist, all off by
      default: v1's dynamics, rewards and observations are unchanged. acld-gym 0.7.0 adds
      ``reward_scale="lqr"`` and 0.23.0 ``observe_commands`` (both off by default).
    * v0: the thesis configuration (``acld_gym.envs.presets.PRESETS["ACLDBeam-v0"]``):
      the thesis's 38-state mesh, its 6-state design model and observers, the same
      dynamics, reward, spaces and episode. It differs from v1 with ``mesh="thesis"`` in
      three settings only: random-load harmonics at 179 and 1115 rad/s
      (``harmonic_modes``; v1: the plant's own 178.64 and 1115.40), a Kalman filter
      driven by the load alone (``model_std=0``; v1: 0.1) and ``param_noise`` up to 0.5
      (``param_noise_max``; v1: 0.05). Since acld-gym 0.3.0 its observation is in the
      same canonical modal basis as v1's, identical on every machine; before, it was
      the Schur method's own coordinates, whose signs changed with the CPU's BLAS kernels
      (up to a sign flip of whole components), so an agent trained on one machine acted
      on other coordinates on another. Since 0.3.0 it is a configuration of this class
      (before, a subclass); its other fields can be set like v1's.
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 30}

    #: Step in C where it can (``COMPILED_STEP``); set False on an instance to force the
    #: numpy reference step from the next reset on (benchmarks and tests compare the two).
    compiled_step = COMPILED_STEP

    def __init__(self, config: EnvConfig | None = None, render_mode: str | None = None, **kwargs):
        self.config = make_config(config, **kwargs)  # validated, no silent conflict
        check_render_mode(render_mode, self.metadata["render_modes"])
        self.render_mode = render_mode
        self.nom = self.config.nominal()
        #: Random-load harmonic targets [rad/s] (``config.harmonic_targets``).
        self.harmonic_modes = self.config.harmonic_targets(self.nom)
        self.max_steps = self.config.max_steps
        self._batch = BatchStep(self.config, 1, self.max_steps, self.compiled_step)
        self.action_space = spaces.Box(-V_LIMIT, V_LIMIT, (1,), np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, (self._batch.n_obs,), np.float32)
        self._fig = None
        self.history: list[tuple[float, float, float]] = []
        self.load = case_load(self.config.load_case) or thesis_load(1)
        self._batch.start_episodes([0], [self.load], [None], np.zeros((1, self.max_steps + 1)))
        self._started = False
        self._fast = not_reset  # the compiled step after reset(); None where it declines

    @property
    def spec(self):
        """The registration spec (set by ``gym.make``; its id must be ``config.env_id``),
        with ``max_episode_steps`` the episode's own, ``episode_length / dt`` steps
        (:func:`acld_gym.envs.conflicts.made_spec`)."""
        return getattr(self, "_spec", None)

    @spec.setter
    def spec(self, value) -> None:
        self._spec = made_spec(value, self.config, self.max_steps)

    @property
    def observation_fingerprint(self) -> dict:
        """What the observation depends on (:mod:`acld_gym.envs.fingerprint`)."""
        return observation_fingerprint(self)

    def __getstate__(self):
        state = super().__getstate__()
        state["_fast"] = None  # a bound method of the compiled core: rebuilt on load
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._fast = not_reset if not self._started else fast_step(self._batch)

    # --- Gymnasium API --------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        case = reset_options(options, self.config.load_case, self.dt)  # checked, then seeded:
        super().reset(seed=check_seed(seed))  # a rejected reset leaves the RNG as it was
        c = self.config
        load, plant = draw_episode(self.np_random, case, self.nom, c, self.harmonic_modes)
        noise = (
            draw_noise(self.np_random, c.sensor_noise, self.max_steps + 1)
            if c.sensor_noise
            else np.zeros(self.max_steps + 1)
        )
        if self._batch.compiled != (self.compiled_step and COMPILED_STEP):
            self._batch = BatchStep(c, 1, self.max_steps, self.compiled_step)
        self._batch.start_episodes([0], [load], [plant], noise[None])
        self.load = load
        self.history = []
        self._started = True
        self._fast = fast_step(self._batch)
        b = self._batch
        return b.observations()[0], reset_info(b, self.nom.design.reduced.order)

    def step(self, action):
        result = self._fast(action)  # the compiled step; None where it does not apply
        if result is None:
            result = self._step(action)
        if self.render_mode is not None:  # the history is only drawn, never observed
            info = result[4]
            self.history.append((info["time"], info["tip_deflection"], info["voltage"]))
            if self.render_mode == "human":
                self.render()
        return result

    def _step(self, action):
        """The step in numpy (:meth:`acld_gym.envs.batch.BatchStep.advance`): the reference
        of the compiled one, and the path for actions of other types, bad actions and steps
        past the tabulated episode."""
        if not self._started:
            not_reset(action)
        requested, v = check_actions(action, 1, V_LIMIT)
        b, k = self._batch, self.k
        inputs = None
        if k >= self.max_steps:  # past the tabulated episode: this period's load and noise
            f = load_schedule(self.nom.plant, self.load, k, k + 1)[0]
            w = self.np_random.normal(0.0, self.sensor_noise) if self.sensor_noise else 0.0
            inputs = np.append(f[0], w)[None]
        out = single(b.advance(v, inputs), float(requested[0]), float(v[0]), k + 1, self.dt)
        if b.scale_cost is not None:
            out[4]["reward_scale"] = float(b.reward_scale[0])
        return out

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; pass render_mode= to make()")
            return None
        frame, self._fig = render_frame(self, self._fig)
        if self.render_mode == "human":
            show(self._fig)
            return None
        return frame

    def close(self):
        self._close_figure()
