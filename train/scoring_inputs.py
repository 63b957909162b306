"""The inputs of :func:`train.scoring.score` made into one policy and one env, and checked:
any policy as an object with SB3's ``predict`` on the wrapped env's observation
(:func:`as_policy`), the env wrapped (:func:`wrap`), and the two fitted to each other
(:func:`check_fits`). Every fault is one ``TypeError`` / ``ValueError`` naming the argument.
"""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np

from acld_gym.util.validate import shown

__all__ = ["ScoredPolicy", "as_policy", "wrap", "check_fits", "load_vec_normalize"]


class ScoredPolicy:
    """A policy as :func:`baselines.evaluation.rollout.rollout` runs it: SB3's ``predict`` on
    the wrapped env's observation, after the ``VecNormalize`` observation statistics
    ``obs_norm`` (if any); a plain callable gets the observation and returns the action (no
    state; a scalar or any shape of one entry per action is taken flat). The recurrent
    protocol's ``state`` and ``episode_start`` pass through unchanged."""

    def __init__(self, policy, obs_norm=None):
        self.policy = policy
        self.obs_norm = obs_norm
        self.calls = not callable(getattr(policy, "predict", None))
        self.name = getattr(policy, "name", type(policy).__name__)

    @property
    def observation_fingerprint(self) -> dict | None:
        """The wrapped policy's (a :class:`train.agent.TrainedAgent`'s), or None."""
        return getattr(self.policy, "observation_fingerprint", None)

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        obs = observation if self.obs_norm is None else self.obs_norm.normalize_obs(observation)
        if self.calls:
            return np.asarray(self.policy(obs), dtype=np.float64).reshape(-1), state
        return self.policy.predict(
            obs, state=state, episode_start=episode_start, deterministic=deterministic
        )


def _is_sb3(policy) -> bool:
    try:
        from stable_baselines3.common.base_class import BaseAlgorithm
    except ImportError:  # pragma: no cover (SB3 is a dependency of train)
        return False
    return isinstance(policy, BaseAlgorithm)


def wrap(env: gym.Env, wrappers: tuple, env_id: str) -> gym.Env:
    """``env`` wrapped by each of ``wrappers`` in turn, running statistics frozen;
    ``ValueError`` naming ``wrappers[i]`` if one fails or does not return an env."""
    for i, w in enumerate(wrappers):
        name = getattr(w, "__name__", None) or type(w).__name__
        try:
            out = w(env)
        except Exception as exc:  # a wrapper's own check, on the env it does not fit
            env.close()
            raise ValueError(f"wrappers[{i}] ({name}) does not fit {env_id}: {exc}") from None
        if not isinstance(out, gym.Env):
            env.close()
            raise ValueError(
                f"wrappers[{i}] ({name}) must return a gymnasium env, got {shown(out)}"
            )
        env = out
    layer = env
    while isinstance(layer, gym.Wrapper):  # evaluation: the trained statistics stay fixed
        if hasattr(layer, "update_running_mean"):
            layer.update_running_mean = False
        layer = layer.env
    return env


def load_vec_normalize(path, env: gym.Env):
    """SB3's ``VecNormalize`` saved at ``path`` (``VecNormalize.load``: it unpickles, so only a
    file from a trusted source), frozen, on a one-env copy of ``env``'s spaces."""
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"vec_normalize: no file {str(path)!r}")
    spaces = _Spaces(env.observation_space, env.action_space)
    try:
        norm = VecNormalize.load(str(path), DummyVecEnv([lambda: spaces]))
    except Exception as exc:
        raise ValueError(f"vec_normalize: cannot load {str(path)!r}: {exc}") from None
    norm.training, norm.norm_reward = False, False
    return norm


class _Spaces(gym.Env):
    """An env that has only ``env``'s spaces (what ``VecNormalize.load`` checks)."""

    def __init__(self, observation_space, action_space):
        self.observation_space, self.action_space = observation_space, action_space


def _own_vec_normalize(model):
    """The ``VecNormalize`` of an SB3 ``model``'s own env, or None if its env is another;
    ``ValueError`` naming ``vec_normalize`` if it has no env (``PPO.load(path)``): whether it
    was trained under a ``VecNormalize`` is then unknown, and scoring it without the
    statistics would give another policy's score without a word."""
    from stable_baselines3.common.vec_env import VecNormalize

    own = model.get_env()
    if own is None:
        raise ValueError(
            f"vec_normalize: this {type(model).__name__} model has no env (loaded with "
            "load(path)?), so its VecNormalize is unknown: pass the VecNormalize it was "
            "trained under or the path of its saved vecnormalize.pkl, or vec_normalize=False "
            "if it was trained without one"
        )
    return own if isinstance(own, VecNormalize) else None


def as_policy(policy, vec_normalize, env: gym.Env, wrappers: tuple) -> ScoredPolicy:
    """``policy`` (an SB3 model, a ``TrainedAgent``, an object with ``predict``, a callable)
    with its ``vec_normalize`` (a ``VecNormalize``, its file, False: none, or None: an SB3
    model's own env's, refused for a model without an env) as a :class:`ScoredPolicy` on
    ``env`` (the wrapped env)."""
    from .agent import TrainedAgent

    if not (callable(getattr(policy, "predict", None)) or callable(policy)):
        raise TypeError(
            "policy must be an SB3 model, a TrainedAgent, an object with predict(observation, "
            f"state, episode_start, deterministic) or a callable observation -> action, got "
            f"{shown(policy)}"
        )
    if isinstance(policy, TrainedAgent) and wrappers:
        raise ValueError(
            "wrappers: a TrainedAgent acts on the env's raw observation in volts (its "
            "normalization and action scaling are inside it): score it without wrappers"
        )
    if vec_normalize is None and _is_sb3(policy):
        vec_normalize = _own_vec_normalize(policy)
    elif vec_normalize is False:  # said so: no VecNormalize
        vec_normalize = None
    if isinstance(vec_normalize, (str, Path)):
        vec_normalize = load_vec_normalize(vec_normalize, env)
    if vec_normalize is not None:
        if not callable(getattr(vec_normalize, "normalize_obs", None)):
            raise TypeError(
                f"vec_normalize must be SB3's VecNormalize, the path of its saved statistics, "
                f"False (none) or None (the SB3 model's own), got {shown(vec_normalize)}"
            )
        mean = getattr(getattr(vec_normalize, "obs_rms", None), "mean", None)
        shape = env.observation_space.shape
        if getattr(vec_normalize, "norm_obs", True) and np.shape(mean) != shape:
            raise ValueError(
                f"vec_normalize: statistics of observations of shape {np.shape(mean)}, the "
                f"env with these wrappers observes {shape}"
            )
    return ScoredPolicy(policy, vec_normalize)


def check_fits(policy: ScoredPolicy, env: gym.Env, env_id: str) -> None:
    """``ValueError`` unless ``policy`` fits ``env``: an SB3 model's spaces against the
    wrapped env's (observation shape; action bounds, as a missing ``UnitAction`` would
    break them), and for every policy one action of the env's shape, finite, on the env's
    first observation."""
    inner = policy.policy
    if _is_sb3(inner):
        want, got = inner.observation_space.shape, env.observation_space.shape
        if want != got:
            raise ValueError(
                f"wrappers: the policy observes shape {want}, {env_id} with these wrappers "
                f"gives {got} (the observation wrappers it was trained with?)"
            )
        a, b = inner.action_space, env.action_space
        if a.shape != b.shape or not (
            np.allclose(a.low, b.low, rtol=1e-6) and np.allclose(a.high, b.high, rtol=1e-6)
        ):
            raise ValueError(
                f"wrappers: the policy acts in [{float(np.min(a.low)):g}, "
                f"{float(np.max(a.high)):g}], {env_id} with these wrappers takes "
                f"[{float(np.min(b.low)):g}, {float(np.max(b.high)):g}] (the action wrapper "
                "it was trained with, e.g. UnitAction?)"
            )
    obs, _ = env.reset(seed=0)
    try:
        action, _ = policy.predict(
            obs, state=None, episode_start=np.ones(1, dtype=bool), deterministic=True
        )
    except Exception as exc:
        raise ValueError(
            f"policy: fails on the observation of {env_id} with these wrappers "
            f"(shape {np.shape(obs)}): {exc}"
        ) from None
    action = np.asarray(action, dtype=np.float64)
    if action.size != int(np.prod(env.action_space.shape)) or not np.all(np.isfinite(action)):
        raise ValueError(
            f"policy: returned {shown(action)} for an observation of {env_id} with these "
            f"wrappers; expected a finite action of shape {env.action_space.shape}"
        )
