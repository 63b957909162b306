"""``studies/probes/critic_first.py``: the actor (the linear law's gains and gSDE's log std)
takes no step in the updates of the first ``frozen_rollouts`` rollouts while the critic
trains, then trains as in the recipe; a bad count is named."""

import pytest
import torch
from stable_baselines3 import PPO

from studies.tests.probe_scripts import load_probe
from tests.train.tiny_sb3 import shrink_ppo

cf = load_probe("critic_first")


def tiny(cfg):
    """``cfg`` shrunk by ``tests.train.tiny_sb3.shrink_ppo``, at a constant learning rate
    (the recipe's decays to 0, which the third update, past the budget, gets)."""
    return shrink_ppo(cfg, {"learning_rate": 1e-3})


@pytest.mark.parametrize(("frozen", "candidate"), [(2, False), (0, False), (1, True)])
def test_the_actor_waits_for_its_rollouts_while_the_critic_trains(monkeypatch, frozen, candidate):
    from train.core.sb3_train import train_sb3

    moved = []
    train = PPO.train

    def spy(self):
        pol = self.policy
        before = [p.detach().clone() for p in pol.actor_parameters()]
        critic = pol.value_net.weight.detach().clone()
        train(self)
        actor_moved = any(
            not torch.equal(b, p) for b, p in zip(before, pol.actor_parameters(), strict=True)
        )
        moved.append((actor_moved, not torch.equal(critic, pol.value_net.weight)))

    monkeypatch.setattr(PPO, "train", spy)
    cfg = tiny(cf.config(frozen, candidate))
    assert cfg.paired_loads is candidate and cfg.restarts == 1
    train_sb3(cfg, 0, "ACLDBeam-v1")
    assert moved == [(i >= frozen, True) for i in range(3)]


@pytest.mark.parametrize("bad", [-1, 1.5, "3"])
def test_a_bad_count_is_named(bad):
    from studies.tests.probe_scripts import tiny_model

    with pytest.raises(ValueError, match="frozen_rollouts: a whole number >= 0"):
        tiny_model(cf.config(bad))
