"""Checks of a training config's algorithm settings, beyond the fields of
:class:`train.config.TrainConfig` themselves: :func:`check_buildable`, the algorithm built
once on its training env, which a command calls before it computes anything, so that a
setting only the algorithm's own constructor reads (a policy's keyword argument, a
schedule) fails in a second, not after the references. The checks run when a config is
built live below the config (:func:`train.config_model.check_model`, the ``model:``
mapping; :mod:`train.config_yaml`, the file's size and keys) and are importable from here
as before."""

from __future__ import annotations

import contextlib
import io
import warnings

import gymnasium as gym

import acld_gym

from .config_model import check_model
from .config_yaml import MAX_BYTES, MAX_VALUES, UniqueKeyLoader, check_size
from .core.threshold import RestartRule

__all__ = [
    "check_model",
    "check_buildable",
    "check_size",
    "MAX_VALUES",
    "MAX_BYTES",
    "UniqueKeyLoader",
]


def check_buildable(cfg, env_id: str | None = None) -> None:
    """Build ``cfg``'s algorithm once on its training env (SB3: the model on
    :func:`train.vec.make_vec_env`, with the whitening's first-layer check; ``vrs``: its
    settings) and drop it: ``ValueError`` naming the setting a constructor refuses, or a
    ``restart_above`` that does not apply to ``env_id`` (a bare number on another level
    than the one it was calibrated on,
    :meth:`train.core.threshold.RestartRule.check_level`). A second or two, no env step;
    call it before computing anything."""
    env_id = env_id or acld_gym.ENV_ID
    rule = RestartRule.parse(cfg.restart_above)
    if rule is not None:  # a bare number is one level's cost: refused on the others
        rule.check_level(env_id)
    if cfg.algo == "vrs":  # RandomSearch is built by check_model; here its envs, one each
        _check_envs(cfg, env_id)
        return
    # the SB3 side (stable-baselines3, torch) is slow to import: only an SB3 recipe needs it
    from .core.sb3_train import first_linear, make_model
    from .vec import make_vec_env

    try:
        venv = make_vec_env(cfg, 0, env_id)
    except (TypeError, ValueError) as exc:  # the options on this id (its preset's fields)
        raise ValueError(f"env_kwargs on {env_id}: {exc}") from None
    try:  # quietly: the run prints SB3's warnings and messages when it builds the model
        with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
            warnings.simplefilter("ignore")
            model = make_model(cfg, venv, 0)
        if cfg.whiten_steps and not callable(getattr(model.policy, "fold_whitening", None)):
            first_linear(model)
    except ValueError as exc:  # the policy's or SB3's own check: in the model: mapping
        raise ValueError(str(exc) if str(exc).startswith("model") else f"model: {exc}") from None
    except Exception as exc:  # noqa: BLE001  (whatever a constructor raises: its message)
        raise ValueError(
            f"model: {cfg.algo.upper()} refuses the settings ({type(exc).__name__}: {exc})"
        ) from None
    finally:
        venv.close()


def _check_envs(cfg, env_id: str) -> None:
    """Build one env of ``env_id`` per training load case with the config's options (as the
    run will, on top of the id's preset), and close it; ``ValueError`` naming the options."""
    for case in cfg.load_weights:
        try:
            gym.make_vec(env_id, num_envs=1, load_case=case, **cfg.env_kwargs).close()
        except (TypeError, ValueError) as exc:
            raise ValueError(f"env_kwargs on {env_id}: {exc}") from None
