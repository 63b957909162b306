"""What the training-loop unit tests share: a tiny SAC configuration and a stand-in for an
SB3 model (``Averaging``, ``Selection`` and ``train_algo`` read only ``model.policy``)."""

import torch

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


class LinearModel:
    """An SB3 model's stand-in: its ``policy`` is a torch ``Linear(2, 1)``."""

    def __init__(self):
        self.policy = torch.nn.Linear(2, 1)

    def set(self, value: float) -> None:
        """Weights ``value``, bias ``-value``."""
        with torch.no_grad():
            self.policy.weight.fill_(value)
            self.policy.bias.fill_(-value)
