r"""The per-episode reward scale (``EnvConfig.reward_scale``): rewards of episodes on
different loads made comparable.

With ``reward_scale="passive"`` each reward of an episode is divided by

.. math:: c = \frac{1}{T} \sum_{k=1}^{T} \left(\frac{y^{p}_k}{y_\mathrm{ref}}\right)^2,

the mean step cost of the *passive* beam (zero voltage) on the episode's own tip load, over
the episode's T steps: :math:`y^p` is the noise-free tip deflection of the configuration's
plant (the nominal beam at the configuration's temperature; the amplifier and the delay do
not act at zero voltage) driven by that load. The passive policy's return is then exactly
``-T`` on every load, and a policy's return is ``-T`` times its cost relative to doing
nothing. Random loads differ in c by six decades (5e-6 .. 10 on ``ACLDBeam-v1``), so
without the scale a few violent loads dominate every gradient and the critic's targets.

With ``reward_scale="lqr"`` c is instead LQR's mean step cost on the episode's load: the
unscaled cost (deflection and voltage terms, :func:`acld_gym.envs.step.reward_terms`) of a
noise-free episode of the configuration's env (its plant, amplifier, delay and observer)
under the thesis's LQR law, saturated at +/-120 V (:class:`LQRCost`). The return is then
``-T`` times the episode's cost relative to LQR's (the benchmark's ISE / LQR of one
episode, with the voltage term), and exactly ``-T`` for the LQR policy without sensor
noise. It costs one more (noise-free) episode per reset, batched over the loads reset
together.

c is known at reset (the load of an episode is drawn at reset), and is reported as
``info["reward_scale"]``; the reward terms ``info["reward_deflection"]`` and
``info["reward_voltage"]`` stay unscaled. Where the episode's plant is drawn
(``param_noise``, ``temperature_range``), c is still that of the configuration's plant: a
scale, not a reward. c is floored at :data:`SCALE_FLOOR` (a load that does not move the
beam), which is reported, not hidden: ``info["reward_scale"]`` is the value divided by.

``observe_reward_scale=True`` appends :math:`\log c` to the observation as its last entry: a
privileged input (the load's violence, from the future of the episode) meant for a critic
only (an asymmetric actor-critic); a deployable actor must not read it.
"""

from __future__ import annotations

import numpy as np

from acld_gym.design.discrete import SampledSystem
from acld_gym.envs.step import load_schedule
from acld_gym.physics.actuator import V_LIMIT
from acld_gym.physics.loads import TipLoad

__all__ = ["REWARD_SCALES", "SCALE_FLOOR", "PassiveCost", "LQRCost"]

#: Values of ``EnvConfig.reward_scale``.
REWARD_SCALES = (None, "passive", "lqr")

#: Smallest reward scale c (a passive tip RMS of 1 nm at ``y_ref`` = 1 mm).
SCALE_FLOOR = 1e-12

#: Episodes whose passive response is computed together (memory: rows x steps x 2 substeps).
_CHUNK = 64


class PassiveCost:
    """The passive beam's mean step cost c on given tip loads (module docstring).

    Parameters
    ----------
    plant : the sampled plant (:class:`acld_gym.design.discrete.SampledSystem`), driven by
        the load only.
    output : its tip-deflection row, ``y = output @ x`` [m].
    steps : T, steps per episode.
    y_ref : the reward's deflection scale [m].
    """

    def __init__(self, plant: SampledSystem, output: np.ndarray, steps: int, y_ref: float):
        self.plant = plant
        self.output = np.asarray(output, dtype=np.float64).reshape(-1)
        if self.output.shape != (plant.Ad.shape[0],):
            raise ValueError(
                f"output must have {plant.Ad.shape[0]} entries (the plant's "
                f"states), got {self.output.shape}"
            )
        self.steps = int(steps)
        self.y_ref = float(y_ref)
        self._AT = np.ascontiguousarray(plant.Ad.T)
        self._WT = np.ascontiguousarray(np.hstack([plant.W0, plant.W1]).T)  # (2 s, n)

    def __call__(self, loads: list[TipLoad]) -> np.ndarray:
        """c of each load in ``loads`` (len(loads),), at least :data:`SCALE_FLOOR`."""
        out = np.empty(len(loads))
        for a in range(0, len(loads), _CHUNK):
            part = loads[a : a + _CHUNK]
            F = np.stack([load_schedule(self.plant, load, 0, self.steps)[0] for load in part])
            x = np.zeros((len(part), self._AT.shape[0]))
            acc = np.zeros(len(part))
            for k in range(self.steps):  # x_{k+1} = A x_k + [W0 W1] [f0; f1]_k, y = output x
                x = x @ self._AT + F[:, k] @ self._WT
                y = x @ self.output
                acc += y * y
            out[a : a + len(part)] = acc / (self.steps * self.y_ref**2)
        return np.maximum(out, SCALE_FLOOR)


class LQRCost:
    """LQR's mean step cost c on given tip loads (``reward_scale="lqr"``; module docstring):
    a noise-free episode of the configuration's env under the thesis's LQR law (the
    reference of :class:`baselines.policies.LQRPolicy`), its unscaled cost over all T steps.

    Parameters
    ----------
    config : the env's configuration (:class:`acld_gym.envs.config.EnvConfig`); the
        episodes run on it without sensor noise, on its fixed plant (``param_noise`` and
        ``temperature_range`` off), observed through its observer's estimate.
    steps : T, steps per episode.
    batch_step : the env's step, called as ``batch_step(config, num_envs, steps)``
        (:class:`acld_gym.envs.batch.BatchStep`, which builds this cost for its
        ``reward_scale="lqr"`` and passes itself: the episodes run on the env's own step).
    """

    def __init__(self, config, steps: int, batch_step):
        self.config = config.replace(
            reward_scale=None,
            observe_reward_scale=False,
            observe_commands=False,
            obs_mode="estimate",
            sensor_noise=0.0,
            param_noise=0.0,
            temperature_range=None,
        )
        self.steps = int(steps)
        self.batch_step = batch_step
        nom = self.config.nominal()
        #: The law (:meth:`acld_gym.design.nominal.NominalDesign.lqr_law`) on the reduced
        #: state, decoded from the estimate observation as obs[:k] * xr_scale.
        self.law = nom.lqr_law()
        self.xr_scale = nom.xr_scale
        # A BatchStep per power-of-two batch size (the loads padded up to it): at most
        # log2(N) + 1 of them, whatever numbers of envs a vector env resets at once.
        self._batches: dict = {}

    def __call__(self, loads: list[TipLoad]) -> np.ndarray:
        """c of each load in ``loads`` (len(loads),), at least :data:`SCALE_FLOOR`."""
        n = len(loads)
        if n == 0:
            return np.empty(0)
        size = 1 << (n - 1).bit_length()
        b = self._batches.get(size)
        if b is None:
            b = self._batches[size] = self.batch_step(self.config, size, self.steps)
        padded = list(loads) + [loads[-1]] * (size - n)
        b.start_episodes(np.arange(size), padded, [None] * size, np.zeros((size, self.steps + 1)))
        k = self.xr_scale.shape[0]
        obs, acc = b.observations(), np.zeros(size)
        for _ in range(self.steps):
            v = self.law.voltage(obs[:, :k].astype(np.float64) * self.xr_scale, V_LIMIT)
            obs, reward, _, _, _ = b.vector_step(v.astype(np.float32))  # as an agent's action
            acc -= reward
        return np.maximum(acc[:n] / self.steps, SCALE_FLOOR)
