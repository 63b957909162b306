"""Checkpoint selection on validation loads (``TrainConfig.select``): the validation cost is
the env's reward per load (1 for the passive beam), its loads are not the test loads, and
a run returns the parameters of its best check, not its last."""

import numpy as np
import pytest
import torch

from baselines.policies import LQRPolicy, PassivePolicy
from tests.train.tiny_sb3 import LinearModel as _Model
from tests.train.tiny_sb3 import tiny_sac, tiny_sac_recipe
from train.compare import HELDOUT_SEEDS
from train.core import evaluate
from train.core.sb3_train import Selection


@pytest.fixture(scope="module")
def design_env():
    import gymnasium as gym

    return gym.make("ACLDBeam-v1").unwrapped


def test_validation_loads_are_not_the_test_loads():
    seeds = evaluate.validation_seeds(64)
    assert len(set(seeds)) == 64 and not set(seeds) & set(HELDOUT_SEEDS)
    assert evaluate.validation_seeds(3) == seeds[:3]  # more episodes only add loads


def test_validation_cost_is_one_for_the_passive_beam(design_env):
    """The reward per load divides by the passive beam's cost on the same load, so the
    passive beam scores 1 on every set of loads (up to round-off); LQR damps, below 1."""
    seeds = evaluate.validation_seeds(8)
    assert evaluate.validation_cost(
        PassivePolicy.for_env(design_env), seeds=seeds
    ) == pytest.approx(1.0, rel=1e-12)
    lqr = evaluate.validation_cost(LQRPolicy.for_env(design_env), seeds=seeds)
    assert 0.2 < lqr < 0.9


def _cfg(**select):
    return tiny_sac(select=select or None)


def test_selection_keeps_the_best_check_and_restores_it(monkeypatch):
    costs = iter([0.9, 0.5, 0.7, 0.6])  # the best is the second check
    monkeypatch.setattr(evaluate, "validation_rollout", lambda *a, **k: (next(costs), 7))
    sel = Selection(_cfg(episodes=3, every=100, start=50), "ACLDBeam-v1")
    model = _Model()
    assert not sel.due(49) and sel.due(50)
    saved = {}
    for steps in (50, 150, 260):
        with torch.no_grad():
            model.policy.weight.fill_(steps)
        saved[steps] = model.policy.weight.clone()
        sel.check(steps, model, lambda: None)
    assert not sel.due(349) and sel.due(350)  # every 100 from 50, past the last check
    with torch.no_grad():
        model.policy.weight.fill_(-1.0)
    rec = sel.finish(400, model, lambda: None)  # the final policy is checked too (0.6)
    assert [h["steps"] for h in rec["history"]] == [50, 150, 260, 400]
    assert rec["steps"] == 150 and rec["cost"] == 0.5 and rec["episodes"] == 3
    assert rec["validation_env_steps"] == 4 * 7
    assert torch.equal(model.policy.weight, saved[150])


def test_selection_off_is_inert():
    sel = Selection(_cfg(), "ACLDBeam-v1")
    model = _Model()
    before = model.policy.weight.clone()
    assert not sel.due(10**9) and sel.finish(10, model, lambda: None) is None
    assert torch.equal(model.policy.weight, before)


def test_a_run_returns_its_best_checkpoint(tmp_path):
    """A tiny SAC run of the recipe with selection: the returned (whitening-folded) policy
    scores the chosen check's validation cost again."""
    from train.core.sb3_train import train_sb3

    cfg = tiny_sac_recipe(800, select={"episodes": 2, "every": 200, "start": 0})
    policy, record = train_sb3(cfg, 0, "ACLDBeam-v1")
    sel = record["select"]
    costs = [h["cost"] for h in sel["history"]]
    assert len(costs) >= 3 and sel["cost"] == min(costs)
    assert sel["steps"] == sel["history"][int(np.argmin(costs))]["steps"]
    again = evaluate.validation_cost(policy, "ACLDBeam-v1", evaluate.validation_seeds(2))
    assert again == pytest.approx(sel["cost"], rel=1e-5)
    assert sel["validation_env_steps"] == len(costs) * 2 * 1000  # 2 episodes of 1000 steps


def test_the_final_check_sees_the_final_policy():
    """A check due at the last env step of the budget is left to ``finish``, after the last
    gradient step: with the one check at the end, the run returns the policy of the same run
    without selection (SB3 calls the step callback before the update of its rollout, so a
    check there would see the policy one update short of the final one)."""
    from train.core.sb3_train import train_sb3

    plain, _ = train_sb3(tiny_sac_recipe(800, restarts=1, select=None), 0, "ACLDBeam-v1")
    cfg = tiny_sac_recipe(800, restarts=1, select={"episodes": 1, "every": 800, "start": 800})
    chosen, record = train_sb3(cfg, 0, "ACLDBeam-v1")
    assert [h["steps"] for h in record["select"]["history"]] == [800]
    seeds = evaluate.validation_seeds(2)
    assert evaluate.validation_cost(chosen, "ACLDBeam-v1", seeds) == evaluate.validation_cost(
        plain, "ACLDBeam-v1", seeds
    )
