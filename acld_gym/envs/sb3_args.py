"""The arguments of :class:`acld_gym.envs.sb3.SB3VecEnv` made into the vector env it adapts:
a level id (``env_id=``), an existing env (``venv=``) or a configuration (``config=`` and
the env's keywords), with the sub-env count, checked. Every fault is one ``ValueError``
naming the argument."""

from __future__ import annotations

import gymnasium as gym
from gymnasium.vector import VectorEnv

from acld_gym.envs.config import EnvConfig
from acld_gym.envs.presets import check_env_id
from acld_gym.envs.vector_env import ACLDBeamVectorEnv
from acld_gym.util.validate import shown

__all__ = ["count_of", "build_venv"]

#: Keywords of ``gym.make_vec`` itself, not of the env: the adapter builds the native env.
_MAKE_VEC_OWN = ("vectorization_mode", "vector_kwargs")


def count_of(positional, env_kwargs: dict) -> int | None:
    """The ``num_envs`` given to the adapter, positionally or as a keyword (taken out of
    ``env_kwargs``), or None; a string (a level id where the count goes) and a count given
    both ways are refused with one line naming ``num_envs``."""
    keyword = env_kwargs.pop("num_envs", None)
    for value in (positional, keyword):
        if isinstance(value, str):
            raise ValueError(
                f"num_envs: expected the number of sub-envs, got {value!r}; a level id goes "
                f"in env_id=, e.g. SB3VecEnv(8, env_id={value!r})"
            )
    if positional is not None and keyword is not None:
        raise ValueError(
            f"num_envs: given twice ({shown(positional)} and num_envs={shown(keyword)}); "
            "pass it once"
        )
    return keyword if positional is None else positional


def build_venv(
    num_envs: int | None,
    venv: VectorEnv | None,
    config: EnvConfig | None,
    env_id: str | None,
    env_kwargs: dict,
) -> VectorEnv:
    """The vector env the adapter steps (before its ``wrappers``): ``venv`` itself; else
    the level ``env_id`` as ``gym.make_vec(env_id, num_envs=n, **env_kwargs)`` builds it
    (the id's preset configuration, the keywords on top); else
    :class:`ACLDBeamVectorEnv` of ``config`` and the keywords. ``n`` is ``num_envs`` (1 if
    None). ``env_id`` with ``venv`` or ``config``, and ``venv`` with ``config`` or
    keywords, are refused with one line naming both."""
    n = 1 if num_envs is None else num_envs
    if env_id is not None:
        env_id = check_env_id(env_id, "env_id")
        if venv is not None:
            raise ValueError(
                "pass either env_id= or venv=, not both: env_id= builds the level's env, "
                "venv= adapts one already built"
            )
        if config is not None:
            raise ValueError(
                f"pass either env_id= or config=, not both: env_id={env_id!r} is the level's "
                f"configuration; with changes, config=acld_gym.envs.presets.preset({env_id!r}, "
                "...) or env_id= with the changes as keywords"
            )
        own = [k for k in _MAKE_VEC_OWN if k in env_kwargs]
        if own:
            raise ValueError(
                f"{own[0]}: not an env keyword; SB3VecEnv builds the native vector env of "
                f"{env_id} (gym.make_vec's vector_entry_point mode)"
            )
        return gym.make_vec(
            env_id, num_envs=n, vectorization_mode="vector_entry_point", **env_kwargs
        )
    if venv is None:
        return ACLDBeamVectorEnv(num_envs=n, config=config, **env_kwargs)
    if env_kwargs or config is not None:
        raise ValueError("pass either venv= or the env's configuration, not both")
    return venv
