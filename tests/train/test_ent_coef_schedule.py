"""A scheduled entropy coefficient (``model.ent_coef: {linear: [start, end]}``, PPO only):
each update uses the value at the progress of its rollout, and the last one ``end``."""

import pytest
import yaml
from stable_baselines3 import PPO

from tests.train.tiny_sb3 import tiny_ppo
from train.config import TrainConfig
from train.core.sb3_train import make_model, train_sb3


def test_each_update_uses_the_scheduled_coefficient(monkeypatch):
    used = []
    train = PPO.train

    def spy(self):
        used.append(self.ent_coef)
        return train(self)

    monkeypatch.setattr(PPO, "train", spy)
    train_sb3(tiny_ppo({"ent_coef": {"linear": [0.02, 0.0]}}), 0, "ACLDBeam-v1")
    # 1280 env steps after the whitening, 512 per rollout: updates at 512, 1024, 1536 steps
    assert used == pytest.approx([0.02 * (1 - 512 / 1280), 0.02 * (1 - 1024 / 1280), 0.0])


def test_a_constant_coefficient_is_left_alone(monkeypatch):
    used = []
    train = PPO.train
    monkeypatch.setattr(PPO, "train", lambda self: (used.append(self.ent_coef), train(self)))
    train_sb3(tiny_ppo({"ent_coef": 0.01}), 0, "ACLDBeam-v1")
    assert used == [0.01] * 3


def test_a_schedule_is_for_ppo_only():
    data = yaml.safe_load(open("train/recipes/sac.yaml"))
    data["model"] = {**data["model"], "ent_coef": {"linear": [0.01, 0.0]}}
    with pytest.raises(ValueError, match="model.ent_coef.*ppo only"):
        make_model(TrainConfig(**data), None, 0)


def test_a_malformed_schedule_names_the_key():
    with pytest.raises(ValueError, match="ent_coef"):
        make_model(tiny_ppo({"ent_coef": {"linear": [0.01]}}), None, 0)
