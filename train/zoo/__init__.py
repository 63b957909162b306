"""What rl-zoo3 needs besides its hyperparameter files (``train/zoo/*.yml``) to run the
package's recipes.

rl-zoo3 states a learning-rate schedule as ``lin_<start>``, linear in the progress from
``start`` to 0 (``rl_zoo3.exp_manager.ExperimentManager._preprocess_schedules``); any other
value than such a string or a number is refused. The SAC recipe's rate decays from 1e-3 to
5e-4, so ``train/zoo/sac.yml`` gives the start as a constant and the schedule as a callback,
which rl-zoo3 builds from the file's ``callback:`` list::

    learning_rate: !!float 1e-3
    callback:
      - train.zoo.LinearLearningRate: {start: !!float 1e-3, end: !!float 5e-4}
"""

from __future__ import annotations

from stable_baselines3.common.callbacks import BaseCallback

from acld_gym.util.validate import check_real
from train.core.sb3_train import LinearSchedule

__all__ = ["LinearLearningRate"]


class LinearLearningRate(BaseCallback):
    r"""Give the model the learning rate :math:`\eta(p) = \eta_1 + (\eta_0 - \eta_1)\,p`
    (``p`` the progress remaining, 1 -> 0; ``start`` :math:`\eta_0`, ``end``
    :math:`\eta_1`), the schedule ``{linear: [start, end]}`` of the package's configs.

    It replaces the model's ``lr_schedule`` when training starts, before the first update:
    SB3 reads that schedule at every update (``BaseAlgorithm._update_learning_rate``).

    Parameters
    ----------
    start, end : float
        The learning rate at the start (positive) and at the end (at least 0) of training.
    """

    def __init__(self, start: float, end: float, verbose: int = 0):
        super().__init__(verbose)
        self.schedule = LinearSchedule(
            check_real("start", start, 0.0, low_open=True), check_real("end", end, 0.0)
        )

    def _on_training_start(self) -> None:
        self.model.lr_schedule = self.schedule

    def _on_step(self) -> bool:
        return True
