"""Training of the stable-baselines3 / sb3-contrib algorithms (PPO, SAC, TD3, TQC,
CrossQ, ARS): the model of a :class:`train.config.TrainConfig` (:func:`make_model`) on the
env of :func:`train.vec.make_vec_env`, from scratch on the env's observation and reward
(or, opt-in, after a DAgger start: ``distill``)."""

from __future__ import annotations

import copy
import inspect
import sys
import time
from collections.abc import Callable

import numpy as np
import torch
import torch.nn as nn
from gymnasium import spaces
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.logger import HumanOutputFormat, Logger
from stable_baselines3.common.off_policy_algorithm import OffPolicyAlgorithm
from stable_baselines3.common.vec_env import VecNormalize

import acld_gym  # noqa: F401  (registers the env ids)
from acld_gym.wrappers import whitening

from ..agent import actor_parts
from ..commands import command_memory
from ..config import TrainConfig, algo_class
from ..distill import distill
from ..vec import VecWhiten, make_vec_env
from ..voltage import VoltageMap
from . import evaluate
from .buffers import FlatNStepReplayBuffer
from .evaluate import CurveCallback, eval_schedule, validation_seeds
from .ppo_policies import AsymmetricCriticPolicy, SplitCriticPolicy
from .sac_policies import AsymmetricSACPolicy
from .sb3_inference import SB3Policy

__all__ = [
    "LinearSchedule",
    "Selection",
    "fold_whitening",
    "make_model",
    "train_sb3",
]


class LinearSchedule:
    r"""An SB3 schedule (of the progress remaining, 1 -> 0) linear from ``start`` to ``end``,
    with an optional linear warm-up: the value of ``{linear: [start, end]}`` (or
    ``{linear: [start, end], warmup: w}``) in a config.

    With progress :math:`p = 1 - \text{remaining}`, clipped to [0, 1], the value is

    .. math:: v(p) = \min(1, p / w)\,\bigl(s + (e - s)\,p\bigr),

    the linear schedule scaled up from 0 over the first fraction ``w`` of training
    (``w = 0``: no warm-up, the plain linear schedule). The clip matters at the end: SB3
    reports ``1 - steps / budget``, below 0 after a last rollout that overshoots the
    budget, where the unclipped line would go past ``end`` (below 0 for a rate decaying to
    0: a step up the loss)."""

    def __init__(self, start: float, end: float, warmup: float = 0.0):
        if not 0.0 <= warmup < 1.0:
            raise ValueError(f"warmup: a fraction of training in [0, 1), got {warmup!r}")
        self.start, self.end, self.warmup = start, end, warmup

    def __call__(self, progress_remaining: float) -> float:
        remaining = min(max(progress_remaining, 0.0), 1.0)
        value = self.end + (self.start - self.end) * remaining
        done = 1.0 - remaining
        return value if done >= self.warmup else value * done / self.warmup


def _schedule(key: str, value: dict) -> LinearSchedule:
    """The schedule of a ``{linear: [start, end]}`` value of the model key ``key``
    (``warmup: w`` added: :class:`LinearSchedule`'s warm-up, for ``learning_rate``)."""
    forms = ["{linear: [start, end]}"]
    keys = {"linear"}
    if key == "learning_rate":
        forms.append("{linear: [start, end], warmup: w}")
        keys.add("warmup")
    if not ({"linear"} <= set(value) <= keys) or len(value["linear"]) != 2:
        raise ValueError(f"{key}: a number or {' or '.join(forms)}, got {value!r}")
    try:
        return LinearSchedule(*map(float, value["linear"]), float(value.get("warmup", 0.0)))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{key}: {exc}") from None


def _resolve_policy_kwargs(kwargs: dict) -> dict:
    """YAML-friendly keyword arguments: ``policy_kwargs.activation_fn`` given by name
    (``"tanh"``); ``policy: SplitCriticPolicy`` names :class:`SplitCriticPolicy`;
    ``learning_rate`` / ``clip_range`` as ``{linear: [start, end]}``, a schedule linear in
    the progress from ``start`` to ``end`` (``ent_coef``'s, which SB3 takes as a number, is
    :func:`ent_coef_schedule`'s, applied by :func:`train_sb3` once per rollout)."""
    for key in ("learning_rate", "clip_range"):
        if isinstance(kwargs.get(key), dict):
            kwargs = {**kwargs, key: _schedule(key, kwargs[key])}

    named = {
        "SplitCriticPolicy": SplitCriticPolicy,
        "AsymmetricCriticPolicy": AsymmetricCriticPolicy,
        "AsymmetricSACPolicy": AsymmetricSACPolicy,
    }
    if kwargs.get("policy") in named:
        kwargs = {**kwargs, "policy": named[kwargs["policy"]]}
    pk = dict(kwargs.get("policy_kwargs") or {})
    if isinstance(pk.get("activation_fn"), str):
        pk["activation_fn"] = {"tanh": nn.Tanh, "relu": nn.ReLU}[pk["activation_fn"].lower()]
    if pk:
        kwargs = {**kwargs, "policy_kwargs": pk}
    return kwargs


def ent_coef_schedule(cfg: TrainConfig) -> LinearSchedule | None:
    """The schedule of ``cfg``'s ``model.ent_coef`` if it is ``{linear: [start, end]}``,
    else None. Only an on-policy algorithm reads its ``ent_coef`` anew at every update
    (SB3's PPO: ``loss = ... + ent_coef * entropy_loss``), so a schedule is for PPO only:
    :func:`make_model` starts the model at its start value, :func:`train_sb3` sets it
    before each update."""
    value = cfg.model.get("ent_coef")
    return _schedule("ent_coef", value) if isinstance(value, dict) else None


def first_linear(model) -> nn.Linear:
    """The actor's first layer, which :func:`fold_whitening` folds the whitening into: a
    ``Linear`` layer, else ``TypeError`` (an actor that starts with a per-feature layer,
    such as CrossQ's batch renormalisation, cannot take a full linear map into it; train
    such a policy with ``whiten_steps: 0``). Checked before the whitening is estimated."""
    layers = actor_parts(model)[1]
    if not layers or not isinstance(layers[0], nn.Linear):
        first = type(layers[0]).__name__ if layers else "no layer"
        raise TypeError(
            f"whiten_steps: the whitening folds into the actor's first layer, which must be "
            f"a Linear layer; {type(model.policy).__name__}'s actor starts with {first} "
            f"(use whiten_steps: 0)"
        )
    return layers[0]


def fold_whitening(model, transform: np.ndarray) -> None:
    """Fold the whitening ``u = T^T z`` into the actor's first layer (``W u = (W T^T) z``),
    so that the trained actor takes the raw observation (and exports as a plain SB3
    actor). Only the deterministic actor stays meaningful afterwards (critic and gSDE
    noise still expect u): call it when training is over. A policy whose actor is not a
    chain of layers folds it itself, with a method ``fold_whitening(transform)``."""
    own = getattr(model.policy, "fold_whitening", None)
    if callable(own):
        own(np.asarray(transform))
        return
    layer = first_linear(model)
    with torch.no_grad():
        t = torch.as_tensor(np.asarray(transform).T, dtype=layer.weight.dtype)
        layer.weight.copy_(layer.weight @ t)


def make_model(cfg: TrainConfig, venv, seed: int, **kwargs):
    """The (untrained) SB3 model of ``cfg`` on ``venv``: the config's keyword arguments
    (schedules and policy names resolved, :func:`_resolve_policy_kwargs`), CPU, seeded;
    ``kwargs`` add to them."""
    model_kwargs = _resolve_policy_kwargs(dict(cfg.model))
    ent_sched = ent_coef_schedule(cfg)
    if ent_sched is not None:
        if cfg.algo != "ppo":
            raise ValueError(
                f"model.ent_coef: a schedule {{linear: [start, end]}} is for "
                f"ppo only, got one for {cfg.algo}"
            )
        model_kwargs["ent_coef"] = ent_sched(1.0)
    policy = model_kwargs.pop("policy")
    if getattr(policy, "takes_action_headroom", False):  # it needs the env's action map
        pk = dict(model_kwargs.get("policy_kwargs") or {})
        if pk.get("action_headroom", cfg.action_headroom) != cfg.action_headroom:
            raise ValueError(
                f"model.policy_kwargs.action_headroom "
                f"{pk['action_headroom']!r} differs from action_headroom "
                f"{cfg.action_headroom!r}: give it once, as action_headroom"
            )
        model_kwargs["policy_kwargs"] = {**pk, "action_headroom": cfg.action_headroom}
    model_kwargs.setdefault("verbose", 0)
    cls = algo_class(cfg.algo)
    model_kwargs = _flat_n_step_buffer(cls, venv, {**model_kwargs, **kwargs})
    model = cls(policy, venv, seed=seed, device="cpu", **model_kwargs)
    if model_kwargs.get("tensorboard_log") is None:
        # SB3's default logger makes an empty /tmp/SB3-<date> folder per model, quiet or
        # not: log to the console (verbose) or nowhere, without a folder.
        formats = [HumanOutputFormat(sys.stdout)] if model_kwargs.get("verbose") else []
        model.set_logger(Logger(folder=None, output_formats=formats))
    return model


def _flat_n_step_buffer(cls, venv, model_kwargs: dict) -> dict:
    """``model_kwargs`` of an off-policy algorithm with n-step returns (``n_steps > 1``, no
    buffer class of its own, a Box observation) with SB3's n-step buffer replaced by
    :class:`train.core.buffers.FlatNStepReplayBuffer`, which returns the same samples,
    faster: ``n_steps`` and ``gamma`` move to ``replay_buffer_kwargs``, as SB3 passes
    them to its own. Other kwargs are returned as they are."""
    n = model_kwargs.get("n_steps", 1)
    if (
        not issubclass(cls, OffPolicyAlgorithm)
        or n <= 1
        or model_kwargs.get("replay_buffer_class") is not None
        or not isinstance(venv.observation_space, spaces.Box)
    ):
        return model_kwargs
    gamma = model_kwargs.get("gamma", inspect.signature(cls.__init__).parameters["gamma"].default)
    out = {k: v for k, v in model_kwargs.items() if k != "n_steps"}
    out["replay_buffer_class"] = FlatNStepReplayBuffer
    out["replay_buffer_kwargs"] = {
        **(model_kwargs.get("replay_buffer_kwargs") or {}),
        "n_steps": n,
        "gamma": gamma,
    }
    return out


class Selection:
    """Checkpoint selection of :class:`train.config.SelectConfig` (``cfg.select``; inert if
    None): :meth:`check` scores the policy made by ``snapshot()`` on the validation loads
    (:func:`train.core.evaluate.validation_rollout`) and keeps a copy of the SB3 policy's
    parameters when it is the best so far; :meth:`finish` checks the final policy too,
    loads the best parameters back into the model and returns the record (the step and
    cost of each check, the step chosen, the env steps of all validation episodes).
    ``progress`` (a :class:`train.core.progress.Progress`) says each check."""

    def __init__(self, cfg: TrainConfig, env_id: str, progress=None):
        self.config = cfg.select_config
        self.env_id = env_id
        self.progress = progress
        self.seeds = () if self.config is None else validation_seeds(self.config.episodes)
        self.next = None if self.config is None else self.config.start
        self.history: list[dict] = []
        self.env_steps = 0  # of the validation episodes (not training: not in the budget)
        self.best: tuple | None = None  # (cost, steps, state_dict)

    def due(self, steps: int) -> bool:
        return self.next is not None and steps >= self.next

    def check(self, steps: int, model, snapshot) -> None:
        cost, env_steps = evaluate.validation_rollout(snapshot(), self.env_id, self.seeds)
        self.env_steps += env_steps
        self.history.append({"steps": int(steps), "cost": cost})
        if self.best is None or cost < self.best[0]:
            self.best = (cost, int(steps), copy.deepcopy(model.policy.state_dict()))
        if self.progress is not None:
            self.progress.check(steps, cost, self.best[0], len(self.seeds))
        while self.next <= steps:
            self.next += self.config.every

    def finish(self, steps: int, model, snapshot) -> dict | None:
        if self.config is None:
            return None
        if not self.history or self.history[-1]["steps"] != steps:
            self.check(steps, model, snapshot)
        cost, chosen, state = self.best
        model.policy.load_state_dict(state)
        return {
            "episodes": self.config.episodes,
            "history": self.history,
            "steps": chosen,
            "cost": cost,
            "validation_env_steps": self.env_steps,
        }


def train_sb3(
    cfg: TrainConfig,
    seed: int,
    env_id: str,
    callback: CurveCallback | None = None,
    *,
    make_env: Callable[[TrainConfig, int, str], VecNormalize] = make_vec_env,
    progress=None,
) -> tuple[SB3Policy, dict]:
    """Train an SB3 / sb3-contrib algorithm for ``cfg.timesteps`` env steps (with
    ``cfg.whiten_steps``: first that many steps of the initial policy, from which the
    whitening is estimated, then the rest of the budget of training; with
    ``cfg.distill``: the DAgger start first, its env steps not counted).

    ``make_env(cfg, seed, env_id)`` builds the training env: :func:`train.vec.make_vec_env`
    unless a probe wraps its own (it must return the same layers, ``VecNormalize`` over
    :class:`train.vec.VecWhiten` where ``cfg.whiten_steps`` is set); the evaluation and the
    validation checks run on the plain env whatever it is. ``progress`` (a
    :class:`train.core.progress.Progress`) says each validation check."""
    torch.set_num_threads(1)
    venv = make_env(cfg, seed, env_id)
    if not isinstance(venv, VecNormalize):
        venv.close()
        raise TypeError(
            f"make_env must return a VecNormalize (train.vec.make_vec_env's outer layer), "
            f"got {type(venv).__name__}"
        )
    model = make_model(cfg, venv, seed)
    ent_sched = ent_coef_schedule(cfg)
    vmap = VoltageMap(cfg.residual, cfg.mesh, cfg.action_headroom)
    commands = command_memory(env_id, cfg.env_kwargs)
    distilled = None
    if cfg.distill is not None:
        t0 = time.perf_counter()
        distilled = {
            "history": distill(model, venv, cfg.distill_config, seed=seed),
            "seconds": round(time.perf_counter() - t0, 1),
        }
    schedule = eval_schedule(cfg.timesteps, cfg.eval_points)
    white = venv.venv  # under VecNormalize (whiten_steps: no direction features)
    transform = None
    offset = 0

    def snapshot() -> SB3Policy:
        norm = None
        if cfg.normalize.get("norm_obs", False):
            norm = copy.deepcopy(venv)
            norm.venv = None
            norm.training = False
        return SB3Policy(model, norm, cfg.features, transform, vmap, commands)

    if cfg.whiten_steps:
        assert isinstance(white, VecWhiten)
        if not callable(getattr(model.policy, "fold_whitening", None)):
            first_linear(model)  # before the whitening's env steps, not after training
        if callback is not None and schedule.due(0):
            callback(0, snapshot())
        white.collect = []
        obs = venv.reset()
        if getattr(model, "use_sde", False):
            model.policy.reset_noise(venv.num_envs)
        while offset < cfg.whiten_steps:
            action, _ = model.predict(obs, deterministic=False)
            obs, _, _, _ = venv.step(action)
            offset += venv.num_envs
        transform = whitening(np.concatenate(white.collect))
        white.collect = None
        white.set_transform(transform)

    select = Selection(cfg, env_id, progress)

    class Curve(BaseCallback):
        def _on_step(self) -> bool:
            steps = offset + int(self.num_timesteps)
            if callback is not None and schedule.due(steps):
                callback(steps, snapshot())
            # a check due at the budget's end is finish()'s, after the last update: SB3
            # calls this before the update of the rollout the step belongs to
            if select.due(steps) and steps < offset + budget:
                select.check(steps, model, snapshot)
            return True

        def _on_training_start(self) -> None:
            self._on_step()

        def _on_rollout_end(self) -> None:  # before the update of this rollout
            if ent_sched is not None:  # the last rollout may overshoot the budget
                model.ent_coef = ent_sched(max(1.0 - self.num_timesteps / budget, 0.0))

    budget = max(cfg.timesteps - offset, 1)
    model.learn(budget, callback=Curve())
    steps = offset + int(model.num_timesteps)
    record = {
        "steps": steps,
        "whiten_steps": offset,
        "transform": None if transform is None else transform.tolist(),
        "distill": distilled,
        "select": select.finish(steps, model, snapshot),
    }
    if transform is not None:  # u = T' z into the actor's first layer: a plain SB3 actor on z
        fold_whitening(model, transform)
        transform = None
    pol = snapshot()
    venv.close()
    return pol, record
