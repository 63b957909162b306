"""The environment's configuration: one frozen :class:`EnvConfig`, validated once, here.

Every env class takes it (:class:`acld_gym.envs.beam_env.ACLDBeamEnv`, the vector env, the
SB3 adapter), either as ``config=`` or as keyword arguments (:func:`make_config` merges
them: the keywords replace fields of the config). ``ACLDBeam-v0``, ``ACLDBeam-v1`` and the
difficulty presets are configurations (:mod:`acld_gym.envs.presets`), not classes.

Each field's unit, range and meaning are in its ``metadata`` (:func:`config_table` prints
them; the env's docstring has the same table). The ranges are physical or practical limits:
beyond them a result would be meaningless (a tip sensor with 1 m of noise), overflow (a
deflection scale of 1e-300 m makes the reward infinite) or exhaust memory (the episode's
sensor noise is tabulated at reset).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from acld_gym.design.nominal import SENSOR_NOISE_M, nominal_design
from acld_gym.design.observer import MODEL_STD
from acld_gym.envs.conflicts import LOAD_SUBSTEPS, check_config_keywords, check_consistent
from acld_gym.envs.fixed import FixedSettings, fixed_names
from acld_gym.envs.ids import check_env_id
from acld_gym.envs.limits import (
    MAX_DELAY,
    MAX_EPISODE_STEPS,
    MAX_TABLE_STEPS,
    PARAM_NOISE_MAX,
    check_episode_size,
    check_param_noise,
)
from acld_gym.envs.scale import REWARD_SCALES
from acld_gym.envs.step import OBS_HIST
from acld_gym.physics.actuator import V_LIMIT
from acld_gym.physics.loads import TipLoad, check_load_case
from acld_gym.physics.temperature import T_REF, TEMPERATURE_RANGE, check_temperature
from acld_gym.physics.truth import MESHES
from acld_gym.util.validate import check_choice, check_int, check_real

__all__ = [
    "EnvConfig",
    "ConfigAttributes",
    "make_config",
    "config_table",
    "check_param_noise",
    "check_episode_size",
    "PARAM_NOISE_MAX",
    "OBS_MODES",
    "OBSERVERS",
    "MAX_EPISODE_STEPS",
    "MAX_TABLE_STEPS",
    "SENSOR_NOISE_M",
]

OBS_MODES = ("estimate", "measurement", "full")
OBSERVERS = ("kalman", "thesis")


def _f(default, unit: str, doc: str, low=None, high=None) -> Any:
    return field(default=default, metadata={"unit": unit, "doc": doc, "low": low, "high": high})


@dataclass(frozen=True)
class EnvConfig:
    """Everything that defines an ACLDBeam task (units and ranges in each field's
    ``metadata``; :func:`config_table`). Frozen and validated on construction: a bad value
    raises ``ValueError`` naming the field and what was expected, and so do fields that
    contradict each other (:mod:`acld_gym.envs.conflicts`).
    :func:`dataclasses.replace` (or :meth:`replace`) validates again.
    """

    load_case: int | str | TipLoad = _f(
        1,
        "-",
        "1, 2, 3 (thesis ch. 5), 'random' (a new random load per episode) or a "
        "TipLoad (a custom load, acld_gym.physics.loads)",
    )
    mesh: str = _f("converged", "-", "truth plant: 'converged' (36 states) or 'thesis' (38)")
    dt: float = _f(
        1e-3, "s", "control period of a piezo rig; the plant is built for 2 pi/dt", 1e-4, 1e-2
    )
    episode_length: float = _f(
        1.0, "s", "episode duration, at most MAX_EPISODE_STEPS steps", 1e-4, 1e3
    )
    observer: str = _f(
        "kalman",
        "-",
        "'kalman' (reduced model, not fed the load) or 'thesis' (full order, fed the load)",
    )
    obs_mode: str = _f("estimate", "-", "'estimate', 'measurement' or 'full' (privileged)")
    sensor_noise: float = _f(
        SENSOR_NOISE_M, "m", "std of the tip sensor (seeded; 0 for none)", 0.0, 1e-3
    )
    y_ref: float = _f(1e-3, "m", "deflection scale of the reward", 1e-9, 1.0)
    lam: float = _f(0.01, "-", "voltage weight of the reward", 0.0, 1e6)
    param_noise: float = _f(
        0.0,
        "-",
        "relative std of the per-episode log-normal parameter "
        "factors (truncated at 3 std), at most param_noise_max",
        0.0,
        None,
    )
    deflection_limit: float = _f(0.02, "m", "termination limit of |tip deflection|", 1e-6, 1.0)
    harmonic_modes: tuple[float, float] | None = _f(
        None,
        "rad/s",
        "targets of the random loads' harmonics; None: the plant's own first two damped modes",
    )
    model_std: float = _f(
        MODEL_STD,
        "-",
        "model-error noise of the Kalman filter (acld_gym.design.observer.discrete_kalman)",
        0.0,
        1e3,
    )
    param_noise_max: float | None = _f(
        None,
        "-",
        "bound of param_noise; None: PARAM_NOISE_MAX of the mesh, within which the "
        "baselines are certified stable",
        0.0,
        1.0,
    )
    actuator_delay: int = _f(
        0,
        "periods",
        "latency from the action to the amplifier, in whole control periods "
        "(computation and conversion delay)",
        0,
        MAX_DELAY,
    )
    amplifier_bandwidth: float | None = _f(
        None,
        "Hz",
        "small-signal bandwidth of the amplifier: a first-order lag from the "
        "command to the patch voltage, sampled exactly; None: ideal",
        1.0,
        1e6,
    )
    slew_rate: float | None = _f(
        None,
        "V/s",
        "largest rate of change of the amplifier's output (its current limit on "
        "the patch's capacitance, acld_gym.physics.actuator); None: unlimited",
        1.0,
        1e9,
    )
    temperature: float = _f(
        T_REF,
        "°C",
        "temperature of the viscoelastic layer (time-temperature superposition, "
        "acld_gym.physics.temperature); 20 °C: the thesis's GHM parameters",
        *TEMPERATURE_RANGE,
    )
    temperature_range: tuple[float, float] | None = _f(
        None,
        "°C",
        "draw the temperature per episode, uniform in (low, high), with temperature at 20; "
        "None: always temperature",
    )
    reward_scale: str | None = _f(
        None,
        "-",
        "None (the reward as defined), 'passive' or 'lqr': each reward of an "
        "episode divided by the passive beam's, or LQR's, mean step cost on its "
        "load (acld_gym.envs.scale; info['reward_scale'])",
    )
    observe_reward_scale: bool = _f(
        False,
        "-",
        "append log(reward scale) to the observation as its last entry: "
        "privileged, for a critic only; needs reward_scale",
    )
    observe_commands: bool = _f(
        False,
        "-",
        "append the commands still in flight (actuator_delay of them, the oldest first, "
        "in units of 120 V; the 'measurement' observation already ends with the newest) "
        "before any log(reward scale): what a delay-aware controller knows; none "
        "without a delay",
    )
    env_id: str = _f(
        "ACLDBeam-v1",
        "-",
        "one of this package's ids, the one the configuration belongs to (and the env is "
        "made as; recorded in the observation fingerprint)",
    )

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "load_case", check_load_case(self.load_case))
        check_choice("mesh", self.mesh, MESHES)
        check_choice("observer", self.observer, OBSERVERS)
        check_choice("obs_mode", self.obs_mode, OBS_MODES)
        for f in dataclasses.fields(self):
            md = f.metadata
            if f.type == "float" and md.get("low") is not None:  # incl. temperature
                set_(
                    self,
                    f.name,
                    check_real(
                        f.name, getattr(self, f.name), md["low"], md["high"], unit=md["unit"]
                    ),
                )
        if self.param_noise_max is not None:
            set_(
                self,
                "param_noise_max",
                check_real("param_noise_max", self.param_noise_max, 0.0, 1.0, low_open=True),
            )
        set_(
            self,
            "param_noise",
            check_param_noise(self.param_noise, self.mesh, self.param_noise_max),
        )
        if self.harmonic_modes is not None:
            modes = self.harmonic_modes
            if not isinstance(modes, (tuple, list)) or len(modes) != 2:
                raise ValueError(
                    f"harmonic_modes must be None or two frequencies [rad/s], got {modes!r}"
                )
            set_(
                self,
                "harmonic_modes",
                tuple(
                    check_real("harmonic_modes", w, 0.0, 1e7, low_open=True, unit="rad/s")
                    for w in modes
                ),
            )
        set_(self, "actuator_delay", check_int("actuator_delay", self.actuator_delay, 0, MAX_DELAY))
        for name in ("amplifier_bandwidth", "slew_rate"):
            value, md = getattr(self, name), self.__dataclass_fields__[name].metadata
            if value is not None:
                set_(self, name, check_real(name, value, md["low"], md["high"], unit=md["unit"]))
        if self.temperature_range is not None:
            rng = self.temperature_range
            if not isinstance(rng, (tuple, list)) or len(rng) != 2:
                raise ValueError(f"temperature_range must be None or (low, high) [°C], got {rng!r}")
            lo, hi = (check_temperature("temperature_range", t) for t in rng)
            if not lo < hi:
                raise ValueError(f"temperature_range must have low < high [°C], got {rng!r}")
            set_(self, "temperature_range", (lo, hi))
        check_choice("reward_scale", self.reward_scale, REWARD_SCALES)
        if not isinstance(self.observe_reward_scale, (bool, np.bool_)):
            raise ValueError(
                f"observe_reward_scale must be True or False, got {self.observe_reward_scale!r}"
            )
        set_(self, "observe_reward_scale", bool(self.observe_reward_scale))
        if self.observe_reward_scale and self.reward_scale is None:
            raise ValueError(
                "observe_reward_scale=True needs a reward_scale (e.g. "
                "reward_scale='passive'), got reward_scale=None"
            )
        if not isinstance(self.observe_commands, (bool, np.bool_)):
            raise ValueError(
                f"observe_commands must be True or False, got {self.observe_commands!r}"
            )
        set_(self, "observe_commands", bool(self.observe_commands))
        check_env_id(self.env_id, "env_id")
        check_episode_size(self.episode_length, self.dt)
        check_consistent(self)  # no field that another one silently overrides

    # --- derived --------------------------------------------------------------------
    @property
    def max_steps(self) -> int:
        """Steps of an episode, ``round(episode_length / dt)``."""
        return int(round(self.episode_length / self.dt))

    @property
    def randomized(self) -> bool:
        """Whether each episode draws its own plant (the design stays nominal)."""
        return self.param_noise > 0 or self.temperature_range is not None

    @property
    def slew_step(self) -> float | None:
        """The largest change of the amplifier's output per control period [V]."""
        return None if self.slew_rate is None else self.slew_rate * self.dt

    def nominal(self):
        """The nominal design of this configuration (:func:`acld_gym.design.nominal.
        nominal_design`, cached)."""
        std = max(self.sensor_noise, 1e-9)
        return nominal_design(self.dt, LOAD_SUBSTEPS, std, mesh=self.mesh, model_std=self.model_std)

    def harmonic_targets(self, nom) -> tuple[float, float]:
        """The random loads' harmonic targets [rad/s]: :attr:`harmonic_modes`, or the first
        two damped modes of the nominal plant of ``nom``."""
        if self.harmonic_modes is not None:
            return self.harmonic_modes
        return tuple(float(w) for w in nom.modes[:2])

    def replace(self, **changes) -> EnvConfig:
        """A copy with ``changes`` (validated; ``TypeError`` on an unknown field)."""
        return make_config(self, **changes)


_FIELDS = tuple(f.name for f in dataclasses.fields(EnvConfig))


def make_config(config: EnvConfig | None = None, **kwargs) -> EnvConfig:
    """``config`` (default: :class:`EnvConfig`'s defaults, ``ACLDBeam-v1``) with the fields
    in ``kwargs`` replaced; ``TypeError`` on a keyword that is no field, ``ValueError`` if
    ``kwargs`` are a registered id's settings that differ from the config's
    (:func:`acld_gym.envs.conflicts.check_config_keywords`)."""
    if config is not None and not isinstance(config, EnvConfig):
        raise TypeError(f"config must be an EnvConfig or None, got {type(config).__name__}")
    unknown = sorted(set(kwargs) - set(_FIELDS))
    if unknown:
        raise TypeError(
            f"unexpected keyword argument(s) {unknown}; the env takes the fields of "
            f"EnvConfig: {', '.join(_FIELDS)}"
        )
    check_config_keywords(config, kwargs)  # gym.make(id, config=...): the id's settings
    if config is None:
        return EnvConfig(**kwargs)
    return dataclasses.replace(config, **kwargs) if kwargs else config


def config_table() -> str:
    """A Markdown table of :class:`EnvConfig`'s fields: default, unit, range, meaning."""
    rows = ["| field | default | unit | range | meaning |", "|---|---|---|---|---|"]
    for f in dataclasses.fields(EnvConfig):
        md = f.metadata
        rng = (
            ""
            if md.get("low") is None
            else f"[{md['low']:g}, {'inf' if md['high'] is None else format(md['high'], 'g')}]"
        )
        rows.append(f"| `{f.name}` | `{f.default!r}` | {md['unit']} | {rng} | {md['doc']} |")
    return "\n".join(rows)


class ConfigAttributes(FixedSettings):
    """The configuration's fields as read-only attributes of an env (``env.dt``,
    ``env.obs_mode``, ...; ``env.observer_kind`` is ``config.observer``), for code that
    reads them from an env or through SB3's ``get_attr``; none assignable once the env is
    built (:mod:`acld_gym.envs.fixed`)."""

    config: EnvConfig
    FIXED_NAMES = fixed_names(EnvConfig)

    load_case = property(lambda self: self.config.load_case, doc="The default load case.")
    mesh = property(lambda self: self.config.mesh)
    dt = property(lambda self: self.config.dt, doc="Control period [s].")
    episode_length = property(lambda self: self.config.episode_length, doc="[s]")
    observer_kind = property(lambda self: self.config.observer)
    obs_mode = property(lambda self: self.config.obs_mode)
    sensor_noise = property(lambda self: self.config.sensor_noise, doc="[m]")
    y_ref = property(lambda self: self.config.y_ref, doc="[m]")
    lam = property(lambda self: self.config.lam)
    param_noise = property(lambda self: self.config.param_noise)
    deflection_limit = property(lambda self: self.config.deflection_limit, doc="[m]")
    env_id = property(lambda self: self.config.env_id)
    #: Voltage limit of the action [V] (:data:`acld_gym.physics.actuator.V_LIMIT`).
    v_max = V_LIMIT
    #: Measurements in the ``"measurement"`` observation.
    obs_hist = OBS_HIST
