"""An episode's ingredients: the reset options, the tip load and the (randomized) plant the
env simulates, drawn from the episode's generator in a fixed order. The nominal design the
observer and baselines know is :mod:`acld_gym.design.nominal`; the loads are
:mod:`acld_gym.physics.loads`."""

from __future__ import annotations

import numpy as np

from acld_gym.design.discrete import SampledSystem, discretize
from acld_gym.design.nominal import NominalDesign
from acld_gym.envs.conflicts import check_case
from acld_gym.physics.actuator import with_amplifier
from acld_gym.physics.loads import TipLoad, case_load, random_load
from acld_gym.physics.temperature import shifted_parameters
from acld_gym.physics.uncertainty import randomized_parameters

__all__ = [
    "reset_options",
    "draw_episode",
    "draw_noise",
    "fixed_plant",
    "sampled_plant",
    "randomized_plant",
    "passive_plant",
    "RESET_OPTIONS",
]

#: The keys of ``reset(options=...)``: a named case or a TipLoad (``"load_case"``), or a
#: TipLoad (``"load"``), for this episode only.
RESET_OPTIONS = ("load_case", "load")


def reset_options(options, default_case, dt: float):
    """The load case of ``reset(options=...)``: ``options["load_case"]`` (a named case or a
    :class:`TipLoad`), ``options["load"]`` (a :class:`TipLoad`) or ``default_case``;
    ``ValueError`` on anything else (before the env changes), or on a load the env's
    integration at control period ``dt`` [s] cannot resolve
    (:func:`acld_gym.envs.conflicts.check_case`)."""
    if options is not None and not isinstance(options, dict):
        raise ValueError(f"options must be a dict or None, got {options!r}")
    options = dict(options or {})
    unknown = sorted(set(options) - set(RESET_OPTIONS))
    if unknown:
        raise ValueError(
            f"options: unknown key(s) {unknown}; expected one of {list(RESET_OPTIONS)}"
        )
    if len(options) > 1:
        raise ValueError("options: give 'load_case' or 'load', not both")
    if "load" in options:
        if not isinstance(options["load"], TipLoad):
            raise ValueError(f"options['load'] must be a TipLoad, got {options['load']!r}")
        return check_case(options["load"], dt, "options['load']")
    return check_case(options.get("load_case", default_case), dt, "options['load_case']")


def draw_episode(
    rng: np.random.Generator, case, nom: NominalDesign, config, harmonic_modes: tuple[float, float]
) -> tuple[TipLoad, SampledSystem | None]:
    """The load and the plant of an episode, drawn from ``rng`` in a fixed order: the load (a
    random one for ``"random"``, aimed at ``harmonic_modes`` [rad/s]), the parameters
    (``config.param_noise`` > 0), the temperature (``config.temperature_range``). The plant
    is None when the configuration has one fixed plant (:func:`fixed_plant`)."""
    plant = nom.plant
    load = case_load(case)
    if load is None:  # the random case
        load = random_load(rng, config.episode_length, plant.dt / plant.substeps, harmonic_modes)
    if not config.randomized:
        return load, None
    params = nom.truth.params
    if config.param_noise > 0:
        params = randomized_parameters(rng, config.param_noise, params)
    temperature = config.temperature
    if config.temperature_range is not None:
        temperature = float(rng.uniform(*config.temperature_range))
    return load, sampled_plant(
        nom, shifted_parameters(params, temperature), config.amplifier_bandwidth
    )


def fixed_plant(nom: NominalDesign, config) -> SampledSystem:
    """The sampled plant of a configuration without per-episode draws: the nominal one (the
    same object), at ``config.temperature``, driven through its amplifier."""
    return sampled_plant(nom, _shifted(nom, config), config.amplifier_bandwidth)


def passive_plant(nom: NominalDesign, config) -> SampledSystem:
    """The configuration's plant as the load alone drives it (the reward scale's,
    :mod:`acld_gym.envs.scale`): the nominal beam at ``config.temperature``, without the
    amplifier (at zero voltage it does not act)."""
    return sampled_plant(nom, _shifted(nom, config), None)


def _shifted(nom: NominalDesign, config):
    """The nominal parameters at ``config.temperature``, or None where they are the nominal
    ones (20 °C)."""
    params = shifted_parameters(nom.truth.params, config.temperature)
    return None if params is nom.truth.params else params


def sampled_plant(nom: NominalDesign, params, bandwidth: float | None) -> SampledSystem:
    """The truth plant with material parameters ``params`` (None: the nominal ones) and, with
    an amplifier ``bandwidth`` [Hz], its first-order lag (:func:`acld_gym.physics.actuator.
    with_amplifier`: the state gains the patch voltage), sampled like the nominal plant. A
    randomized plant is the Galerkin projection of the physical beam with those parameters,
    hence stable (:mod:`acld_gym.physics.truth`)."""
    if params is None and bandwidth is None:
        return nom.plant
    A, B, E, _ = nom.truth.state_space(params)
    if bandwidth is not None:
        A, B, E = with_amplifier(A, B, E, bandwidth)
    return discretize(A, B, E, nom.plant.dt, nom.plant.substeps)


def draw_noise(
    rng: np.random.Generator, std: float, n: int | None = None, out: np.ndarray | None = None
) -> np.ndarray:
    """An episode's sensor noise, ``n`` (or ``out.size``) draws of N(0, std^2) [m] from
    ``rng`` (into ``out`` if given): the numbers of ``rng.normal(0.0, std, n)``, which is
    ``0.0 + std * z`` with z the generator's standard normals."""
    z = rng.standard_normal(n, out=out)
    z *= std
    return z


def randomized_plant(
    rng: np.random.Generator, param_noise: float, nom: NominalDesign
) -> SampledSystem:
    """The nominal truth plant with randomized material parameters
    (:func:`acld_gym.physics.uncertainty.randomized_parameters`), sampled like the nominal
    one (:func:`sampled_plant`)."""
    return sampled_plant(nom, randomized_parameters(rng, param_noise, nom.truth.params), None)
