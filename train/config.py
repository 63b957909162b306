"""Hyperparameters: one rl-zoo3-style YAML file per algorithm (``train/ppo.yaml``,
``train/sac.yaml``), validated into a :class:`TrainConfig`."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml

from acld_gym.envs.config import check_param_noise
from acld_gym.physics.loads import LOAD_CASES, parse_load_case
from acld_gym.physics.truth import MESHES
from acld_gym.util.validate import check_int, check_real

__all__ = ["ALGOS", "TrainConfig", "load_config", "config_path", "algo_class", "parse_load_case"]

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
        (:class:`train.vec.VecAgentEnv`, :func:`train.vec.lq_potential`); None: the env's
        reward as is.
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
            check_int(name, getattr(self, name), 1, 10**12)
        if isinstance(self.load_case, bool) or self.load_case not in LOAD_CASES:
            raise ValueError(f"load_case must be one of {list(LOAD_CASES)}, "
                             f"got {self.load_case!r}")
        if self.mesh not in MESHES:
            raise ValueError(f"mesh must be one of {list(MESHES)}, got {self.mesh!r}")
        check_param_noise(self.param_noise, self.mesh)
        if self.residual not in RESIDUALS:
            raise ValueError(f"residual must be one of {list(RESIDUALS)}, got {self.residual!r}")
        if self.shaping is not None:
            check_real("shaping", self.shaping, 0.0, 1e6, low_open=True)
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
        if not isinstance(self.model, dict) or "policy" not in self.model:
            raise ValueError("model must name the SB3 policy (e.g. policy: MlpPolicy)")
        check_model_kwargs(self.algo, self.model)
        if not isinstance(self.normalize, dict):
            raise ValueError(f"normalize must be a mapping, got {self.normalize!r}")
        import inspect

        from stable_baselines3.common.vec_env import VecNormalize

        allowed = set(inspect.signature(VecNormalize).parameters) - {"venv", "gamma"}
        bad = sorted(set(self.normalize) - allowed)
        if bad:
            raise ValueError(f"normalize: unknown key(s) {bad}; expected some of "
                             f"{sorted(allowed)}")

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


def check_model_kwargs(algo: str, model: dict) -> None:
    """``ValueError`` naming a key of ``model`` that ``algo``'s class does not take, or a
    number given as something else (``learning_rate: fast``), before anything runs."""
    import inspect

    sig = inspect.signature(algo_class(algo))
    params = sig.parameters
    unknown = sorted(k for k in model if k not in params)
    if unknown:
        raise ValueError(f"model: unknown key(s) {unknown} for {algo.upper()}; expected some "
                         f"of {sorted(k for k in params if k not in ('env', 'self'))}")
    for key, value in model.items():
        default = params[key].default
        if isinstance(default, bool) or default is None or key == "policy":
            continue
        if isinstance(default, (int, float)) and not isinstance(value, bool):
            if isinstance(default, int) and key not in ("learning_rate", "clip_range"):
                check_int(f"model.{key}", value, 0 if key == "seed" else 1)
            else:
                check_real(f"model.{key}", value, 0.0)


def load_config(algo: str, path: str | Path | None = None) -> TrainConfig:
    """Read and validate ``algo``'s hyperparameters (``path`` or the shipped file);
    ``ValueError`` (naming the file and the key) on a malformed file or a bad value."""
    path = config_path(algo) if path is None else Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"config file {str(path)!r} does not exist")
    try:
        data = yaml.safe_load(path.read_text()) or {}
    except yaml.YAMLError as exc:
        where = getattr(exc, "problem_mark", None)
        at = f" (line {where.line + 1}, column {where.column + 1})" if where else ""
        raise ValueError(f"{path}: not valid YAML{at}: {getattr(exc, 'problem', exc)}") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path}: expected a mapping of hyperparameters")
    known = set(TrainConfig.__dataclass_fields__) - {"algo"}
    unknown = sorted(set(data) - known)
    if unknown:
        raise ValueError(f"{path}: unknown key(s) {unknown}; expected some of {sorted(known)}")
    missing = sorted({"n_timesteps", "n_envs"} - set(data))
    if missing:
        raise ValueError(f"{path}: missing key(s) {missing}")
    try:
        return TrainConfig(algo=algo, **data)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def algo_class(algo: str):
    """The stable-baselines3 class of ``algo`` (:data:`ALGOS`)."""
    from stable_baselines3 import PPO, SAC

    classes = {"ppo": PPO, "sac": SAC}
    if algo not in classes:
        raise ValueError(f"algo must be one of {list(classes)}, got {algo!r}")
    return classes[algo]
