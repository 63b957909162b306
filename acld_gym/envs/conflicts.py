"""Settings the env would silently override or not honour, refused in one place.

Every env class (the single env, the vector env and the SB3 adapter over it) builds its
configuration with :func:`acld_gym.envs.config.make_config`, which calls
:func:`check_config_keywords`, and validates it once in
:class:`acld_gym.envs.config.EnvConfig`, which calls :func:`check_consistent`; the spec
setters of the two env classes call :func:`made_spec`, and the load of an episode
(``reset(options=...)``, a vector env's ``load_case``) goes through :func:`check_case`.
Each refusal is one ``ValueError`` naming the argument and the reason:

* ``config=`` with a registered id's settings, ``gym.make(id, config=...)``: the id's
  keywords would replace the config's fields (refused where they differ);
* a field an id sets for its mesh (:data:`MESH_TIED`: ``ACLDBeam-v0``'s
  ``param_noise_max=0.5`` and ``harmonic_modes``), kept while ``mesh`` changes;
* ``temperature`` other than 20 °C with a ``temperature_range`` (the range draws it);
* ``env_id``: one of this package's ids and, for an env made by ``gym.make``, its id;
* ``max_episode_steps`` beyond the episode's ``episode_length / dt`` steps;
* a load the sampled integration cannot resolve: it reads the load at the ends of
  :data:`LOAD_SUBSTEPS` sub-steps per control period (first-order hold,
  :mod:`acld_gym.design.discrete`), so a ``Harmonic`` at or above the sub-step's Nyquist
  frequency ``pi / (dt / 10)`` (31416 rad/s at 1 kHz) would alias, and a ``Pulse`` or
  ``Harmonic`` shorter than a sub-step, or ``Samples`` finer than one, would be missed in
  part or whole. Below the Nyquist frequency a harmonic's relative error is about
  ``(omega h)^2 / 12`` (h the sub-step).
"""

from __future__ import annotations

import math
import sys

from acld_gym.envs.fixed import FixedSettings
from acld_gym.envs.ids import PRESETS, check_env_id
from acld_gym.envs.limits import PARAM_NOISE_MAX
from acld_gym.envs.registration import make_limit, plain_spec
from acld_gym.physics.loads import Harmonic, Samples, TipLoad, check_load_case
from acld_gym.physics.temperature import T_REF
from acld_gym.util.validate import check_int

__all__ = [
    "LOAD_SUBSTEPS",
    "MESH_TIED",
    "check_case",
    "check_resolution",
    "check_consistent",
    "check_config_keywords",
    "check_limit",
    "made_spec",
]

#: Load sub-steps per control period of the sampled plant (the nominal design's).
LOAD_SUBSTEPS = 10
#: The fields an id may set for its own mesh only.
MESH_TIED = ("param_noise_max", "harmonic_modes")
#: A random load's harmonic lies within this factor of its target (``random_load``).
_SPREAD = 1.05
_DEFAULT_ID = "ACLDBeam-v1"


def substep_nyquist(dt: float) -> float:
    """The Nyquist frequency of the load sub-step at control period ``dt`` [s]:
    ``pi * LOAD_SUBSTEPS / dt`` [rad/s], one expression for every check (so a frequency
    exactly at the limit is refused whichever check sees it)."""
    return math.pi * LOAD_SUBSTEPS / dt


def check_resolution(load: TipLoad, dt: float, name: str = "load_case") -> TipLoad:
    """``load`` if the sampled integration at control period ``dt`` [s] resolves every
    component (module docstring); else ``ValueError`` naming ``name`` and the limit."""
    h = dt / LOAD_SUBSTEPS
    nyquist = substep_nyquist(dt)
    at = f"at dt = {dt:g} s"
    for c in load.components:
        kind = type(c).__name__
        if isinstance(c, Harmonic) and not c.frequency < nyquist:
            raise ValueError(
                f"{name}: Harmonic.frequency must be below the Nyquist frequency of the load "
                f"sub-step, pi / (dt / {LOAD_SUBSTEPS}) = {nyquist:.6g} rad/s {at} (the sampled "
                f"integration would alias it), got {c.frequency!r}"
            )
        field, span = ("step", c.step) if isinstance(c, Samples) else ("duration", c.duration)
        if span < h * (1.0 - 1e-9):
            raise ValueError(
                f"{name}: {kind}.{field} must be at least the load sub-step dt / "
                f"{LOAD_SUBSTEPS} = {h:g} s {at} (the integration reads the load once per "
                f"sub-step), got {span!r}"
            )
    return load


def check_case(value, dt: float, name: str = "load_case"):
    """A load case (:func:`acld_gym.physics.loads.check_load_case`) whose load, if it is a
    :class:`TipLoad`, the integration at ``dt`` resolves (:func:`check_resolution`)."""
    case = check_load_case(value, name)
    if isinstance(case, TipLoad):
        check_resolution(case, dt, name)
    return case


def check_consistent(config) -> None:
    """``ValueError`` if fields of ``config`` (an :class:`acld_gym.envs.config.EnvConfig`,
    each field valid) contradict each other: a temperature with a temperature range, a
    field its id set for another mesh, a load or random-load target the integration does
    not resolve."""
    c = config
    if c.temperature_range is not None and c.temperature != T_REF:
        raise ValueError(
            f"temperature={c.temperature!r} is not used with temperature_range="
            f"{c.temperature_range!r} (the range draws the temperature per episode): set "
            f"temperature_range=None for a fixed temperature, or leave temperature at {T_REF:g}"
        )
    fields = PRESETS[c.env_id]
    mesh = fields.get("mesh", "converged")
    kept = [f for f in MESH_TIED if f in fields and getattr(c, f) == fields[f]]
    if c.mesh != mesh and kept:
        settings = ", ".join(f"{f}={fields[f]!r}" for f in kept)
        raise ValueError(
            f"mesh={c.mesh!r} with {c.env_id}'s {settings}, set for mesh={mesh!r} (the "
            f"certified param_noise bound of mesh={c.mesh!r} is {PARAM_NOISE_MAX[c.mesh]}): "
            f"pass {' and '.join(kept)} for this mesh (None: its own), or start from "
            f"{_DEFAULT_ID}"
        )
    if isinstance(c.load_case, TipLoad):
        check_resolution(c.load_case, c.dt)
    nyquist = substep_nyquist(c.dt)
    if c.harmonic_modes is not None and not _SPREAD * max(c.harmonic_modes) < nyquist:
        raise ValueError(
            f"harmonic_modes must be below {nyquist / _SPREAD:.6g} rad/s at dt = {c.dt:g} s "
            f"(a random load's harmonic, up to {_SPREAD} x its target, must stay below the "
            f"load sub-step's Nyquist frequency {nyquist:.6g} rad/s), got {c.harmonic_modes!r}"
        )


def check_config_keywords(config, kwargs: dict) -> None:
    """``ValueError`` if ``kwargs`` carry a registered id's settings (``env_id`` among
    them, as ``gym.make(id, config=config)`` passes them) that would replace different
    values of ``config`` (its ``env_id`` becomes the id's). Keywords without ``env_id``
    replace the config's fields as documented (:func:`acld_gym.envs.config.make_config`)."""
    if config is None or "env_id" not in kwargs:
        return
    env_id = check_env_id(kwargs["env_id"])
    fields = PRESETS[env_id]
    replaced = [  # env_id itself is the made id's (made_spec): the config takes it
        f
        for f, value in fields.items()
        if f != "env_id" and f in kwargs and kwargs[f] == value and getattr(config, f) != value
    ]
    if replaced:
        theirs = ", ".join(f"{f}={getattr(config, f)!r}" for f in replaced)
        raise ValueError(
            f"config: {env_id}'s settings would replace its {theirs}; build it with "
            f"acld_gym.envs.presets.preset({env_id!r}, ...), or make {config.env_id!r} with it"
        )


def check_limit(limit, steps: int, name: str = "max_episode_steps") -> int:
    """``limit`` as an int in [1, ``steps``]: a limit beyond the episode's ``steps`` (its
    ``episode_length / dt``, where the env ends it) is refused, not reported."""
    n = check_int(name, limit, 1)
    if n > steps:
        raise ValueError(
            f"{name}={n} exceeds the episode, episode_length / dt = {steps} steps, where "
            "the env ends it: set episode_length for longer episodes"
        )
    return n


def made_spec(spec, config, steps: int):
    """The spec an env reports when ``spec`` is set on it (its spec setter calls this
    directly; ``gym.make`` and ``make_vec`` set it): a plain spec with
    ``max_episode_steps=steps``. ``ValueError`` if the spec's id is one of this package's
    and not ``config.env_id``, or if ``gym.make`` was given a ``max_episode_steps`` beyond
    ``steps`` (its ``TimeLimit`` would report steps the env never takes)."""
    if spec is None:
        return None
    if spec.id in PRESETS and spec.id != config.env_id:
        raise ValueError(
            f"env_id={config.env_id!r} is not the id this env is made as, {spec.id!r}: "
            f"make {config.env_id!r} instead (or pass env_id={spec.id!r})"
        )
    caller = sys._getframe(2)  # this function <- the setter <- its caller
    while caller is not None and caller.f_code is FixedSettings.__setattr__.__code__:
        caller = caller.f_back  # (the env's __setattr__, between the setter and gym.make)
    limit = make_limit(caller)
    if limit is not None and limit != -1:
        check_limit(limit, steps)
    return plain_spec(spec, steps)
