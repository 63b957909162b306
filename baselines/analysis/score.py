"""The import path of :mod:`baselines.evaluation.score` before it moved
(acld-gym 0.21.0): its public names, re-exported (the same objects). New code imports
:mod:`baselines.evaluation.score`."""

from baselines.evaluation.score import (  # noqa: F401 (re-exported)
    SCORE_NAME,
    SCORE_VERSION,
    Score,
    ScoreUndefined,
    episode_scores,
    format_scores,
    policy_ises,
    score_of,
    score_policies,
    score_policy,
)

__all__ = [
    "SCORE_VERSION",
    "SCORE_NAME",
    "ScoreUndefined",
    "Score",
    "episode_scores",
    "score_of",
    "score_policy",
    "policy_ises",
    "score_policies",
    "format_scores",
]
