"""The single env (:class:`acld_gym.envs.beam_env.ACLDBeamEnv`) as the N = 1 case of the
batched step (:class:`acld_gym.envs.batch.BatchStep`): its state read from the batch
(:class:`BatchView`), its reset info (:func:`reset_info`), its compiled fast path
(:func:`fast_step`) and Gymnasium's 5-tuple of env 0 of a batch step (:func:`single`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from acld_gym.envs.batch import BatchStep, StepResult
from acld_gym.envs.step import INFO_KEYS, TERMINATED_BY

__all__ = ["BatchView", "fast_step", "reset_info", "single", "not_reset", "no_fast_path"]


def not_reset(action):
    """The step of an env that was not reset: ``RuntimeError``."""
    raise RuntimeError("ACLDBeamEnv: call reset() before step()")


def no_fast_path(action):
    """The fast path of an env without the compiled step: None (the numpy step runs)."""
    return None


class BatchView:
    """Mixin: the env's state as views of env 0 of its batched step ``self._batch``."""

    _batch: BatchStep

    batch = property(
        lambda self: self._batch,
        doc="The batched step this env is the N = 1 case of "
        "(:class:`acld_gym.envs.batch.BatchStep`: its state and step).",
    )
    k = property(lambda self: int(self._batch.k[0]), doc="Steps taken in the episode.")
    v = property(
        lambda self: float(self._batch.Z[0, self._batch.layout.voltage]),
        doc="Voltage applied in the last step [V].",
    )
    y_meas = property(
        lambda self: float(self._batch.Z[0, self._batch.layout.y_meas]),
        doc="Last tip measurement [m].",
    )
    x = property(
        lambda self: self._batch.Z[0, self._batch.layout.x],
        doc="True plant state [q; dq/dt] (a view).",
    )
    xhat = property(
        lambda self: self._batch.Z[0, self._batch.layout.xhat], doc="Observer state (a view)."
    )
    episode_plant = property(
        lambda self: self._batch.plants[0],
        doc="The sampled plant of this episode (randomized with ``param_noise``), a "
        ":class:`acld_gym.design.discrete.SampledSystem`.",
    )


def fast_step(b: BatchStep):
    """The compiled step of the env whose batch is ``b`` (with the reward scale and the
    appended observation entries, if set: :meth:`BatchStep.scaled_one`), or
    :func:`no_fast_path`."""
    if b.core is None:
        return no_fast_path
    if not b.appends:
        return b.core.step_one
    step_one, scaled_one = b.core.step_one, b.scaled_one
    return lambda action: scaled_one(step_one(action))


def reset_info(b: BatchStep, order: int) -> dict:
    """The info of ``reset`` for the batch ``b`` just started (``order``: the design's
    reduced order, the length of ``xr_true``)."""
    info = {
        "tip_deflection": 0.0,
        "voltage": 0.0,
        "requested_voltage": 0.0,
        "clipped": False,
        "tip_load": float(b.tip_loads()[0]),
        "time": 0.0,
        "xr_true": np.zeros(order),
        "terminated_by": None,
        "reward_deflection": 0.0,
        "reward_voltage": 0.0,
    }
    if b.scale_cost is not None:
        info["reward_scale"] = float(b.reward_scale[0])
    return info


def single(res: StepResult, requested: float, command: float, k: int, dt: float):
    """Gymnasium's 5-tuple of env 0 of a batch step (as the compiled ``step_one`` gives it)."""
    code = int(res.code[0])
    values = (
        float(res.y[0]),
        float(res.voltage[0]),
        requested,
        requested != command,
        float(res.tip_load[0]),
        k * dt,
        res.xr[0],
        TERMINATED_BY[code],
        float(res.reward_deflection[0]),
        float(res.reward_voltage[0]),
    )
    info: dict[str, Any] = dict(zip(INFO_KEYS, values, strict=True))
    return res.obs[0], float(res.reward[0]), code != 0, bool(res.truncated[0]), info
