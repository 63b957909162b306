"""Configuration of one benchmark algorithm (``train/benchmark/*.yaml``): the algorithm,
its fixed env-step budget, training loads, observation options and the model's keyword
arguments; and the learning-curve evaluation schedule."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from train.config import parse_load_case

__all__ = ["ALGOS", "SB3_ALGOS", "CurveCallback", "AlgoConfig", "eval_schedule"]


#: Algorithms from stable-baselines3 / sb3-contrib (module, class).
SB3_ALGOS = {
    "ppo": ("stable_baselines3", "PPO"),
    "sac": ("stable_baselines3", "SAC"),
    "td3": ("stable_baselines3", "TD3"),
    "tqc": ("sb3_contrib", "TQC"),
    "crossq": ("sb3_contrib", "CrossQ"),
    "ars": ("sb3_contrib", "ARS"),
}
ALGOS = ("vrs", *SB3_ALGOS)

#: Learning-curve callback: ``callback(env_steps, policy)``.
CurveCallback = Callable[[int, Any], None]


@dataclass(frozen=True)
class AlgoConfig:
    """One algorithm's settings (a YAML file under ``train/benchmark/``).

    Attributes
    ----------
    algo : str
        One of :data:`ALGOS`.
    timesteps : int
        Env-step budget of a run (the same for every seed).
    n_envs : int
        Sub-envs of the native batched env (SB3 algorithms).
    loads : dict
        Training loads, ``{case: weight}`` with cases 1, 2, 3, ``random``. For ``vrs``
        the weights are episodes per candidate per iteration; for SB3 algorithms the
        sub-envs are split in proportion (:class:`train.bench.sb3_envs.ConcatVecEnv`).
    features : str or None
        ``"direction"``: the agent sees ``[z/|z|, log|z|]``; None: the raw observation.
    normalize : dict
        ``VecNormalize`` keyword arguments (SB3 algorithms).
    model : dict
        The algorithm's keyword arguments (SB3: ``policy`` included; ``vrs``: the
        fields of :class:`train.bench.search.RandomSearch`).
    eval_points : int
        Learning-curve points (evaluations) over the budget, besides the one at step 0
        (log-spaced, :class:`eval_schedule`).
    whiten_steps : int
        SB3 algorithms: 0 (default) for none; else the agent first acts with its own
        initial (stochastic) policy for about this many env steps (whole vector steps,
        counted in the budget), and :func:`acld_gym.wrappers.whitening` of the observation
        directions it
        saw becomes a fixed linear map of the observation, ``u = T^T z``
        (:class:`train.bench.sb3_envs.VecWhiten`), the network's input. Needs ``features: null`` and
        ``norm_obs: false``; the final actor takes T into its first layer.
    episode_scale : bool
        PPO only: the advantages of each episode in a rollout are divided by their
        root mean square (:class:`train.bench.sb3_policies.EpisodeScaledRolloutBuffer`; the
        critic's targets
        are unchanged): episodes whose returns differ by decades weigh alike in the
        policy gradient (normalisation per load). Use ``n_steps`` = the episode length.
    env_kwargs : dict
        SB3 algorithms: options of the *training* env (fields of
        :class:`acld_gym.envs.config.EnvConfig`, e.g. ``reward_scale: passive`` and
        ``observe_reward_scale: true``); the evaluation is always on the env id as
        registered. With ``observe_reward_scale`` the whitening leaves the last entry
        (log c) alone and the policy must drop it from its actor
        (:class:`train.bench.sb3_policies.AsymmetricCriticPolicy`).
    """

    algo: str
    timesteps: int
    n_envs: int = 16
    loads: dict = field(default_factory=lambda: {"random": 1})
    features: str | None = "direction"
    normalize: dict = field(default_factory=lambda: {"norm_obs": False, "norm_reward": True})
    model: dict = field(default_factory=dict)
    eval_points: int = 10
    whiten_steps: int = 0
    episode_scale: bool = False
    env_kwargs: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.algo not in ALGOS:
            raise ValueError(f"algo must be one of {list(ALGOS)}, got {self.algo!r}")
        for name in ("timesteps", "n_envs", "eval_points"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")
        if not self.loads or any(
            not (isinstance(w, (int, float)) and w > 0) for w in self.loads.values()
        ):
            raise ValueError(f"loads must map cases to positive weights, got {self.loads!r}")
        for case in self.loads:
            parse_load_case(case)
        if self.features not in (None, "direction"):
            raise ValueError(f"features must be 'direction' or null, got {self.features!r}")
        if self.algo != "vrs" and "policy" not in self.model:
            raise ValueError(f"{self.algo}: model must name the SB3 policy")
        if (
            isinstance(self.whiten_steps, bool)
            or not isinstance(self.whiten_steps, int)
            or self.whiten_steps < 0
            or (self.whiten_steps and self.algo in ("vrs", "ars"))
        ):
            raise ValueError(
                f"whiten_steps must be a non-negative integer (SB3 algorithms "
                f"other than ars; vrs: model.whiten), got {self.whiten_steps!r}"
            )
        if self.whiten_steps and (
            self.features is not None or self.normalize.get("norm_obs", False)
        ):
            raise ValueError(
                "whiten_steps needs features: null and norm_obs: false (the "
                "trained actor takes the whitening into its first layer)"
            )
        if not isinstance(self.env_kwargs, dict):
            raise ValueError(f"env_kwargs must be a mapping of env options, got "
                             f"{self.env_kwargs!r}")
        if self.env_kwargs:
            from acld_gym.envs.config import make_config

            try:  # the training env's options, validated by the env's own config
                make_config(**self.env_kwargs)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"env_kwargs: {exc}") from None
            if self.algo == "vrs":
                raise ValueError("env_kwargs are for the SB3 algorithms (vrs has its own env)")
        if self.episode_scale and self.algo != "ppo":
            raise ValueError("episode_scale is for ppo only")

    @property
    def load_weights(self) -> dict:
        """``loads`` with parsed case keys."""
        return {parse_load_case(c): w for c, w in self.loads.items()}

    @classmethod
    def from_dict(cls, data: dict) -> AlgoConfig:
        known = set(cls.__dataclass_fields__)
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"unknown key(s) {unknown}; expected some of {sorted(known)}")
        return cls(**data)

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


class eval_schedule:  # noqa: N801  (used like a function)
    """Learning-curve evaluations: at step 0 and at ``points`` env-step counts spaced
    logarithmically from 1 % of ``budget`` to ``budget``; :meth:`due` is true once per
    threshold crossed."""

    def __init__(self, budget: int, points: int):
        self.thresholds = sorted({int(round(x)) for x in budget * np.logspace(-2, 0, points)})
        self.thresholds = [0] + [t for t in self.thresholds if t > 0]
        self._next = 0

    def due(self, steps: int) -> bool:
        if self._next >= len(self.thresholds) or steps < self.thresholds[self._next]:
            return False
        while self._next < len(self.thresholds) and steps >= self.thresholds[self._next]:
            self._next += 1
        return True
