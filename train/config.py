"""The one training configuration: a YAML file per recipe under ``train/recipes/``
(``ppo.yaml``, ``sac.yaml``, ``vrs.yaml``, the opt-in DAgger starts; a file of your own may
be ``base: ppo`` and what it changes, :func:`read_config`; the research record's variants
are in ``studies/ablations/``, not packaged), validated into a
:class:`TrainConfig`. ``python -m train`` and ``python -m train.benchmark`` read the same
files, build the same env (:func:`train.vec.make_vec_env`), train with the same function
(:func:`train.core.algos.train_algo`) and evaluate with the same evaluator
(:mod:`train.core.evaluate`)."""

from __future__ import annotations

import importlib
from dataclasses import MISSING, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import yaml

from acld_gym.physics.loads import parse_load_case
from acld_gym.util.validate import DataFileError, check_int, check_real

__all__ = [
    "ALGOS",
    "SB3_ALGOS",
    "CONFIG_DIR",
    "TrainConfig",
    "SelectConfig",
    "algo_class",
    "config_path",
    "read_config",
    "load_config",
    "parse_load_case",
]

#: Algorithms from stable-baselines3 / sb3-contrib (module, class).
SB3_ALGOS = {
    "ppo": ("stable_baselines3", "PPO"),
    "sac": ("stable_baselines3", "SAC"),
    "td3": ("stable_baselines3", "TD3"),
    "tqc": ("sb3_contrib", "TQC"),
    "crossq": ("sb3_contrib", "CrossQ"),
    "ars": ("sb3_contrib", "ARS"),
}
#: Every algorithm: the random search ``vrs`` (:mod:`train.core.search`) and the SB3 ones.
ALGOS = ("vrs", *SB3_ALGOS)
#: The recipes: ``train/recipes/<name>.yaml``.
CONFIG_DIR = Path(__file__).resolve().parent / "recipes"
RESIDUALS = (None, "lqr")


@dataclass(frozen=True)
class SelectConfig:
    """Checkpoint selection on validation loads (``TrainConfig.select``), as SB3's
    ``EvalCallback`` keeps its best model: every ``every`` env steps from ``start`` on, and
    at the end, the deterministic policy runs ``episodes`` random loads of the validation
    seeds (:func:`train.core.evaluate.validation_seeds`, disjoint from the held-out test
    loads) and is scored by the env's reward per load
    (:func:`train.core.evaluate.validation_cost`: 1 for the passive beam); the run
    returns the best-scoring policy. Its env steps are not counted in the budget (they
    train nothing; the run records them); its time is in the training wall time. The
    learning curve follows the policy being trained (the average, with ``average``), the
    final evaluation is the returned one's.

    Attributes
    ----------
    episodes : int
        Validation episodes per check (random loads), at least 1.
    every : int
        Env steps between checks, at least 1.
    start : int
        Env steps before the first check (0: from the start).
    """

    episodes: int
    every: int
    start: int = 0

    def __post_init__(self):
        check_int("select.episodes", self.episodes, 1, 10**4)
        check_int("select.every", self.every, 1, 10**12)
        check_int("select.start", self.start, 0, 10**12)


def _section(cls, data: dict, name: str):
    """The dataclass ``cls`` of a config's mapping ``name`` (``distill``, ``select``);
    ``ValueError`` naming ``name`` and its unknown or missing keys."""
    known = {f.name for f in fields(cls)}
    required = {
        f.name for f in fields(cls) if f.default is MISSING and f.default_factory is MISSING
    }
    unknown, missing = sorted(str(k) for k in set(data) - known), sorted(required - set(data))
    if unknown or missing:
        raise ValueError(
            f"{name}: unknown key(s) {unknown}, missing {missing}; expected some of {sorted(known)}"
        )
    return cls(**data)


def _distill_config_class():
    from .distill import DistillConfig  # train.distill imports this module

    return DistillConfig


#: The sub-mappings of a :class:`TrainConfig` and (a function giving) the dataclass of each.
_SECTIONS = {
    "distill": _distill_config_class,
    "select": lambda: SelectConfig,
}


def algo_class(algo: str):
    """The stable-baselines3 / sb3-contrib class of ``algo`` (:data:`SB3_ALGOS`)."""
    if algo not in SB3_ALGOS:
        raise ValueError(f"algo must be one of {list(SB3_ALGOS)}, got {algo!r}")
    module, name = SB3_ALGOS[algo]
    return getattr(importlib.import_module(module), name)


@dataclass(frozen=True)
class TrainConfig:
    """One training recipe (a YAML file under ``train/recipes/``).

    Attributes
    ----------
    algo : str
        One of :data:`ALGOS`.
    timesteps : int
        Env-step budget of a run, all sub-envs together (the same for every seed).
    n_envs : int
        Sub-envs of the native batched env (SB3 algorithms).
    loads : dict
        Training loads, ``{case: weight}`` with cases 1, 2, 3, ``random``. For ``vrs``
        the weights are episodes per candidate per iteration; for SB3 algorithms the
        sub-envs are split in proportion (:class:`train.vec.ConcatVecEnv`).
    features : str or None
        ``"direction"``: the agent sees ``[z/|z|, log|z|]``
        (:class:`train.vec.VecDirectionFeatures`); None: the raw observation.
    normalize : dict
        ``VecNormalize`` keyword arguments (SB3 algorithms).
    model : dict
        The algorithm's keyword arguments (SB3: ``policy`` included; ``vrs``: the
        fields of :class:`train.core.search.RandomSearch`). SB3's ``learning_rate`` and
        ``clip_range``, and PPO's ``ent_coef``, may be ``{linear: [start, end]}``, linear
        in the progress from ``start`` to ``end`` (``ent_coef``: set before each update,
        :func:`train.core.sb3_train.ent_coef_schedule`); ``learning_rate`` also
        ``{linear: [start, end], warmup: w}``, scaled up from 0 over the first fraction
        ``w`` of training (:class:`train.core.sb3_train.LinearSchedule`);
        ``policy_kwargs.activation_fn`` is given by name.
    eval_points : int
        Learning-curve points (evaluations) over the budget, besides the one at step 0
        (log-spaced, :class:`train.core.evaluate.eval_schedule`).
    whiten_steps : int
        SB3 algorithms: 0 (default) for none; else the agent first acts with its own
        initial (stochastic) policy for about this many env steps (whole vector steps,
        counted in the budget), and :func:`acld_gym.wrappers.whitening` of the observation
        directions it saw becomes a fixed linear map of the observation, ``u = T^T z``
        (:class:`train.vec.VecWhiten`), the network's input. Needs ``features: null`` and
        ``norm_obs: false``; the final actor takes T into its first layer. Let it cover
        whole episodes (the recipe: 1000 vector steps, one episode per sub-env): estimated
        from the first 64 ms of each episode only, it preconditions the policy gradient
        badly on some seeds (``docs/training.md``).
    paired_loads : bool
        SB3 algorithms: sub-envs ``2i`` and ``2i + 1`` of each load case get one seed
        (:class:`acld_gym.envs.sb3.SB3VecEnv`'s ``seed_group=2``), so the pair runs the
        same loads and sensor noise: common random numbers, for antithetic exploration
        (``policy_kwargs: {antithetic_noise: true}``,
        :class:`train.core.sb3_policies.SplitCriticPolicy`). Needs an even number of
        sub-envs per load case. Default false: sub-env i gets ``seed + i``.
    env_kwargs : dict
        Options of the *training* env (fields of :class:`acld_gym.envs.config.EnvConfig`,
        e.g. ``reward_scale: passive``, ``observe_reward_scale: true``, ``param_noise:
        0.05``); the evaluation is always on the env id as registered. With
        ``observe_reward_scale`` (SB3 algorithms only: vrs's actor reads the whole
        observation) the whitening leaves the last entry (log c) alone and the policy must
        drop it from its actor (:class:`train.core.sb3_policies.AsymmetricCriticPolicy`).
        vrs: its candidates' episodes run on them (with ``reward_scale`` and ``objective:
        return`` an episode's score is its scaled return).
    residual : str or None
        SB3 algorithms: ``"lqr"``: the action a in [-1, 1] is added to the discrete LQR
        voltage, ``V = 120 clip(u_lqr / 120 + 2 a, -1, 1)`` [V]
        (:class:`train.voltage.VoltageMap`; controller knowledge in the policy, so the
        agent is labelled so); None (default): ``V = 120 a``.
    action_headroom : float
        SB3 algorithms: the action a in [-1, 1] drives ``V = 120 clip(k a, -1, 1)`` with
        k = ``action_headroom`` (default 1; :class:`train.voltage.VoltageMap`, the same
        map as :class:`acld_gym.wrappers.UnitAction`'s ``headroom``). A tanh-squashed actor
        (SAC) reaches the +/-120 V limit at a = 1/k instead of only in tanh's flat tail,
        which its entropy term forbids; the agent records k and applies it when deployed.
    shaping : float or None
        SB3 algorithms: voltage weight of the LQ potential used for reward shaping in
        training (:class:`train.vec.VecAgentEnv`, :func:`train.vec.lq_potential`;
        controller knowledge in the reward); None (default): the env's reward as is.
    distill : dict or None
        SB3 algorithms: DAgger initialisation of the actor before reinforcement learning
        (:class:`train.distill.DistillConfig`'s fields, e.g. ``{teacher: mpc}``); None
        (default): from scratch.
    select : dict or None
        SB3 algorithms: checkpoint selection on validation loads (:class:`SelectConfig`'s
        fields, e.g. ``{episodes: 32, every: 50000, start: 300000}``); None (default): the
        final policy.
    restarts : int
        SB3 algorithms with ``select``: independent runs of ``timesteps`` each from fresh
        initialisations (the first with the trial's seed, the others with seeds derived
        from it, :func:`train.core.algos.restart_seeds`); the trial returns the run whose
        chosen check has the lowest validation cost (the same validation loads for all).
        The budget is ``restarts * timesteps`` (:attr:`budget`). Default 1: one run.
    restart_above : str, float or None
        With ``restarts`` > 1: a run is followed by the next only if its chosen check's
        validation cost (:func:`train.core.evaluate.validation_cost`) is above this:
        ``"<ratio> * <reference>"`` (e.g. ``"1.03 * lqg"``; a reference alone: ratio 1),
        the ratio times the reference's cost on the same validation loads of the level
        the run trains on (``lqg``, the level's engineer's LQG; ``lqr``, the thesis LQR;
        ``passive``), resolved before the first run
        (:class:`train.core.threshold.RestartRule`), so one recipe carries over to every
        level; a bare number: an absolute cost of ``ACLDBeam-v1``, the level such numbers
        were calibrated on, refused on any other. The first run at or below it is
        returned, and if none is, the lowest; every retry is said, with its reason. Seeds
        then train ``timesteps`` to :attr:`budget` env steps, by one rule. None (default):
        every run, the lowest returned.
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
    paired_loads: bool = False
    env_kwargs: dict = field(default_factory=dict)
    residual: str | None = None
    action_headroom: float = 1.0
    shaping: float | None = None
    distill: dict | None = None
    select: dict | None = None
    restarts: int = 1
    restart_above: float | str | None = None

    @property
    def budget(self) -> int:
        """Env steps of training in all: ``restarts * timesteps`` (with
        ``restart_above``, the most a seed may take)."""
        return self.restarts * self.timesteps

    def __post_init__(self):
        if self.algo not in ALGOS:
            raise ValueError(f"algo must be one of {list(ALGOS)}, got {self.algo!r}")
        for name, most in (("timesteps", 10**12), ("n_envs", 2**16), ("eval_points", 10**4)):
            check_int(name, getattr(self, name), 1, most)  # most: what memory allows
        check_int("restarts", self.restarts, 1, 64)
        if self.restart_above is not None:
            from .core.threshold import RestartRule

            RestartRule.parse(self.restart_above)
            if self.restarts < 2:
                raise ValueError(
                    f"restart_above needs restarts >= 2 (runs to choose from), "
                    f"got restarts {self.restarts}"
                )
        if not isinstance(self.loads, dict) or not self.loads:
            raise ValueError(f"loads must map cases to positive weights, got {self.loads!r}")
        for case, w in self.loads.items():
            parse_load_case(case)
            if self.algo == "vrs":  # episodes per candidate and iteration
                check_int(f"loads.{case}", w, 1, 10**4)
            else:  # the sub-envs' shares
                check_real(f"loads.{case}", w, 0.0, 1e6, low_open=True)
        if self.features not in (None, "direction"):
            raise ValueError(f"features must be 'direction' or null, got {self.features!r}")
        sb3 = self.algo != "vrs"
        if not isinstance(self.model, dict):
            raise ValueError(f"model must be a mapping, got {self.model!r}")
        if sb3 and "policy" not in self.model:
            raise ValueError(
                f"{self.algo}: model must name the SB3 policy (e.g. policy: MlpPolicy)"
            )
        if (
            isinstance(self.whiten_steps, bool)
            or not isinstance(self.whiten_steps, int)
            or (self.whiten_steps < 0 or (self.whiten_steps and self.algo in ("vrs", "ars")))
        ):
            raise ValueError(
                f"whiten_steps must be a non-negative integer (SB3 algorithms "
                f"other than ars; vrs: model.whiten), got {self.whiten_steps!r}"
            )
        if not isinstance(self.normalize, dict):
            raise ValueError(f"normalize must be a mapping, got {self.normalize!r}")
        if self.whiten_steps and (
            self.features is not None or self.normalize.get("norm_obs", False)
        ):
            raise ValueError(
                "whiten_steps needs features: null and norm_obs: false (the "
                "trained actor takes the whitening into its first layer)"
            )
        if not isinstance(self.paired_loads, bool) or (self.paired_loads and not sb3):
            raise ValueError(
                f"paired_loads must be true or false, and true for the SB3 algorithms "
                f"only; got {self.paired_loads!r}"
            )
        if self.paired_loads and any(n % 2 for n in self.envs_per_load.values()):
            raise ValueError(
                f"paired_loads needs an even number of sub-envs per load case; n_envs "
                f"{self.n_envs} over loads {self.loads} gives {self.envs_per_load}"
            )
        if not isinstance(self.env_kwargs, dict):
            raise ValueError(
                f"env_kwargs must be a mapping of env options, got {self.env_kwargs!r}"
            )
        if self.env_kwargs:
            if not sb3 and self.env_kwargs.get("observe_reward_scale"):
                raise ValueError(
                    "env_kwargs: observe_reward_scale is for the SB3 algorithms (vrs's "
                    "actor reads the whole observation, log c included)"
                )
            if "load_case" in self.env_kwargs:
                raise ValueError(
                    "env_kwargs: the training loads are the loads: field, not load_case"
                )
            from acld_gym.envs.config import make_config

            try:  # the training env's options, validated by the env's own config
                make_config(**self.env_kwargs)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"env_kwargs: {exc}") from None
        if self.residual not in RESIDUALS:
            raise ValueError(f"residual must be one of {list(RESIDUALS)}, got {self.residual!r}")
        from acld_gym.wrappers import check_headroom

        check_headroom(self.action_headroom, "action_headroom")
        if self.action_headroom != 1.0 and not sb3:
            raise ValueError(
                "action_headroom is for the SB3 algorithms (vrs: a saturated linear actor)"
            )
        if self.shaping is not None:
            check_real("shaping", self.shaping, 0.0, 1e6, low_open=True)
        for name in _SECTIONS:  # the sub-mappings, each validated by its dataclass
            value = getattr(self, name)
            if value is not None and not isinstance(value, dict):
                raise ValueError(f"{name} must be a mapping or null, got {value!r}")
            _ = self._section_config(name)
        if self.distill is not None and self.residual is not None:
            raise ValueError(
                "distill needs residual: null (the action's sign is the "
                f"voltage's), got residual {self.residual!r}"
            )
        if self.select is not None and self.normalize.get("norm_obs", False):
            raise ValueError(
                "select needs norm_obs: false (the chosen parameters would "
                "meet the final observation statistics)"
            )
        if not sb3 and (
            self.residual or self.shaping is not None or self.distill or self.select is not None
        ):
            raise ValueError("residual, shaping, distill and select are for the SB3 algorithms")
        if self.restarts > 1 and self.select is None:
            raise ValueError(
                f"restarts: {self.restarts} runs need select: (the choice between "
                "them is on the validation loads); got select: null"
            )
        from .config_checks import check_model  # the model: mapping (moved for size)

        check_model(self)

    @property
    def load_weights(self) -> dict:
        """``loads`` with parsed case keys."""
        return {parse_load_case(c): w for c, w in self.loads.items()}

    @property
    def envs_per_load(self) -> dict:
        """Sub-envs of the training env per load case (parsed keys), in proportion to
        ``loads``, at least one each, ``n_envs`` in all unless there are more cases."""
        weights = self.load_weights
        total = float(sum(weights.values()))
        counts = {c: max(1, int(round(self.n_envs * w / total))) for c, w in weights.items()}
        last = list(counts)[-1]
        counts[last] = max(1, self.n_envs - sum(v for c, v in counts.items() if c != last))
        return counts

    @property
    def mesh(self) -> str:
        """Truth plant of the training env (``env_kwargs.mesh``; ``"converged"`` if unset)."""
        return self.env_kwargs.get("mesh", "converged")

    @property
    def gamma(self) -> float:
        """Discount factor of the algorithm (SB3's default 0.99 if not set)."""
        return float(self.model.get("gamma", 0.99))

    def _section_config(self, name: str):
        """The dataclass of the sub-mapping ``name`` (:data:`_SECTIONS`), None if off."""
        value = getattr(self, name)
        return None if value is None else _section(_SECTIONS[name](), value, name)

    @property
    def distill_config(self):
        """The :class:`train.distill.DistillConfig` of ``distill`` (None if off)."""
        return self._section_config("distill")

    @property
    def select_config(self) -> SelectConfig | None:
        """The :class:`SelectConfig` of ``select`` (None if off)."""
        return self._section_config("select")

    @property
    def teacher(self) -> str | None:
        """The teacher the actor imitates before RL (``distill.teacher``), or None."""
        return None if self.distill is None else self.distill_config.teacher

    @property
    def training(self) -> str:
        """The label of the agents in every table: ``"from scratch"``, ``"DAgger from MPC
        + RL"``, or with controller knowledge in the action or the reward, say so."""
        teacher = self.teacher
        label = "from scratch" if teacher is None else f"DAgger from {teacher.upper()} + RL"
        extra = [
            s
            for s, on in (
                ("LQR residual", self.residual == "lqr"),
                ("LQ-potential shaping", self.shaping is not None),
            )
            if on
        ]
        return label if not extra else f"{label} ({', '.join(extra)})"

    @classmethod
    def from_dict(cls, data: dict) -> TrainConfig:
        """Validate a config mapping (``ValueError`` naming an unknown key)."""
        if not isinstance(data, dict):
            raise ValueError(f"expected a mapping of settings, got {type(data).__name__}")
        known = set(cls.__dataclass_fields__)
        unknown = sorted(str(k) for k in set(data) - known)
        if unknown:
            raise ValueError(f"unknown key(s) {unknown}; expected some of {sorted(known)}")
        missing = sorted({"algo", "timesteps"} - set(data))
        if missing:
            raise ValueError(f"missing key(s) {missing}")
        return cls(**data)

    def with_overrides(self, **changes: Any) -> TrainConfig:
        """A copy with the non-None ``changes`` applied (validated again)."""
        return replace(self, **{k: v for k, v in changes.items() if v is not None})

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def config_path(spec: str | Path) -> Path:
    """The file of a config: a recipe name under ``train/recipes/`` (``"ppo"``) or a
    YAML path; ``FileNotFoundError`` naming both if there is none."""
    path = Path(spec)
    if not path.suffix:
        path = CONFIG_DIR / f"{spec}.yaml"
    if not path.is_file():
        raise FileNotFoundError(f"config {str(spec)!r}: file {str(path)!r} does not exist")
    return path


def _read_yaml(path: Path) -> dict:
    """The mapping of one YAML file; :class:`DataFileError` naming the file and the place."""
    from .config_checks import MAX_BYTES, UniqueKeyLoader, check_size

    try:
        if path.stat().st_size > MAX_BYTES:
            raise DataFileError(f"{path}: larger than {MAX_BYTES} bytes: not a config")
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=UniqueKeyLoader) or {}  # noqa: S506 (a safe loader)
        check_size(data, path)
    except (yaml.YAMLError, UnicodeDecodeError, RecursionError) as exc:
        where = getattr(exc, "problem_mark", None)
        at = f" (line {where.line + 1}, column {where.column + 1})" if where else ""
        why = getattr(exc, "problem", None) or type(exc).__name__
        raise DataFileError(f"{path}: not valid YAML{at}: {why}") from None
    except ValueError as exc:
        raise DataFileError(str(exc)) from None
    if not isinstance(data, dict):
        raise DataFileError(f"{path}: expected a mapping of settings, got {type(data).__name__}")
    return data


def _merged(base: dict, changes: dict) -> dict:
    """``base`` with ``changes`` applied key by key, nested mappings merged the same way."""
    out = dict(base)
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            value = _merged(out[key], value)
        out[key] = value
    return out


def _resolve(path: Path, seen: tuple[Path, ...] = ()) -> dict:
    """The mapping of a config file with its ``base:`` (a config name or a YAML path, itself
    resolved) applied: the base's settings, then the file's own on top of them. A name is
    the file ``<name>.yaml`` beside ``path`` if there is one (a chain of configs kept in one
    folder, e.g. ``studies/ablations/``), else a recipe's."""
    data = _read_yaml(path)
    if "base" not in data:
        return data
    base = data.pop("base")
    if not isinstance(base, str):
        raise DataFileError(f"{path}: base: expected a config name or path, got {base!r}")
    sibling = path.parent / f"{base}.yaml"
    try:
        base_path = sibling if not Path(base).suffix and sibling.is_file() else config_path(base)
    except FileNotFoundError as exc:
        raise DataFileError(f"{path}: base: {exc}") from None
    if base_path.resolve() in seen:
        raise DataFileError(f"{path}: base: {base!r} leads back to itself")
    return _merged(_resolve(base_path, (*seen, path.resolve())), data)


def read_config(spec: str | Path) -> tuple[str, dict]:
    """``(name, mapping)`` of a config (:func:`config_path`), validated; the mapping is the
    file's own with its ``base:`` applied, if it names one (a variant of a recipe is
    ``base: ppo`` and the settings it changes; nested mappings such as ``model`` merge key
    by key). It is what a trial records and ``--resume`` compares. ``ValueError`` naming
    the file and the key on a malformed file or a bad value (a
    :class:`acld_gym.util.validate.DataFileError`)."""
    path = config_path(spec)
    data = _resolve(path)
    try:
        TrainConfig.from_dict(data)
    except (TypeError, ValueError) as exc:
        raise DataFileError(f"{path}: {exc}") from None
    return path.stem, data


def load_config(spec: str | Path) -> TrainConfig:
    """The validated :class:`TrainConfig` of a config (:func:`read_config`)."""
    return TrainConfig.from_dict(read_config(spec)[1])
