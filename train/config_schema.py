"""The schema of a training recipe: :class:`TrainConfig`, one YAML file under
``train/recipes/`` as a frozen dataclass (its fields' checks in
:mod:`train.config_validate`; reading the files in :mod:`train.config`)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

from acld_gym.physics.loads import parse_load_case

from .config_sections import SECTIONS, SelectConfig, section
from .config_validate import check_config

__all__ = ["TrainConfig"]


@dataclass(frozen=True)
class TrainConfig:
    """One training recipe (a YAML file under ``train/recipes/``).

    Attributes
    ----------
    algo : str
        One of :data:`train.config_algos.ALGOS`.
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
        check_config(self)

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
        """The dataclass of the sub-mapping ``name`` (:data:`SECTIONS`), None if off."""
        value = getattr(self, name)
        return None if value is None else section(SECTIONS[name], value, name)

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
