"""The import path of :mod:`baselines.evaluation.rollout` before it moved
(acld-gym 0.21.0): its public names, re-exported (the same objects). New code imports
:mod:`baselines.evaluation.rollout`."""

from baselines.evaluation.rollout import (  # noqa: F401 (re-exported)
    Episode,
    EvalRow,
    bound_episode,
    bound_solution,
    check_compatible,
    metrics_row,
    rollout,
)

__all__ = [
    "Episode",
    "EvalRow",
    "check_compatible",
    "rollout",
    "bound_episode",
    "bound_solution",
    "metrics_row",
]
