"""A short training run per algorithm: it updates the networks, saves everything a
user needs, loads back as a policy in volts, and repeats bit for bit with the same
seed. Marked slow (about a minute each): ``make test-slow``."""

import json

import numpy as np
import pytest
import torch

from acld_gym.envs.beam_env import ACLDBeamEnv
from baselines.evaluate import rollout
from train.agent import TrainedAgent
from train.cli import make_model, train
from train.config import config_path, load_config

pytestmark = pytest.mark.slow


def _params(model) -> np.ndarray:
    return torch.cat([p.detach().flatten() for p in model.policy.parameters()]).numpy().copy()


@pytest.mark.parametrize("algo, config, steps", [("ppo", "ppo", 1024), ("sac", "sac", 600),
                                                  ("ppo", "ppo_dagger", 1024)])
def test_smoke_training(algo, config, steps, tmp_path):
    cfg = load_config(algo, config_path(algo).with_name(f"{config}.yaml")).with_overrides(
        n_timesteps=steps, n_envs=2, eval_freq=steps // 2, checkpoint_freq=steps // 2)
    if algo == "sac":
        cfg = cfg.with_overrides(model={**cfg.model, "learning_starts": 100,
                                        "buffer_size": 2000})
    else:  # a mini-batch that divides the 2 x 256-step rollout
        cfg = cfg.with_overrides(model={**cfg.model, "batch_size": 256})
    if cfg.distill is not None:
        cfg = cfg.with_overrides(distill={**cfg.distill, "iterations": 2})
    m1 = train(cfg, 7, tmp_path / "a")
    m2 = train(cfg, 7, tmp_path / "b")
    # repeatable on one machine
    assert np.array_equal(_params(m1), _params(m2))
    # the networks moved away from their (seeded) initialization
    from train.vec import make_vec_env

    init = make_model(cfg, make_vec_env(cfg, 7), seed=7)
    assert not np.allclose(_params(init), _params(m1))
    out = tmp_path / "a"
    for f in ("policy.npz", "metadata.json", "model.zip", "vecnormalize.pkl",
              "learning_curve.csv", "best/policy.npz", "best/metadata.json"):
        assert (out / f).is_file(), f
    assert list((out / "checkpoints").glob("*.zip"))
    assert list((out / "tb").rglob("events.out.tfevents*"))
    meta = json.loads((out / "metadata.json").read_text())
    assert meta["seed"] == 7 and meta["algo"] == algo and "torch" in meta["versions"]
    assert meta["env"] == {"id": "ACLDBeam-v1", "kwargs": {"mesh": "converged"}}
    if cfg.distill is not None:
        assert meta["teacher"] == "mpc" and meta["training"] == "DAgger from MPC + RL"
        assert [h["iteration"] for h in meta["distill"]["history"]] == [0, 1]
    else:
        assert meta["teacher"] is None and meta["training"] == "from scratch"
    agent = TrainedAgent.load(out)
    ep = rollout(agent, ACLDBeamEnv(load_case=1), seed=0)
    assert np.all(np.abs(ep.voltage) <= 120.0) and np.isfinite(ep.y).all()
    a, _ = agent.predict(np.zeros((4, 9), np.float32))
    assert a.shape == (4, 1) and a.dtype == np.float32
