"""An annealed exploration noise (``TrainConfig.anneal_std``, PPO only): the log std is
trained until ``start``, then held and lowered before each rollout by log f, f linear in env
steps from 1 to ``end`` at the budget's end."""

import math

import numpy as np
import pytest
import torch
import yaml
from stable_baselines3 import PPO

from tests.train.tiny_sb3 import tiny_ppo
from train.bench.sb3_train import train_sb3
from train.config import StdAnnealConfig, TrainConfig


def test_the_factor_falls_linearly_from_start_to_the_budget_end():
    cfg = StdAnnealConfig(start=100, end=0.2)
    assert cfg.factor(50, 300) == 1.0 and cfg.factor(100, 300) == 1.0
    assert cfg.factor(200, 300) == pytest.approx(0.6)
    assert cfg.factor(300, 300) == pytest.approx(0.2) and cfg.factor(400, 300) == pytest.approx(0.2)


@pytest.mark.parametrize(
    "bad, match",
    [
        ({"start": -1, "end": 0.5}, "anneal_std.start"),
        ({"start": 0, "end": 0.0}, "anneal_std.end must be > 0"),
        ({"start": 0, "end": 1.5}, "anneal_std.end must be <= 1"),
        ({"start": 0, "end": "half"}, "anneal_std.end must be a finite real number"),
        ({"start": 0}, r"anneal_std: unknown key\(s\) \[\], missing \['end'\]"),
    ],
)
def test_bad_configs_are_refused_by_name(bad, match):
    with pytest.raises(ValueError, match=match):
        tiny_ppo(anneal_std=bad)


def test_it_is_for_ppo_only():
    data = yaml.safe_load(open("train/benchmark/sac.yaml"))
    with pytest.raises(ValueError, match="anneal_std is for ppo only"):
        TrainConfig(**{**data, "anneal_std": {"start": 0, "end": 0.5}})


def test_updates_see_the_trained_then_the_annealed_log_std(monkeypatch):
    seen = []
    train = PPO.train

    def spy(self):
        seen.append(self.policy.log_std.detach().clone())
        return train(self)

    monkeypatch.setattr(PPO, "train", spy)
    # 256 whitening steps, then rollouts of 512 starting at 256, 768 and 1280 env steps
    _, record = train_sb3(tiny_ppo(anneal_std={"start": 700, "end": 0.5}), 0, "ACLDBeam-v1")
    rec = record["anneal_std"]
    assert rec["frozen_at"] == 768
    frozen = torch.tensor(rec["frozen_log_std"]).reshape(seen[0].shape)
    np.testing.assert_allclose(seen[1], frozen + math.log(1 - 0.5 * 68 / 836), rtol=0, atol=1e-6)
    assert not torch.allclose(frozen, seen[0])  # the first update trained it
    f_last = 1 - 0.5 * (1280 - 700) / (1536 - 700)
    assert rec["last_factor"] == pytest.approx(f_last)
    np.testing.assert_allclose(seen[2], frozen + math.log(f_last), rtol=0, atol=1e-6)


def test_off_it_leaves_the_log_std_trained(monkeypatch):
    seen = []
    train = PPO.train
    monkeypatch.setattr(
        PPO, "train", lambda self: (seen.append(self.policy.log_std.requires_grad), train(self))
    )
    _, record = train_sb3(tiny_ppo(), 0, "ACLDBeam-v1")
    assert record["anneal_std"] is None and seen == [True] * 3
