"""A short training run per algorithm through the one stack (train.core.algos.train_algo on
the env of train.vec.make_vec_env): it updates the networks, repeats bit for bit with the
same seed, and the opt-in DAgger start is recorded. Marked slow: ``make test-slow``."""

import numpy as np
import pytest
import torch

from train.config import load_config
from train.core.algos import train_algo
from train.core.sb3_train import make_model
from train.vec import make_vec_env

pytestmark = pytest.mark.slow


def _params(model) -> np.ndarray:
    return torch.cat([p.detach().flatten() for p in model.policy.parameters()]).numpy().copy()


@pytest.mark.parametrize("name, steps", [("ppo", 4096), ("sac", 600), ("ppo_dagger", 1024)])
def test_smoke_training(name, steps):
    cfg = load_config(name).with_overrides(timesteps=steps, n_envs=2, eval_points=1)
    if cfg.algo == "sac":
        cfg = cfg.with_overrides(
            model={**cfg.model, "learning_starts": 100, "buffer_size": 2000, "batch_size": 64},
            whiten_steps=100,
        )
    else:  # a mini-batch that divides the 2-env rollout
        cfg = cfg.with_overrides(model={**cfg.model, "n_steps": 256, "batch_size": 256})
        if cfg.whiten_steps:
            cfg = cfg.with_overrides(whiten_steps=512)
    if cfg.distill is not None:
        cfg = cfg.with_overrides(distill={**cfg.distill, "iterations": 2})
    p1, r1 = train_algo(cfg, 7, "ACLDBeam-v1")
    p2, _ = train_algo(cfg, 7, "ACLDBeam-v1")
    assert np.array_equal(_params(p1.model), _params(p2.model))  # repeatable on one machine
    # the returned run's own initialisation (PPO's recipe may retry: a run of another seed)
    rs = r1.get("restarts")
    seed = rs["runs"][rs["chosen"]]["seed"] if rs else 7
    init = make_model(cfg, make_vec_env(cfg, seed), seed=seed)
    assert not np.allclose(_params(init), _params(p1.model))  # the networks moved
    if cfg.distill is not None:
        assert [h["iteration"] for h in r1["distill"]["history"]] == [0, 1]
    else:
        assert r1["distill"] is None
