"""The import path of :mod:`baselines.evaluation.references` before it moved
(acld-gym 0.21.0): its public names, re-exported (the same objects). New code imports
:mod:`baselines.evaluation.references`."""

from baselines.evaluation.references import (  # noqa: F401 (re-exported)
    FORMAT,
    KIND,
    KINDS,
    SPOT_RTOL,
    References,
    cache_path,
    make_env,
    reference_episode,
    references,
)

__all__ = [
    "References",
    "references",
    "reference_episode",
    "make_env",
    "cache_path",
    "KIND",
    "KINDS",
    "FORMAT",
    "SPOT_RTOL",
]
