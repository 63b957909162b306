"""The learning-rate schedule of a config (``model.learning_rate: {linear: [start, end]}``,
with an optional ``warmup: w``): the closed form at every progress, never outside
[``end``, ``start``] when SB3's last rollout overshoots the budget (SB3's progress
remaining is then below 0), and the value each PPO update uses."""

import numpy as np
import pytest
from stable_baselines3 import PPO

from tests.train.tiny_sb3 import tiny_ppo
from train.core.sb3_train import LinearSchedule, make_model, train_sb3


@pytest.mark.parametrize("warmup", [0.0, 0.1, 0.5])
def test_the_schedule_is_the_linear_one_scaled_up_over_the_warmup(warmup):
    sched = LinearSchedule(3e-3, 1e-4, warmup)
    for p in np.linspace(0.0, 1.0, 41):  # p: progress done
        linear = 3e-3 + (1e-4 - 3e-3) * p
        ramp = 1.0 if warmup == 0.0 else min(1.0, p / warmup)
        assert sched(1.0 - p) == pytest.approx(linear * ramp, rel=1e-12, abs=1e-15)
    assert sched(1.0) == (3e-3 if warmup == 0.0 else 0.0) and sched(0.0) == pytest.approx(1e-4)


@pytest.mark.parametrize("warmup", [0.0, 0.2])
def test_an_overshooting_last_rollout_gets_the_end_value_not_beyond(warmup):
    """SB3 reports progress remaining 1 - steps / budget, below 0 after a last rollout that
    overshoots the budget: the schedule holds ``end`` there (a linear rate to 0 would turn
    negative, an ascent step on the loss) and ``start`` (ramped) before training starts."""
    sched = LinearSchedule(3e-3, 0.0, warmup)
    assert sched(-0.2) == 0.0 and sched(-1e-3) == 0.0
    assert sched(1.5) == sched(1.0)


def test_each_ppo_update_uses_the_scheduled_rate_and_the_last_one_zero(monkeypatch):
    used = []
    train = PPO.train

    def spy(self):
        out = train(self)  # SB3 sets the optimizer's rate at the start of the update
        used.append(self.policy.optimizer.param_groups[0]["lr"])
        return out

    monkeypatch.setattr(PPO, "train", spy)
    model = {"learning_rate": {"linear": [3e-3, 0.0], "warmup": 0.5}}
    train_sb3(tiny_ppo(model), 0, "ACLDBeam-v1")
    # 1280 env steps after the whitening, 512 per rollout: updates at 512, 1024 and 1536
    # steps, progress done 0.4 (in the warm-up: 0.4 / 0.5 of the linear value), 0.8, 1.2
    assert used == pytest.approx([3e-3 * 0.6 * 0.8, 3e-3 * 0.2, 0.0], rel=1e-9)


@pytest.mark.parametrize(
    ("value", "match"),
    [
        ({"linear": [3e-3, 0.0], "warmup": 1.0}, r"learning_rate: warmup: .*\[0, 1\), got 1.0"),
        ({"linear": [3e-3, 0.0], "warmup": -0.1}, r"learning_rate: warmup"),
        ({"linear": [3e-3, 0.0], "warm": 0.1}, r"learning_rate: a number or"),
        ({"linear": [3e-3, 0.0], "warmup": None}, r"learning_rate: float\(\) argument"),
        ({"linear": [3e-3]}, r"learning_rate: a number or"),
    ],
)
def test_a_malformed_learning_rate_schedule_names_the_key(value, match):
    with pytest.raises(ValueError, match=match):
        make_model(tiny_ppo({"learning_rate": value}), None, 0)


def test_a_warmup_is_for_the_learning_rate_only():
    with pytest.raises(ValueError, match=r"clip_range: a number or \{linear: \[start, end\]\}"):
        make_model(tiny_ppo({"clip_range": {"linear": [0.2, 0.1], "warmup": 0.1}}), None, 0)
