"""Hyperparameters: one rl-zoo3-style YAML file per algorithm (``train/ppo.yaml``,
``train/sac.yaml``), validated into a :class:`TrainConfig`."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml

from acld_gym.env import LOAD_CASES, PARAM_NOISE_MAX
from acld_gym.plant import MESHES

__all__ = ["ALGOS", "TrainConfig", "load_config", "config_path", "algo_class"]

ALGOS = ("ppo", "sac")
RESIDUALS = (None, "lqr")
FEATURE_NAMES = ("direction",)
_HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class TrainConfig:
    """A training run's settings (see the YAML files for the defaults).

    Attributes
    ----------
    algo : str
        ``"ppo"`` or ``"sac"``.
    n_timesteps : int
        Environment steps in total (over all sub-envs).
    n_envs : int
        Sub-envs of the native batched env.
    load_case : int or str
        Training loads: 1, 2, 3 or ``"random"``.
    mesh : str
        Truth plant of ``ACLDBeam-v1``: ``"converged"`` (default) or ``"thesis"``.
    param_noise : float
        Relative std of per-episode parameter randomization (0: nominal plant).
    residual : str or None
        ``"lqr"``: the agent's action a in [-1, 1] is added to the discrete LQR
        voltage, ``V = 120 clip(u_lqr / 120 + 2 a, -1, 1)`` [V]; None: ``V = 120 a``.
    features : str or None
        ``"direction"``: the networks see :class:`train.features.DirectionFeatures`
        of the observation (``[z/|z|, log|z|]``); None: SB3's default (flattened).
    distill : dict or None
        DAgger initialisation of the actor before reinforcement learning
        (:class:`train.distill.DistillConfig`'s fields); None: from scratch.
    shaping : float or None
        Voltage weight of the LQ potential used for reward shaping during training
        (:class:`train.vec.VecLQShaping`); None: the env's reward as is.
    normalize : dict
        Keyword arguments of ``VecNormalize``.
    eval_freq, checkpoint_freq : int
        Env steps between evaluations (thesis cases) and between checkpoints.
    model : dict
        Keyword arguments of the SB3 algorithm (``policy`` included).
    """

    algo: str
    n_timesteps: int
    n_envs: int
    load_case: int | str = "random"
    mesh: str = "converged"
    param_noise: float = 0.0
    residual: str | None = None
    shaping: float | None = None
    features: str | None = None
    distill: dict | None = None
    normalize: dict = field(default_factory=dict)
    eval_freq: int = 100_000
    checkpoint_freq: int = 500_000
    model: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.algo not in ALGOS:
            raise ValueError(f"algo must be one of {list(ALGOS)}, got {self.algo!r}")
        for name in ("n_timesteps", "n_envs", "eval_freq", "checkpoint_freq"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")
        if isinstance(self.load_case, bool) or self.load_case not in LOAD_CASES:
            raise ValueError(f"load_case must be one of {list(LOAD_CASES)}, "
                             f"got {self.load_case!r}")
        if self.mesh not in MESHES:
            raise ValueError(f"mesh must be one of {list(MESHES)}, got {self.mesh!r}")
        if not (isinstance(self.param_noise, (int, float)) and not isinstance(
                self.param_noise, bool) and 0 <= self.param_noise <= PARAM_NOISE_MAX[self.mesh]):
            raise ValueError(f"param_noise must be a number in [0, {PARAM_NOISE_MAX[self.mesh]}] "
                             f"for mesh {self.mesh!r}, got {self.param_noise!r}")
        if self.residual not in RESIDUALS:
            raise ValueError(f"residual must be one of {list(RESIDUALS)}, got {self.residual!r}")
        if self.shaping is not None and not (isinstance(self.shaping, (int, float))
                                             and self.shaping > 0):
            raise ValueError(f"shaping must be a positive number or null, got {self.shaping!r}")
        if self.features is not None and self.features not in FEATURE_NAMES:
            raise ValueError(f"features must be one of {list(FEATURE_NAMES)} or null, "
                             f"got {self.features!r}")
        if self.distill is not None:
            if not isinstance(self.distill, dict):
                raise ValueError(f"distill must be a mapping or null, got {self.distill!r}")
            _ = self.distill_config  # validates the fields
            if self.residual is not None:
                raise ValueError("distill needs residual: null (the action's sign is the "
                                 f"voltage's), got residual {self.residual!r}")
        if "policy" not in self.model:
            raise ValueError("model must name the SB3 policy (e.g. policy: MlpPolicy)")

    @property
    def teacher(self) -> str | None:
        """The teacher the actor imitates before RL (``distill.teacher``), or None."""
        return None if self.distill is None else self.distill_config.teacher

    @property
    def training(self) -> str:
        """The label of the agents in every table: ``"from scratch"`` or
        ``"DAgger from MPC + RL"``."""
        if self.teacher is None:
            return "from scratch"
        return f"DAgger from {self.teacher.upper()} + RL"

    @property
    def gamma(self) -> float:
        """Discount factor of the algorithm (SB3's default 0.99 if not set)."""
        return float(self.model.get("gamma", 0.99))

    @property
    def distill_config(self):
        """The :class:`train.distill.DistillConfig` of ``distill`` (None if off)."""
        from .distill import DistillConfig

        if self.distill is None:
            return None
        known = set(DistillConfig.__dataclass_fields__)
        unknown = sorted(set(self.distill) - known)
        if unknown:
            raise ValueError(f"distill: unknown key(s) {unknown}; expected some of {sorted(known)}")
        return DistillConfig(**self.distill)

    def with_overrides(self, **changes: Any) -> TrainConfig:
        """A copy with the non-None ``changes`` applied (validated again)."""
        return replace(self, **{k: v for k, v in changes.items() if v is not None})

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def config_path(algo: str) -> Path:
    """The shipped YAML file of ``algo``."""
    if algo not in ALGOS:
        raise ValueError(f"algo must be one of {list(ALGOS)}, got {algo!r}")
    return _HERE / f"{algo}.yaml"


def load_config(algo: str, path: str | Path | None = None) -> TrainConfig:
    """Read and validate ``algo``'s hyperparameters (``path`` or the shipped file)."""
    path = config_path(algo) if path is None else Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"config file {str(path)!r} does not exist")
    data = yaml.safe_load(path.read_text()) or {}
    if not isinstance(data, dict):
        raise ValueError(f"{path}: expected a mapping of hyperparameters")
    known = set(TrainConfig.__dataclass_fields__) - {"algo"}
    unknown = sorted(set(data) - known)
    if unknown:
        raise ValueError(f"{path}: unknown key(s) {unknown}; expected some of {sorted(known)}")
    missing = sorted({"n_timesteps", "n_envs"} - set(data))
    if missing:
        raise ValueError(f"{path}: missing key(s) {missing}")
    return TrainConfig(algo=algo, **data)


def algo_class(algo: str):
    """The stable-baselines3 class of ``algo`` (:data:`ALGOS`)."""
    from stable_baselines3 import PPO, SAC

    classes = {"ppo": PPO, "sac": SAC}
    if algo not in classes:
        raise ValueError(f"algo must be one of {list(classes)}, got {algo!r}")
    return classes[algo]
