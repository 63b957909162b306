"""What the training-loop unit tests share: tiny SAC, PPO and CrossQ configurations and a
stand-in for an SB3 model (``Selection`` and ``train_algo`` read only
``model.policy``)."""

import dataclasses

import torch
import yaml

from train.config import TrainConfig


def tiny_sac(timesteps: int = 10, **fields) -> TrainConfig:
    """A SAC ``TrainConfig`` of ``timesteps`` env steps on raw observations with
    ``fields`` (``select=``, ``average=``, ``restarts=``) set."""
    return TrainConfig(
        algo="sac",
        timesteps=timesteps,
        model={"policy": "MlpPolicy"},
        features=None,
        normalize={},
        **fields,
    )


def shrink_ppo(cfg: TrainConfig, model: dict | None = None, **fields) -> TrainConfig:
    """A PPO config ``cfg`` shrunk to 1536 env steps on 4 sub-envs: 256 of whitening, then
    rollouts of 512 starting at 256, 768 and 1280 env steps, one epoch each; ``model`` keys
    and ``fields`` changed on top."""
    small = {"n_steps": 128, "batch_size": 256, "n_epochs": 1, **(model or {})}
    shrunk = {"timesteps": 1536, "n_envs": 4, "eval_points": 1, "whiten_steps": 256, **fields}
    return dataclasses.replace(cfg, model={**cfg.model, **small}, **shrunk)


def tiny_ppo(model: dict | None = None, **fields) -> TrainConfig:
    """The PPO recipe (train/recipes/ppo.yaml) shrunk by :func:`shrink_ppo`."""
    return shrink_ppo(
        TrainConfig(**yaml.safe_load(open("train/recipes/ppo.yaml"))), model, **fields
    )


def tiny_sac_recipe(timesteps: int, **fields) -> TrainConfig:
    """The SAC recipe (train/recipes/sac.yaml) shrunk to ``timesteps`` env steps on 4
    sub-envs (128 of whitening, learning from 200 on, a 2000-step buffer, minibatches of
    64) and without the recipe's retry threshold (``restart_above``: a tiny run never gets
    near it, and ``restarts=1`` needs none), with ``fields`` changed on top."""
    data = yaml.safe_load(open("train/recipes/sac.yaml"))
    data.update(timesteps=timesteps, n_envs=4, eval_points=1, whiten_steps=128)
    data.update({"restart_above": None, **fields})
    data["model"] = {**data["model"], "learning_starts": 200, "buffer_size": 2000, "batch_size": 64}
    return TrainConfig.from_dict(data)


def tiny_crossq(**fields) -> TrainConfig:
    """sb3-contrib's CrossQ with its own MLP policy on the SAC recipe's env-level pieces
    (random loads, the reward per load, action headroom 3; the probe
    ``studies/ablations/ablation_crossq.yaml``) shrunk to 1200 env steps on 2 sub-envs
    (learning from 400 on, one gradient step of a minibatch of 64 per step, layers of 32
    units, no checkpoint selection), with ``fields`` changed on top."""
    data = dict(
        algo="crossq",
        timesteps=1200,
        n_envs=2,
        loads={"random": 1},
        features=None,
        env_kwargs={"reward_scale": "passive"},
        normalize={"norm_obs": False, "norm_reward": False},
        eval_points=1,
        action_headroom=3.0,
        model={
            "policy": "MlpPolicy",
            "buffer_size": 10000,
            "batch_size": 64,
            "learning_starts": 400,
            "gamma": 0.995,
            "train_freq": 1,
            "gradient_steps": 1,
            "policy_kwargs": {"net_arch": {"pi": [32, 32], "qf": [32, 32]}},
        },
    )
    data.update(fields)
    return TrainConfig.from_dict(data)


class LinearModel:
    """An SB3 model's stand-in: its ``policy`` is a torch ``Linear(2, 1)``."""

    def __init__(self):
        self.policy = torch.nn.Linear(2, 1)

    def set(self, value: float) -> None:
        """Weights ``value``, bias ``-value``."""
        with torch.no_grad():
            self.policy.weight.fill_(value)
            self.policy.bias.fill_(-value)
