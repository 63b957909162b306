"""The algorithms a training config may name: the random search ``vrs`` and the
stable-baselines3 / sb3-contrib ones (:data:`SB3_ALGOS`), and :func:`algo_class`, the class
of one of the latter."""

from __future__ import annotations

import importlib

__all__ = ["SB3_ALGOS", "ALGOS", "algo_class"]

#: Algorithms from stable-baselines3 / sb3-contrib (module, class).
SB3_ALGOS = {
    "ppo": ("stable_baselines3", "PPO"),
    "sac": ("stable_baselines3", "SAC"),
    "td3": ("stable_baselines3", "TD3"),
    "tqc": ("sb3_contrib", "TQC"),
    "crossq": ("sb3_contrib", "CrossQ"),
    "ars": ("sb3_contrib", "ARS"),
}
#: Every algorithm: the random search ``vrs`` (:mod:`train.core.search`) and the SB3 ones.
ALGOS = ("vrs", *SB3_ALGOS)


def algo_class(algo: str):
    """The stable-baselines3 / sb3-contrib class of ``algo`` (:data:`SB3_ALGOS`)."""
    if algo not in SB3_ALGOS:
        raise ValueError(f"algo must be one of {list(SB3_ALGOS)}, got {algo!r}")
    module, name = SB3_ALGOS[algo]
    return getattr(importlib.import_module(module), name)
