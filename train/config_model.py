"""The ``model:`` mapping of a training config, checked (:func:`check_model`, called by the
config's validation): every key a keyword of the SB3 algorithm, or a field of
:class:`train.core.search_settings.RandomSearch` for ``vrs``, every number in range."""

from __future__ import annotations

import inspect
from dataclasses import fields

from acld_gym.util.validate import check_int, check_real

from .config_algos import algo_class
from .core.search_settings import RandomSearch

__all__ = ["check_model"]

#: Smallest value of the SB3 integer arguments that may be below 1 (-1: "as many as").
_INT_MIN = {
    "seed": 0,
    "verbose": 0,
    "learning_starts": 0,
    "sde_sample_freq": -1,
    "gradient_steps": -1,
}

#: Model keys that take one number only: never a schedule or a list (a list there reached the
#: env's reward scale and failed as an env setting, naming none).
_SCALAR_ONLY = frozenset({"gamma", "gae_lambda", "n_steps", "batch_size", "n_epochs", "tau"})


def check_model(cfg) -> None:
    """``ValueError`` naming the key unless ``cfg.model`` (and, for the SB3 algorithms,
    ``cfg.normalize``) holds only keys the algorithm takes, with numbers in range."""
    if cfg.algo == "vrs":
        _check_vrs(cfg.model)
    else:
        _check_sb3(cfg)


def _check_vrs(model: dict) -> None:
    """The ``model:`` of ``vrs``: fields of :class:`RandomSearch`, whose own checks then
    apply."""
    known = sorted(f.name for f in fields(RandomSearch))
    unknown = sorted(str(k) for k in model if k not in known)
    if unknown:
        raise ValueError(f"model: unknown key(s) {unknown} for VRS; expected some of {known}")
    RandomSearch(**model)


def _check_sb3(cfg) -> None:
    # stable-baselines3 (torch) is slow to import: only a config of an SB3 algorithm needs it
    from stable_baselines3.common.vec_env import VecNormalize

    allowed = set(inspect.signature(VecNormalize).parameters) - {"venv", "gamma"}
    bad = sorted(str(k) for k in set(cfg.normalize) - allowed)
    if bad:
        raise ValueError(f"normalize: unknown key(s) {bad}; expected some of {sorted(allowed)}")
    try:
        cls = algo_class(cfg.algo)
    except ImportError:  # sb3-contrib not installed: checked when the run starts
        return
    params = inspect.signature(cls).parameters
    unknown = sorted(str(k) for k in cfg.model if k not in params)
    if unknown:
        raise ValueError(
            f"model: unknown key(s) {unknown} for {cfg.algo.upper()}; expected some of "
            f"{sorted(k for k in params if k not in ('env', 'self'))}"
        )
    if not isinstance(cfg.model["policy"], str):
        raise ValueError(f"model.policy must be a policy's name, got {cfg.model['policy']!r}")
    for key, value in cfg.model.items():
        default = params[key].default
        if (
            isinstance(default, bool)
            or default is None
            or key == "policy"
            or (isinstance(value, (dict, list, tuple)) and key not in _SCALAR_ONLY)
        ):  # a schedule, a train_freq
            continue
        if isinstance(default, (int, float)) and not isinstance(value, bool):
            if isinstance(default, int) and key not in ("learning_rate", "clip_range"):
                check_int(f"model.{key}", value, _INT_MIN.get(key, 1))
            elif key in ("gamma", "gae_lambda"):  # a discount, a GAE weight: (0, 1]
                check_real(f"model.{key}", value, 0.0, 1.0, low_open=True)
            else:
                check_real(f"model.{key}", value, 0.0)
