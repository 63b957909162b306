"""The argument checks every reference shares (:mod:`baselines.policies`,
:mod:`baselines.oracle`, :mod:`baselines.engineer`) and their CLIs': each raises
``ValueError`` naming the argument and what was expected, before anything is built
(:mod:`acld_gym.util.validate`)."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np

from acld_gym.design.nominal import NominalDesign, nominal_design
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.config import EnvConfig, check_param_noise
from acld_gym.envs.presets import check_env_id
from acld_gym.physics.truth import MESHES
from acld_gym.util.atomic import check_directory, check_writable
from acld_gym.util.validate import check_choice, check_int, check_real, shown

__all__ = [
    "MAX_HORIZON",
    "DEFAULT_DT",
    "positive",
    "lqr_weight",
    "MAX_LQR_WEIGHT",
    "non_negative",
    "horizon",
    "flag",
    "nominal",
    "design",
    "matching",
    "acld_env",
    "env_config",
    "model_std",
    "input_directory",
    "folder_name",
    "outputs",
    "param_noise",
]

#: The longest QP horizon [periods] of an MPC (its prediction matrices grow as H^2 x n).
MAX_HORIZON = 1000
#: The control period a reference is designed for when neither ``dt`` nor ``nom`` is given.
DEFAULT_DT = 1e-3


def positive(name: str, value, unit: str = "") -> float:
    """``value`` as a float if it is a finite real number > 0."""
    return check_real(name, value, 0.0, low_open=True, unit=unit)


#: The largest LQR state weight taken: nine decades above the thesis's 1e11; from about 5e28
#: on the discrete Riccati equation is numerically singular and scipy's solver fails.
MAX_LQR_WEIGHT = 1e20


def lqr_weight(value, name: str = "weight") -> float:
    """An LQR state weight: a finite real number in (0, :data:`MAX_LQR_WEIGHT`]."""
    return check_real(name, value, 0.0, MAX_LQR_WEIGHT, low_open=True)


def non_negative(name: str, value, unit: str = "") -> float:
    """``value`` as a float if it is a finite real number >= 0."""
    return check_real(name, value, 0.0, unit=unit)


def horizon(value, name: str = "horizon") -> int:
    """An MPC's horizon: an integer in [1, :data:`MAX_HORIZON`] periods."""
    return check_int(name, value, 1, MAX_HORIZON)


def flag(name: str, value) -> bool:
    """``value`` if it is True or False (not 0, 1 or a string)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {shown(value)}")
    return bool(value)


def _dt_range() -> tuple[float, float]:
    md = EnvConfig.__dataclass_fields__["dt"].metadata
    return md["low"], md["high"]


def nominal(owner: str, dt=None, nom=None, mesh=None):
    """The nominal design (:class:`acld_gym.design.nominal.NominalDesign`) a reference is
    built on: ``nom`` as given, else :func:`acld_gym.design.nominal.nominal_design` of
    ``dt`` [s] (the env's range of control periods; default :data:`DEFAULT_DT`) and
    ``mesh`` (default ``"converged"``). With ``nom`` a ``dt`` or ``mesh`` that is not the
    design's is a conflict, refused naming both (it would be ignored)."""
    low, high = _dt_range()
    if dt is not None:
        dt = check_real("dt", dt, low, high, unit="s")
    if mesh is not None:
        check_choice("mesh", mesh, MESHES)
    if nom is None:
        return nominal_design(DEFAULT_DT if dt is None else dt, mesh=mesh or "converged")
    design(nom)
    if dt is not None and dt != nom.plant.dt:
        raise ValueError(
            f"{owner}: dt={dt!r} conflicts with nom, designed for dt={nom.plant.dt!r}: "
            "give one of them"
        )
    if mesh is not None and mesh != nom.mesh:
        raise ValueError(
            f"{owner}: mesh={mesh!r} conflicts with nom, designed for mesh={nom.mesh!r}: "
            "give one of them"
        )
    return nom


def design(nom, name: str = "nom"):
    """``nom`` if it is a :class:`acld_gym.design.nominal.NominalDesign`."""
    if not isinstance(nom, NominalDesign):
        raise ValueError(
            f"{name} must be a NominalDesign (acld_gym.design.nominal.nominal_design), "
            f"got {type(nom).__name__}"
        )
    return nom


def matching(owner: str, nom, config) -> None:
    """Refuse a configuration (``config``) of another plant or control period than the
    design ``nom``, naming both."""
    if config.mesh != nom.mesh or config.dt != nom.plant.dt:
        raise ValueError(
            f"{owner}: config (mesh={config.mesh!r}, dt={config.dt!r}) conflicts with nom "
            f"(mesh={nom.mesh!r}, dt={nom.plant.dt!r}): the design must be the config's"
        )


def acld_env(env, name: str = "env", ids: bool = True):
    """The :class:`acld_gym.envs.beam_env.ACLDBeamEnv` under ``env`` (any Gymnasium
    wrapper), or (``ids``) made from ``env`` if it is one of this package's ids
    (:func:`acld_gym.envs.presets.check_env_id`, checked as data before ``gym.make``)."""
    if isinstance(env, str) and ids:
        return gym.make(check_env_id(env, name)).unwrapped
    inner = getattr(env, "unwrapped", None)
    if not isinstance(inner, ACLDBeamEnv):
        ids_too = " or one of this package's ids" if ids else ""
        raise ValueError(f"{name} must be an ACLDBeam env (any wrapper){ids_too}, got {shown(env)}")
    return inner


def env_config(config, name: str = "config"):
    """``config`` if it is an :class:`acld_gym.envs.config.EnvConfig`."""
    if not isinstance(config, EnvConfig):
        raise ValueError(f"{name} must be an EnvConfig, got {type(config).__name__}")
    return config


def model_std(value, name: str = "model_std"):
    """None, one finite value >= 0, or a 1-D array of them (one per state)."""
    if value is None or np.ndim(value) == 0:
        return None if value is None else non_negative(name, value)
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        a = None
    if a is None or a.ndim != 1 or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ValueError(f"{name} must be a number >= 0 or a vector of them, got {shown(value)}")
    return a


def input_directory(path, what: str) -> Path:
    """``path`` if it is an existing directory, else ``ValueError`` naming ``what``."""
    p = Path(path)
    if not p.is_dir():
        state = "is not a directory" if p.exists() else "does not exist"
        raise ValueError(f"{what}: {str(path)!r} {state}")
    return p


def folder_name(name, what: str) -> str:
    """``name`` if it names a folder inside a directory (no separator, not ``.``/``..``)."""
    if not isinstance(name, str) or name in ("", ".", "..") or "/" in name or "\\" in name:
        raise ValueError(f"{what}: expected a folder name, got {shown(name)}")
    return name


def outputs(files: dict, directories: dict | None = None) -> None:
    """A CLI's output paths, flag -> path (None: not asked for): each file writable, no two
    the same file, each directory usable (:mod:`acld_gym.util.atomic`); else ``ValueError``
    naming the flag. Call it before computing anything."""
    seen: dict = {}
    for what, path in files.items():
        if path:
            where = check_writable(path, what).resolve()
            if where in seen:
                raise ValueError(f"{seen[where]} and {what} name the same file {str(path)!r}")
            seen[where] = what
    for what, path in (directories or {}).items():
        if path:
            check_directory(path, what)


def param_noise(value, mesh: str, what: str = "--param-noise") -> float:
    """``value`` if it is a ``param_noise`` the env accepts on ``mesh``
    (:func:`acld_gym.envs.config.check_param_noise`), else ``ValueError`` naming ``what``."""
    try:
        return check_param_noise(value, mesh)
    except ValueError as exc:
        raise ValueError(f"{what}: {exc}") from None
