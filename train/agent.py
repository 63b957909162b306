"""A trained agent as a policy with SB3's ``predict`` protocol in volts, so
:mod:`baselines.evaluate` treats it exactly like LQR, SMC and MPC."""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import numpy as np

from .vec import VoltageMap

__all__ = ["TrainedAgent", "MODEL_FILE", "STATS_FILE", "META_FILE"]

MODEL_FILE = "model.zip"
STATS_FILE = "vecnormalize.pkl"
META_FILE = "metadata.json"


def _algo_class(algo: str):
    from stable_baselines3 import PPO, SAC

    classes = {"ppo": PPO, "sac": SAC}
    if algo not in classes:
        raise ValueError(f"algo must be one of {list(classes)}, got {algo!r}")
    return classes[algo]




class TrainedAgent:
    """An agent directory (``model.zip``, ``vecnormalize.pkl``, ``metadata.json``)
    as a policy on the env's raw ``"estimate"`` observation.

    ``predict`` normalizes the observation with the frozen ``VecNormalize``
    statistics, runs the network deterministically and maps its action to volts
    with the same :class:`train.vec.VoltageMap` as in training.
    """

    def __init__(self, model, obs_norm, residual: str | None, name: str = "agent",
                 metadata: dict | None = None, directory: Path | None = None):
        self.directory = directory
        self.model = model
        self.obs_norm = obs_norm
        self.map = VoltageMap(residual)
        self.name = name
        self.metadata = dict(metadata or {})

    @classmethod
    def load(cls, directory: str | Path, name: str | None = None) -> TrainedAgent:
        """Load an agent directory written by ``python -m train``."""
        d = Path(directory)
        for f in (META_FILE, MODEL_FILE, STATS_FILE):
            if not (d / f).is_file():
                raise FileNotFoundError(f"agent directory {str(d)!r} lacks {f}")
        meta = json.loads((d / META_FILE).read_text())
        algo = meta.get("algo")
        model = _algo_class(algo).load(str(d / MODEL_FILE), device="cpu")
        with (d / STATS_FILE).open("rb") as fh:
            obs_norm = pickle.load(fh)  # a VecNormalize without its venv
        obs_norm.training = False
        residual = meta.get("config", {}).get("residual")
        return cls(model, obs_norm, residual, name or algo, meta, d)

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol: ``(voltages, state)``, shape (n, 1) for a batch or (1,)."""
        obs = np.asarray(observation, dtype=np.float32)
        batched = obs.ndim == 2
        obs2 = np.atleast_2d(obs)
        action, _ = self.model.predict(self.obs_norm.normalize_obs(obs2),
                                       deterministic=deterministic)
        v = self.map(action, obs2)
        return (v if batched else v[0]), state
