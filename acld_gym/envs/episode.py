"""An episode's ingredients: the nominal design the observer and baselines know, the tip load,
and the (randomized) plant the env simulates."""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from acld_gym.design.discrete import SampledSystem, discretize
from acld_gym.design.observer import (
    MODEL_STD,
    DiscreteObserver,
    discrete_kalman,
    discrete_thesis,
)
from acld_gym.design.pipeline import DESIGN_ORDER, Design, design
from acld_gym.design.reduction import BASES
from acld_gym.design.simulate import simulate
from acld_gym.physics.loads import Harmonic, Pulse, Samples, TipLoad, thesis_load
from acld_gym.physics.params import BeamParameters
from acld_gym.physics.plant import Plant
from acld_gym.physics.truth import MESHES
from acld_gym.physics.truth import plant as nominal_plant
from acld_gym.util.validate import check_choice

__all__ = ["Nominal", "nominal", "random_load", "draw_episode", "randomized_parameters",
           "randomized_plant", "reset_options", "LOAD_CASES", "OBS_MODES", "OBSERVERS",
           "SENSOR_NOISE_M", "RANDOMIZED", "PARAM_NOISE_MAX", "PARAM_NOISE_CLIP"]


LOAD_CASES = (1, 2, 3, "random")


#: Default tip-sensor noise std [m]: 0.1 um, the resolution of a laser displacement
#: sensor. (With 1 um the high-gain LQR turns the noise into voltage jitter and the
#: thesis's settling times are not reached.)
SENSOR_NOISE_M = 1e-7


OBS_MODES = ("estimate", "measurement", "full")


OBSERVERS = ("kalman", "thesis")


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
    """Nominal design of the ``mesh`` plant (:data:`acld_gym.physics.truth.MESHES`) sampled at
    ``dt``, with the design order :data:`acld_gym.design.pipeline.DESIGN_ORDER` and the Kalman
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
    (:mod:`acld_gym.physics.truth`)."""
    truth = nom.truth
    A, B, E, _ = truth.state_space(randomized_parameters(rng, param_noise, truth.params))
    return discretize(A, B, E, nom.plant.dt, nom.plant.substeps)
