r"""The engineer's output-feedback LQG for the level's known actuator."""

from __future__ import annotations

import numpy as np

from .. import arguments
from .base import RigPolicy
from .riccati import lqr_gain

__all__ = ["DelayLQGPolicy"]


class DelayLQGPolicy(RigPolicy):
    r"""Output-feedback LQG designed for the level's actuator, on the env's own reward.

    **Design model** (:class:`baselines.engineer.model.RigModel`): the nominal reduced
    model sampled at the control period, with the amplifier's first-order lag as one more
    state where the level has one, augmented with the d commands in flight (d =
    ``actuator_delay``, a shift register):
    :math:`z_{k+1} = A z_k + b u_k`, :math:`z = [x_p; u_{k-d}, \dots, u_{k-1}]`.

    **The LQR** minimizes the env's step cost
    :math:`(y_{k+1}/y_{ref})^2 + \lambda (V/120)^2` summed over an infinite horizon,
    mapped to the sampled domain with its cross term
    (:meth:`~baselines.engineer.model.RigModel.reward_weights`):

    .. math::

        u_k = -K \hat z_k, \qquad K = (R + b^T X b)^{-1}(b^T X A + N^T),

    X from the DARE in scaled coordinates (:func:`baselines.engineer.riccati.lqr_gain`),
    saturated at ±120 V. ``weight`` multiplies the deflection term (1: the reward).

    **The Kalman filter** (:mod:`baselines.engineer.base`) estimates the plant part from
    the tip measurement, fed the voltage that actually reaches the amplifier (the commands
    in flight are known exactly); its process noise is the load (``load_std`` [N], white
    across periods) and the model's error (``model_std``: one value, or one per state of
    the plant part; as :func:`acld_gym.design.observer.discrete_kalman`), its sensor noise
    the level's ``sensor_noise``. Equivalent to applying the delay-free gain to the
    prediction :math:`\hat x_{k+d|k}`. ``for_env`` (and
    :func:`~baselines.engineer.level.engineer_policies`) take the level's noise model
    from :data:`~baselines.engineer.designs.DESIGNS`, chosen offline on training episodes;
    on ``ACLDBeamHard-v1`` it is the design for the level's distribution of plants.

    **Knows**: the nominal beam (20 °C, nominal parameters), the delay, the amplifier's
    bandwidth and slew rate, the sensor's noise, the reward's weights and, on the Hard
    level, the range of temperature and the parameter scatter (through the offline
    choice of its noise model). **Does not know**: the episode's load, temperature and
    parameters. On ``ACLDBeam-v1`` (no actuator) it is the plain output-feedback LQG on
    the reward's weights.
    """

    name = "lqg"

    def __init__(
        self,
        nom,
        config,
        weight: float = 1.0,
        model_std: float | None = None,
        load_std: float = 1.0,
        model=None,
    ):
        self.weight = arguments.positive("weight", weight)
        super().__init__(nom, config, model_std=model_std, load_std=load_std, model=model)
        m = self.model
        A, b = m.augmented()
        Q, R, N = m.reward_weights(deflection=self.weight)
        self.K = lqr_gain(A, b, Q, R, N, m.augmented_scale())[0]

    def command(self, z: np.ndarray, held: np.ndarray) -> np.ndarray:
        return -(z @ self.K)

    def small_signal_gain(self) -> np.ndarray:
        return self.K.copy()
