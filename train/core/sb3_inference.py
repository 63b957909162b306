"""A trained SB3 model as a ``predict`` policy in volts on the env's raw observation
(:class:`SB3Policy`: its whitening, direction features, frozen ``VecNormalize`` statistics
and voltage map), and the small copy of it that crosses process boundaries."""

from __future__ import annotations

import pickle

import numpy as np
import torch
from stable_baselines3.common.vec_env import VecNormalize

from ..agent import actor_extractor
from ..commands import CommandMemory
from ..features import DropLast, direction_features
from ..voltage import VoltageMap

__all__ = ["SB3Policy"]


class _PolicyOnly:
    """What :class:`SB3Policy` and :func:`train.agent.export_sb3` read of an SB3 model:
    its ``policy`` (the torch module). Pickles the module as plain bytes: a process pool
    sends results with torch's tensor reductions (shared memory), which refuse the tensors
    a training step leaves attached to autograd (gSDE's last noise draw)."""

    def __init__(self, policy):
        self.policy = policy

    def __getstate__(self) -> dict:
        return {"policy": pickle.dumps(self.policy, protocol=pickle.HIGHEST_PROTOCOL)}

    def __setstate__(self, state: dict) -> None:
        self.policy = pickle.loads(state["policy"])


class SB3Policy:
    """A trained SB3 model with its frozen ``VecNormalize`` statistics as a policy on the
    env's raw observation, ``predict`` in volts (``voltage_map``: the training env's
    :class:`train.voltage.VoltageMap`, default ``V = 120 clip(a, -1, 1)``);
    ``transform``: the agent's whitening matrix (:class:`train.vec.VecWhiten`), or None;
    ``commands``: the memory of its own commands of a model trained with
    ``observe_commands`` (:class:`train.commands.CommandMemory`, carried in ``state``), or
    None."""

    def __init__(
        self,
        model,
        obs_norm: VecNormalize | None,
        features: str | None,
        transform: np.ndarray | None = None,
        voltage_map=None,
        commands: CommandMemory | None = None,
    ):
        self.model = model
        self.commands = commands
        self.obs_norm = obs_norm
        self.features = features
        self.transform = None if transform is None else np.asarray(transform, np.float64)
        self.voltage_map = VoltageMap() if voltage_map is None else voltage_map
        extractor = actor_extractor(model)  # an asymmetric agent's actor drops the
        # privileged entries (log c, ...) the plain env does not have: predict pads them
        self.privileged = extractor.n if isinstance(extractor, DropLast) else 0

    @property
    def residual(self) -> str | None:
        """The voltage map's residual (None or ``"lqr"``)."""
        return self.voltage_map.residual

    def portable(self) -> SB3Policy:
        """This policy without its model's training state (env, replay buffer, logger,
        schedules): the same ``predict`` and export, small enough to send between
        processes (a SAC model with its buffer pickles to ~1 GB)."""
        return SB3Policy(
            _PolicyOnly(self.model.policy),
            self.obs_norm,
            self.features,
            self.transform,
            self.voltage_map,
            self.commands,
        )

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        obs = np.asarray(observation, dtype=np.float32)
        batched = obs.ndim == 2
        raw = np.atleast_2d(obs)
        x = raw
        if self.commands is not None:
            x, state = self.commands.observe(raw, state, episode_start)
        if self.transform is not None:
            x = (x.astype(np.float64) @ self.transform).astype(np.float32)
        if self.features == "direction":
            x = direction_features(x).astype(np.float32)
        if self.obs_norm is not None:
            x = self.obs_norm.normalize_obs(x)
        if self.privileged:
            x = np.concatenate([x, np.zeros((len(x), self.privileged), np.float32)], axis=1)
        with torch.no_grad():  # the deterministic action of model.predict, without its checks
            a = self.model.policy._predict(torch.as_tensor(x), deterministic=True).numpy()
        v = self.voltage_map(a, raw)
        if self.commands is not None:
            state = self.commands.remember(state, v)
        return (v if batched else v[0]), state
