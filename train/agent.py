"""A trained agent as a policy with SB3's ``predict`` protocol in volts, so
:mod:`baselines.evaluate` treats it exactly like LQR, SMC and MPC."""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import numpy as np

from .features import direction_features
from .vec import VoltageMap

__all__ = ["TrainedAgent", "NumpyActor", "MODEL_FILE", "STATS_FILE", "META_FILE"]

MODEL_FILE = "model.zip"
STATS_FILE = "vecnormalize.pkl"
META_FILE = "metadata.json"


def _algo_class(algo: str):
    from stable_baselines3 import PPO, SAC

    classes = {"ppo": PPO, "sac": SAC}
    if algo not in classes:
        raise ValueError(f"algo must be one of {list(classes)}, got {algo!r}")
    return classes[algo]



class NumpyActor:
    """The deterministic actor of an SB3 ``MlpPolicy`` (PPO or SAC) as numpy layers.

    SB3's ``predict`` costs about 0.2 ms per call (tensor conversion, checks); the
    network itself is a few small matrix-vector products. This evaluates exactly
    SB3's deterministic action -- PPO: the Gaussian mean clipped to the action box;
    SAC: tanh of the mean -- in float64 (the tests compare it with ``predict``), with
    the flatten or :class:`train.features.DirectionFeatures` extractor.
    """

    def __init__(self, model):
        import torch.nn as nn
        from stable_baselines3 import SAC
        from stable_baselines3.common.torch_layers import FlattenExtractor

        pol = model.policy
        if isinstance(model, SAC):
            extractor = pol.actor.features_extractor
            mu = pol.actor.mu
            layers = [*pol.actor.latent_pi, *(mu if isinstance(mu, nn.Sequential) else [mu])]
            self.squash = True
        else:
            extractor = pol.pi_features_extractor
            layers = [*pol.mlp_extractor.policy_net, pol.action_net]
            self.squash = bool(pol.squash_output)
        from .features import DirectionFeatures

        self.ops: list[tuple] = []
        if isinstance(extractor, DirectionFeatures):
            self.ops.append(("direction",))
        elif not isinstance(extractor, FlattenExtractor):
            raise TypeError(f"NumpyActor supports MlpPolicy with the flatten or direction "
                            f"features only, got {type(extractor).__name__}")
        for layer in layers:
            if isinstance(layer, nn.Linear):
                self.ops.append(("linear", layer.weight.detach().double().numpy().T.copy(),
                                 layer.bias.detach().double().numpy().copy()))
            elif isinstance(layer, nn.Tanh):
                self.ops.append(("tanh",))
            elif isinstance(layer, nn.ReLU):
                self.ops.append(("relu",))
            elif isinstance(layer, nn.Hardtanh):
                self.ops.append(("clip", float(layer.min_val), float(layer.max_val)))
            else:
                raise TypeError(f"NumpyActor: unsupported layer {layer!r}")

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        """Actions in [-1, 1], shape (n, 1), for normalized observations (n, d)."""
        z = np.asarray(obs, dtype=np.float64)
        for op in self.ops:
            if op[0] == "linear":
                z = z @ op[1] + op[2]
            elif op[0] == "tanh":
                z = np.tanh(z)
            elif op[0] == "direction":
                z = direction_features(z)
            elif op[0] == "relu":
                z = np.maximum(z, 0.0)
            else:
                z = np.clip(z, op[1], op[2])
        return np.clip(np.tanh(z) if self.squash else z, -1.0, 1.0)


class TrainedAgent:
    """An agent directory (``model.zip``, ``vecnormalize.pkl``, ``metadata.json``)
    as a policy on the env's raw ``"estimate"`` observation.

    ``predict`` normalizes the observation with the frozen ``VecNormalize``
    statistics, runs the actor network deterministically (:class:`NumpyActor`) and
    maps its action to volts with the same :class:`train.vec.VoltageMap` as in
    training. ``model`` is the SB3 model (``model.predict`` gives the same actions).
    """

    def __init__(self, model, obs_norm, residual: str | None, name: str = "agent",
                 metadata: dict | None = None, directory: Path | None = None):
        self.directory = directory
        self.model = model
        self.actor = NumpyActor(model)
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
        if not deterministic:
            raise ValueError("deterministic must be True: TrainedAgent evaluates the "
                             "deterministic policy (use .model.predict to sample)")
        v = self.map(self.actor(self.obs_norm.normalize_obs(obs2)), obs2)
        return (v if batched else v[0]), state
