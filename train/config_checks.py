"""Checks of a training config's algorithm settings, beyond the fields of
:class:`train.config.TrainConfig` themselves: :func:`check_model`, the ``model:`` mapping
(called by the config's validation: every key a keyword of the SB3 algorithm, or a field of
:class:`train.core.search.RandomSearch` for ``vrs``, every number in range), and
:func:`check_buildable`, the algorithm built once on its training env, which a command calls
before it computes anything, so that a setting only the algorithm's own constructor reads (a
policy's keyword argument, a schedule) fails in a second, not after the references."""

from __future__ import annotations

import contextlib
import inspect
import io
import warnings
from dataclasses import fields

import yaml

from acld_gym.util.validate import check_int, check_real

__all__ = ["check_model", "check_buildable", "check_size", "MAX_VALUES", "MAX_BYTES"]

#: The most values (every list item and mapping entry, YAML aliases counted each time they
#: are used) and bytes a config file may hold; a recipe has under 100 values and 3 kB.
MAX_VALUES = 10_000
MAX_BYTES = 2**20

#: Smallest value of the SB3 integer arguments that may be below 1 (-1: "as many as").
_INT_MIN = {
    "seed": 0,
    "verbose": 0,
    "learning_starts": 0,
    "sde_sample_freq": -1,
    "gradient_steps": -1,
}


def check_model(cfg) -> None:
    """``ValueError`` naming the key unless ``cfg.model`` (and, for the SB3 algorithms,
    ``cfg.normalize``) holds only keys the algorithm takes, with numbers in range."""
    if cfg.algo == "vrs":
        _check_vrs(cfg.model)
    else:
        _check_sb3(cfg)


def _check_vrs(model: dict) -> None:
    """The ``model:`` of ``vrs``: fields of :class:`train.core.search.RandomSearch`, whose
    own checks then apply (imported lazily: it imports the env)."""
    from .core.search import RandomSearch

    known = sorted(f.name for f in fields(RandomSearch))
    unknown = sorted(str(k) for k in model if k not in known)
    if unknown:
        raise ValueError(f"model: unknown key(s) {unknown} for VRS; expected some of {known}")
    RandomSearch(**model)


#: Model keys that take one number only: never a schedule or a list (a list there reached the
#: env's reward scale and failed as an env setting, naming none).
_SCALAR_ONLY = frozenset({"gamma", "gae_lambda", "n_steps", "batch_size", "n_epochs", "tau"})


class UniqueKeyLoader(yaml.SafeLoader):
    """YAML's safe loader that refuses a key given twice in one mapping (plain YAML keeps the
    last silently: ``timesteps: 1000`` then ``timesteps: 2000`` would train 2000)."""

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":  # '<<': merged keys may be replaced
                    continue
                key = self.construct_object(key_node, deep=deep)
                try:
                    duplicate = key in seen
                    seen.add(key)
                except TypeError:  # an unhashable key: the base class refuses it
                    continue
                if duplicate:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"key {key!r} given twice", key_node.start_mark
                    )
        return super().construct_mapping(node, deep)


def _check_sb3(cfg) -> None:
    from stable_baselines3.common.vec_env import VecNormalize

    from .config import algo_class

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


def check_buildable(cfg, env_id: str | None = None) -> None:
    """Build ``cfg``'s algorithm once on its training env (SB3: the model on
    :func:`train.vec.make_vec_env`, with the whitening's first-layer check; ``vrs``: its
    settings) and drop it: ``ValueError`` naming the setting a constructor refuses, or a
    ``restart_above`` that does not apply to ``env_id`` (a bare number on another level
    than the one it was calibrated on,
    :meth:`train.core.threshold.RestartRule.check_level`). A second or two, no env step;
    call it before computing anything."""
    import acld_gym

    from .core.threshold import RestartRule

    env_id = env_id or acld_gym.ENV_ID
    rule = RestartRule.parse(cfg.restart_above)
    if rule is not None:  # a bare number is one level's cost: refused on the others
        rule.check_level(env_id)
    if cfg.algo == "vrs":  # RandomSearch is built by check_model; here its envs, one each
        _check_envs(cfg, env_id)
        return
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
    import gymnasium as gym

    for case in cfg.load_weights:
        try:
            gym.make_vec(env_id, num_envs=1, load_case=case, **cfg.env_kwargs).close()
        except (TypeError, ValueError) as exc:
            raise ValueError(f"env_kwargs on {env_id}: {exc}") from None


def check_size(data, path) -> None:
    """``ValueError`` naming ``path`` if the parsed config ``data`` holds more than
    :data:`MAX_VALUES` values, YAML aliases expanded (a few lines of nested aliases can
    stand for billions of values, which comparing or recording the config would build)."""
    stack, count = [data], 0
    while stack:
        value = stack.pop()
        count += 1
        if count > MAX_VALUES:
            raise ValueError(f"{path}: more than {MAX_VALUES} values (aliases expanded)")
        if isinstance(value, dict):
            stack += [*value.keys(), *value.values()]
        elif isinstance(value, list):
            stack += value
